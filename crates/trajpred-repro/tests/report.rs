//! The report model: Markdown and CSV output, the `--check` comparison (its tolerances, and
//! the tables, rows, columns, figures and claims found on one side only), atomic writes,
//! `--bless`, and the files `write_paper` / `write_index` produce.

use std::path::{Path, PathBuf};
use trajpred::plot::{Chart, Series};
use trajpred_repro::report::{
    check_run, format_number, replace_run, write_atomic, write_atomic_with, write_index,
    write_paper,
};
use trajpred_repro::{
    Context, Difference, Figure, Paper, PaperResult, ReproError, RunInfo, Table, Value, run_info,
};

fn table() -> Table {
    let mut t = Table::new("table1", "Table 1: a test")
        .label("m")
        .ours("ours", 3, 1e-9, 1e-6)
        .paper("paper", 1)
        .timing("seconds", 2);
    t.push(vec!["2".into(), 0.0037.into(), 3.7.into(), 0.5.into()])
        .expect("4 values");
    t.push(vec!["3".into(), 1.25.into(), Value::Missing, 0.25.into()])
        .expect("4 values");
    t.note("units: metres");
    t
}

#[test]
fn markdown_shows_every_cell_and_small_numbers_are_not_rounded_to_zero() {
    let md = table().to_markdown();
    assert!(md.starts_with(
        "### Table 1: a test\n\n| m | ours | paper | seconds |\n|---|---:|---:|---:|\n"
    ));
    assert!(md.contains("| 2 | 0.004 | 3.7 | 0.50 |"), "{md}");
    assert!(md.contains("| 3 | 1.250 | — | 0.25 |"), "{md}");
    assert!(md.contains("- units: metres"));
    assert_eq!(format_number(0.00004, 3), "4.00e-5");
    assert_eq!(format_number(0.0, 3), "0.000");
    assert_eq!(format_number(12.5, 1), "12.5");
}

#[test]
fn csv_keeps_full_precision_and_empty_for_missing() {
    let csv = table().to_csv().expect("csv");
    assert_eq!(
        csv,
        "m,ours,paper,seconds\n2,0.0037,3.7,0.5\n3,1.25,,0.25\n"
    );
}

#[test]
fn a_row_of_the_wrong_width_is_an_error() {
    let mut t = table();
    let err = t.push(vec!["4".into()]).expect_err("1 value for 4 columns");
    assert!(matches!(err, ReproError::Experiment { .. }), "{err}");
}

/// A result with `table()`, one figure and two claims, written as the committed run in
/// `<dir>/gskf/`; returns the result and that folder.
fn committed_run(dir: &Path) -> (PaperResult, PathBuf) {
    let mut result = PaperResult::new();
    result.tables.push(table());
    result.figures.push(figure("fig1"));
    result.claim("ours is small", true, "0.0037 < 0.01");
    result.claim("ours beats the paper", false, "1.25 > 0.9");
    let info = info_of(&result);
    let paper_dir = dir.join("gskf");
    write_paper(&result, &info, &paper_dir).expect("written");
    (result, paper_dir)
}

fn figure(id: &str) -> Figure {
    Figure {
        id: id.into(),
        caption: "a line".into(),
        chart: Chart {
            title: "line".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            series: vec![Series {
                label: "y = x".into(),
                points: vec![(0.0, 0.0), (1.0, 1.0)],
                markers: true,
            }],
            log_y: false,
        },
    }
}

/// The [`RunInfo`] that `run_info` gives `result` as a quick `gskf` run (seed 1, 1.5 s, revision
/// `abc`), under the title `A paper`.
fn info_of(result: &PaperResult) -> RunInfo {
    let ctx = Context {
        quick: true,
        seed: 1,
        ..Context::default()
    };
    RunInfo {
        title: "A paper".into(),
        ..run_info(Paper::Gskf, &ctx, result, 1.5, "abc")
    }
}

/// `check_run` of `fresh` against `dir`: the list of differences it failed with (empty when it
/// passed).
fn check(fresh: &PaperResult, dir: &Path) -> Vec<Difference> {
    match check_run("gskf", fresh, dir) {
        Ok(()) => Vec::new(),
        Err(ReproError::CheckFailed {
            paper, differences, ..
        }) => {
            assert_eq!(paper, "gskf");
            assert!(!differences.is_empty());
            differences
        }
        Err(e) => panic!("not a check failure: {e}"),
    }
}

