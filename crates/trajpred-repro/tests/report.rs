//! The report model: Markdown and CSV output, the `--check` comparison and its tolerances,
//! and the files `write_paper` / `write_index` produce.

use trajpred::plot::{Chart, Series};
use trajpred_repro::report::{compare_with_committed, format_number, write_index, write_paper};
use trajpred_repro::{Figure, PaperResult, ReproError, RunInfo, Table, Value};

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

#[test]
fn check_accepts_tolerance_and_timing_and_rejects_the_rest() {
    let dir = tempfile::tempdir().expect("tempdir");
    let committed = table();
    std::fs::write(
        dir.path().join("table1.csv"),
        committed.to_csv().expect("csv"),
    )
    .expect("write");

    // within tolerance (1e-9 + 1e-6 * 1.25), and a different wall time: no difference
    let mut fresh = committed.clone();
    fresh.rows[1][1] = Value::Num(1.25 + 1e-7);
    fresh.rows[0][3] = Value::Num(99.0);
    assert!(
        compare_with_committed(&[fresh.clone()], dir.path())
            .expect("compare")
            .is_empty()
    );

    // outside tolerance, a changed paper figure and a changed label: three differences
    fresh.rows[1][1] = Value::Num(1.26);
    fresh.rows[0][2] = Value::Num(3.8);
    fresh.rows[1][0] = "4".into();
    let diffs = compare_with_committed(&[fresh.clone()], dir.path()).expect("compare");
    assert_eq!(diffs.len(), 3, "{diffs:?}");
    assert!(diffs[0].contains("row 1 column \"paper\""), "{diffs:?}");

    // a missing row and a missing file are differences too
    fresh = committed.clone();
    fresh.rows.pop();
    let diffs = compare_with_committed(&[fresh], dir.path()).expect("compare");
    assert_eq!(diffs.len(), 1, "{diffs:?}");
    let mut other = committed.clone();
    other.id = "table9".into();
    let diffs = compare_with_committed(&[other], dir.path()).expect("compare");
    assert!(diffs[0].contains("no committed file"), "{diffs:?}");
}

#[test]
fn write_paper_and_index_produce_the_documented_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut result = PaperResult::new();
    result.tables.push(table());
    result.figures.push(Figure {
        id: "fig1".into(),
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
    });
    result.claim("ours is small", true, "0.0037 < 0.01");
    result.notes.push("a note".into());
    result.missing.push("no data".into());
    let info = RunInfo {
        paper: "gskf".into(),
        title: "A paper".into(),
        seed: 1,
        revision: "abc".into(),
        quick: true,
        wall_seconds: 1.5,
        data: vec![],
        missing: result.missing.clone(),
        claims: result.claims.clone(),
        notes: result.notes.clone(),
        tables: vec![("table1".into(), "Table 1: a test".into())],
        figures: vec![("fig1".into(), "a line".into())],
    };
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
