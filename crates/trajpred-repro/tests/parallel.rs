//! `run_papers`: papers run at once give the tables of papers run one at a time, in the
//! order asked for.

use trajpred_repro::report::{ColumnKind, Table};
use trajpred_repro::{Context, Paper, run_paper, run_papers};

/// Every cell but those of timing columns, printed.
fn cells(t: &Table) -> Vec<String> {
    t.rows
        .iter()
        .flat_map(|r| r.iter().zip(&t.columns))
        .filter(|(_, c)| !matches!(c.kind, ColumnKind::Timing))
        .map(|(v, _)| format!("{v:?}"))
        .collect()
}

#[test]
fn papers_run_at_once_give_the_tables_of_one_at_a_time_in_order() {
    let ctx = Context {
        quick: true,
        ..Context::default()
    };
    // kf-dynamic runs alone (its claims compare wall times); mkpf shares the pool
    assert!(Paper::KfDynamic.spec().expect("spec").runs_alone);
    assert!(!Paper::Mkpf.spec().expect("spec").runs_alone);
    let papers = [Paper::KfDynamic, Paper::Mkpf, Paper::Mkpf];
    let together = run_papers(&papers, &ctx, 2);
    assert_eq!(together.len(), 3);
    for (p, r) in papers.iter().zip(&together) {
        let (r, _) = r.as_ref().expect("the paper runs");
        let (alone, _) = run_paper(*p, &ctx).expect("the paper runs");
        assert_eq!(r.tables.len(), alone.tables.len(), "{}", p.slug());
        for (a, b) in r.tables.iter().zip(&alone.tables) {
            assert_eq!(a.id, b.id);
            // timing columns aside, every cell is the same
            assert_eq!(cells(a), cells(b), "{} {}", p.slug(), a.id);
        }
    }
}