#[test]
fn check_accepts_tolerance_and_timing_and_rejects_the_rest() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (committed, paper_dir) = committed_run(dir.path());
    assert_eq!(check(&committed, &paper_dir), []);

    // within tolerance (1e-9 + 1e-6 * 1.25), and a different wall time: no difference
    let mut fresh = committed.clone();
    fresh.tables[0].rows[1][1] = Value::Num(1.25 + 1e-7);
    fresh.tables[0].rows[0][3] = Value::Num(99.0);
    assert_eq!(check(&fresh, &paper_dir), []);

    // outside tolerance and a changed paper figure: two cell differences, in row order
    fresh.tables[0].rows[1][1] = Value::Num(1.26);
    fresh.tables[0].rows[0][2] = Value::Num(3.8);
    let diffs = check(&fresh, &paper_dir);
    assert!(
        matches!(
            diffs.as_slice(),
            [
                Difference::Cell { row: r0, column: c0, allowed: None, .. },
                Difference::Cell { row: r1, column: c1, allowed: Some(a), .. },
            ] if r0 == "m = 2" && c0 == "paper" && r1 == "m = 3" && c1 == "ours"
                && (*a - (1e-9 + 1e-6 * 1.26)).abs() < 1e-15
        ),
        "{diffs:?}"
    );
    assert!(
        diffs[1].to_string().contains("column \"ours\""),
        "{}",
        diffs[1]
    );

    // at the boundary: 1e-9 + 1e-6 * 1.2500012 allows 1.2e-6, not 1.3e-6
    fresh = committed.clone();
    fresh.tables[0].rows[1][1] = Value::Num(1.25 + 1.2e-6);
    assert_eq!(check(&fresh, &paper_dir), []);
    fresh.tables[0].rows[1][1] = Value::Num(1.25 + 1.3e-6);
    assert!(matches!(
        check(&fresh, &paper_dir).as_slice(),
        [Difference::Cell { .. }]
    ));

    // a number where the committed cell is missing, and an infinity against a number
    fresh = committed.clone();
    fresh.tables[0].rows[1][2] = Value::Num(0.9);
    fresh.tables[0].rows[0][1] = Value::Num(f64::INFINITY);
    let diffs = check(&fresh, &paper_dir);
    assert_eq!(diffs.len(), 2, "{diffs:?}");
    assert!(
        diffs
            .iter()
            .all(|d| matches!(d, Difference::Cell { allowed: None, .. }))
    );
}

#[test]
fn check_fails_on_a_missing_or_extra_table() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (committed, paper_dir) = committed_run(dir.path());

    let mut fresh = committed.clone();
    fresh.tables.clear();
    assert_eq!(
        check(&fresh, &paper_dir),
        [Difference::MissingTable {
            table: "table1".into()
        }]
    );

    let mut other = table();
    other.id = "table9".into();
    fresh.tables = vec![committed.tables[0].clone(), other];
    assert_eq!(
        check(&fresh, &paper_dir),
        [Difference::ExtraTable {
            table: "table9".into()
        }]
    );

    // no committed run at all
    let diffs = check(&committed, &dir.path().join("mkpf"));
    assert!(
        matches!(diffs.as_slice(), [Difference::NoCommittedRun { .. }]),
        "{diffs:?}"
    );
}

#[test]
fn check_fails_on_a_missing_or_extra_row_or_column() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (committed, paper_dir) = committed_run(dir.path());

    // the last row dropped
    let mut fresh = committed.clone();
    fresh.tables[0].rows.pop();
    let diffs = check(&fresh, &paper_dir);
    assert_eq!(
        diffs,
        [Difference::MissingRow {
            table: "table1".into(),
            row: "m = 3".into()
        }]
    );
    assert!(diffs[0].to_string().contains("missing from the fresh run"));

    // the first row dropped: the other still matches by its label, no cell differences
    fresh = committed.clone();
    fresh.tables[0].rows.remove(0);
    assert_eq!(
        check(&fresh, &paper_dir),
        [Difference::MissingRow {
            table: "table1".into(),
            row: "m = 2".into()
        }]
    );

    // a row added, and a label changed (one row missing, one extra)
    fresh = committed.clone();
    let mut row = fresh.tables[0].rows[1].clone();
    row[0] = "4".into();
    fresh.tables[0].rows.push(row);
    fresh.tables[0].rows[0][0] = "5".into();
    assert_eq!(
        check(&fresh, &paper_dir),
        [
            Difference::MissingRow {
                table: "table1".into(),
                row: "m = 2".into()
            },
            Difference::ExtraRow {
                table: "table1".into(),
                row: "m = 5".into()
            },
            Difference::ExtraRow {
                table: "table1".into(),
                row: "m = 4".into()
            },
        ]
    );

    // a column dropped
    fresh = committed.clone();
    let t = &mut fresh.tables[0];
    t.columns.pop();
    for r in &mut t.rows {
        r.pop();
    }
    let diffs = check(&fresh, &paper_dir);
    assert!(
        matches!(diffs.as_slice(), [Difference::Columns { committed, fresh, .. }]
            if committed.len() == 4 && fresh.len() == 3),
        "{diffs:?}"
    );
}

#[test]
fn check_fails_on_a_missing_extra_or_reversed_claim_and_a_missing_figure() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (committed, paper_dir) = committed_run(dir.path());

    let mut fresh = committed.clone();
    fresh.claim("a new claim", true, "1 < 2");
    assert_eq!(
        check(&fresh, &paper_dir),
        [Difference::ExtraClaim {
            statement: "a new claim".into()
        }]
    );

    fresh = committed.clone();
    fresh.claims.remove(0);
    fresh.claims[0].holds = true;
    assert_eq!(
        check(&fresh, &paper_dir),
        [
            Difference::MissingClaim {
                statement: "ours is small".into()
            },
            Difference::Verdict {
                statement: "ours beats the paper".into(),
                committed: false,
                fresh: true
            },
        ]
    );

    // evidence is not compared
    fresh = committed.clone();
    fresh.claims[0].evidence = "0.0038 < 0.01".into();
    assert_eq!(check(&fresh, &paper_dir), []);

    // a claim decided by wall times may change its verdict (the machine's load decides it)
    fresh = committed.clone();
    fresh.claims[1].holds = !fresh.claims[1].holds;
    fresh.claims[1].wall_time = true;
    assert_eq!(check(&fresh, &paper_dir), []);

    fresh = committed.clone();
    fresh.figures[0].id = "fig2".into();
    assert_eq!(
        check(&fresh, &paper_dir),
        [
            Difference::MissingFigure {
                figure: "fig1".into()
            },
            Difference::ExtraFigure {
                figure: "fig2".into()
            },
        ]
    );

    // the error lists every difference
    let err = check_run("gskf", &fresh, &paper_dir).expect_err("differs");
    let text = err.to_string();
    assert!(text.contains("2 difference(s)"), "{text}");
    assert!(
        text.contains("\n  - figure fig1: committed, missing"),
        "{text}"
    );
    assert!(
        text.contains("\n  - figure fig2: in the fresh run"),
        "{text}"
    );
}

/// The names of the files in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("read_dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn an_interrupted_write_leaves_the_old_file_and_no_temporary_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("table1.csv");
    write_atomic(&path, b"old").expect("first write");
    assert_eq!(std::fs::read(&path).expect("read"), b"old");

    // the new content is fully written to the temporary file, then the run fails before the
    // rename
    let mut seen = None;
    let err = write_atomic_with(&path, |tmp| {
        assert_eq!(
            tmp.parent(),
            Some(dir.path()),
            "the temporary file is beside the target"
        );
        std::fs::write(tmp, b"new").expect("temporary write");
        seen = Some(tmp.to_path_buf());
        Err(ReproError::Experiment {
            experiment: "test".into(),
            reason: "interrupted".into(),
        })
    })
    .expect_err("interrupted");
    assert!(matches!(err, ReproError::Experiment { .. }), "{err}");
    let tmp = seen.expect("the writer ran");
    assert!(!tmp.exists(), "{} left behind", tmp.display());
    assert_eq!(std::fs::read(&path).expect("read"), b"old");
    assert_eq!(names(dir.path()), ["table1.csv"]);

    // the temporary write itself fails (its folder is a file)
    let err = write_atomic(&path.join("x.csv"), b"new").expect_err("not a folder");
    assert!(matches!(err, ReproError::Io { .. }), "{err}");
    assert_eq!(std::fs::read(&path).expect("read"), b"old");

    // the rename fails (the destination is a non-empty folder): the temporary file is removed
    let folder = dir.path().join("fig1.svg");
    std::fs::create_dir(&folder).expect("mkdir");
    std::fs::write(folder.join("keep"), b"x").expect("write");
    let err = write_atomic(&folder, b"new").expect_err("a folder is in the way");
    assert!(matches!(err, ReproError::Io { .. }), "{err}");
    assert_eq!(names(dir.path()), ["fig1.svg", "table1.csv"]);

    // a completed write replaces the file; a figure goes through the plot writer the same way
    write_atomic(&path, b"new").expect("second write");
    assert_eq!(std::fs::read(&path).expect("read"), b"new");
    let (result, paper_dir) = committed_run(dir.path());
    assert!(result.figures.len() == 1);
    assert!(
        names(&paper_dir).iter().all(|n| !n.starts_with('.')),
        "{:?}",
        names(&paper_dir)
    );
}

#[test]
fn bless_replaces_the_committed_folder_and_removes_stale_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let committed_root = dir.path().join("results");
    let (_, committed) = committed_run(&committed_root);
    std::fs::write(committed.join("stale.csv"), "m\n1\n").expect("write");

    let fresh_root = dir.path().join("fresh");
    let mut result = PaperResult::new();
    let mut t = table();
    t.id = "table2".into();
    result.tables.push(t);
    result.claim("ours is small", true, "0.0037 < 0.01");
    write_paper(&result, &info_of(&result), &fresh_root.join("gskf")).expect("fresh");
    replace_run(&fresh_root.join("gskf"), &committed).expect("blessed");
    assert_eq!(
        names(&committed),
        ["README.md", "run.json", "table2.csv", "table2.md"]
    );
    assert_eq!(check(&result, &committed), []);
    assert_eq!(
        std::fs::read(committed.join("table2.csv")).expect("read"),
        std::fs::read(fresh_root.join("gskf").join("table2.csv")).expect("read")
    );
}

#[test]
fn write_paper_and_index_produce_the_documented_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut result = PaperResult::new();
    result.tables.push(table());
    result.figures.push(figure("fig1"));
    result.claim("ours is small", true, "0.0037 < 0.01");
    result.notes.push("a note".into());
    result.missing.push("no data".into());
    let info = info_of(&result);
    let paper_dir = dir.path().join("gskf");
    write_paper(&result, &info, &paper_dir).expect("written");
    for f in [
        "README.md",
        "run.json",
        "table1.md",
        "table1.csv",
        "fig1.svg",
        "fig1.png",
    ] {
        let meta = std::fs::metadata(paper_dir.join(f)).expect(f);
        assert!(meta.len() > 0, "{f} is empty");
    }
    let readme = std::fs::read_to_string(paper_dir.join("README.md")).expect("readme");
    assert!(
        readme.contains("| ours is small | yes | 0.0037 < 0.01 |"),
        "{readme}"
    );
    assert!(readme.contains("revision `abc`, seed 1"), "{readme}");

    write_index(dir.path(), &[("gskf", "why it differs"), ("mkpf", "")]).expect("index");
    let index = std::fs::read_to_string(dir.path().join("README.md")).expect("index");
    assert!(index.contains("[A paper](gskf/README.md)"), "{index}");
    assert!(
        index.contains("- [Table 1: a test](gskf/table1.md)"),
        "{index}"
    );
    assert!(index.contains("- Not run: no data"), "{index}");
    assert!(index.contains("why it differs"), "{index}");
    assert!(
        index.contains("Not run yet: `cargo xtask reproduce --paper mkpf`"),
        "{index}"
    );
}
