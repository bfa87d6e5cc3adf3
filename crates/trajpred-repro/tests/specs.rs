//! Papers as data: every paper's spec (`papers/<slug>.toml`) parses and is consistent (every
//! cell a claim or template refers to exists, every paper figure sits in a paper column of a
//! table that exists), and the one runner turns a spec and computed numbers into tables and
//! claims as the spec says.

use trajpred_repro::report::{ColumnKind, Value};
use trajpred_repro::runner::{Computed, Row, assemble};
use trajpred_repro::spec::Spec;
use trajpred_repro::{Context, Paper};

#[test]
fn every_spec_parses_and_is_consistent() {
    for p in Paper::ALL {
        let spec = p.spec().unwrap_or_else(|e| panic!("{}: {e}", p.slug()));
        assert_eq!(spec.slug, p.slug());
        assert!(spec.title.contains("docs/papers.md"), "{}", spec.title);
        let problems = spec.problems();
        assert!(
            problems.is_empty(),
            "{}:\n{}",
            p.slug(),
            problems.join("\n")
        );
    }
}

const TOY: &str = r#"
slug = "toy"
title = "A toy paper (docs/papers.md Z)"
anchor = "Z.1"
explanation = "none"
quantities = ["speed"]

[params]
window = 6
grid = [0.5, 1.0]

[[sections]]
instances = [{ id = "a", t = "ta", name = "A" }, { id = "b", t = "tb", name = "B" }]

[[sections.tables]]
id = "${t}"
title = "${name}: error at window {window}"
columns = [
  { name = "method", kind = "label" },
  { key = "err", name = "error (m)", kind = "ours", decimals = 2, abs = 0.0, rel = 1e-9 },
  { key = "paper", name = "paper", kind = "paper", decimals = 1 },
  { key = "h#", name = "h = #", kind = "ours", each = [1, 2] },
]
rows = [{ key = "kf", labels = ["KF"] }, { key = "poly", labels = ["fit"] }]
notes = ["grid {grid}, error of the KF {${t}/kf/err|.3} m", "${extra}"]

[[sections.claims]]
id = "${id}-kf-best"
statement = "${name}: the KF beats the fit (paper: {ta/kf/paper} m)"
holds = { all = [{ lt = ["${t}/kf/err", "${t}/poly/err"] }, { gt = ["speed", 0] }] }
evidence = "KF {${t}/kf/err|.2} m, fit {${t}/poly/err|.2} m, speed {speed}"

[[paper]]
table = "ta"
column = "paper"
values = { kf = 1.5 }
"#;

fn toy(extra_b: &str) -> Spec {
    toy_from(TOY, extra_b)
}

fn toy_from(template: &str, extra_b: &str) -> Spec {
    let text = template
        .replace(r#"name = "A" }"#, r#"name = "A", extra = "" }"#)
        .replace(
            r#"name = "B" }"#,
            &format!(r#"name = "B", extra = "{extra_b}" }}"#),
        );
    Spec::parse(&text).expect("toy spec")
}

fn rows(kf: f64, poly: f64) -> Vec<Row> {
    ["kf", "poly"]
        .into_iter()
        .zip([kf, poly])
        .map(|(k, e)| Row::new(k).set("err", e).set("h1", 1.0).set("h2", 2.0))
        .collect()
}

#[test]
fn the_runner_builds_tables_and_decides_claims_from_the_spec() {
    let spec = toy("only in B");
    assert!(spec.problems().is_empty(), "{:?}", spec.problems());
    let mut c = Computed::default();
    c.table("ta").rows = rows(1.0, 2.0);
    c.table("tb").rows = rows(3.0, 2.0);
    c.quantities.insert("speed".into(), 4.0);
    let r = assemble(&spec, &Context::default(), c).expect("assemble");
    assert_eq!(r.tables.len(), 2);
    let ta = &r.tables[0];
    assert_eq!(ta.title, "A: error at window 6");
    let names: Vec<&str> = ta.columns.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["method", "error (m)", "paper", "h = 1", "h = 2"]);
    assert_eq!(ta.columns[2].kind, ColumnKind::Paper);
    assert_eq!(
        ta.rows[0],
        vec![
            Value::from("KF"),
            Value::Num(1.0),
            Value::Num(1.5),
            Value::Num(1.0),
            Value::Num(2.0)
        ]
    );
    assert_eq!(ta.rows[1][2], Value::Missing);
    assert_eq!(ta.notes, ["grid [0.5, 1.0], error of the KF 1.000 m"]);
    assert_eq!(r.tables[1].notes.len(), 2);
    assert_eq!(r.claims.len(), 2);
    assert_eq!(
        r.claims[0].statement,
        "A: the KF beats the fit (paper: 1.5 m)"
    );
    assert!(r.claims[0].holds);
    assert_eq!(r.claims[0].evidence, "KF 1.00 m, fit 2.00 m, speed 4");
    assert!(!r.claims[1].holds);
}

#[test]
fn a_claim_on_a_table_not_in_the_run_is_not_checked() {
    let spec = toy("");
    let mut c = Computed::default();
    c.table("ta").rows = rows(1.0, 2.0);
    c.quantities.insert("speed".into(), 4.0);
    let r = assemble(&spec, &Context::default(), c).expect("assemble");
    assert_eq!(r.tables.len(), 1);
    assert_eq!(r.claims.len(), 1);
}

#[test]
fn a_row_or_table_the_spec_does_not_know_is_an_error() {
    let spec = toy("");
    let mut c = Computed::default();
    c.table("ta").rows = rows(1.0, 2.0);
    c.table("ta").rows.push(Row::new("hmm").set("err", 1.0));
    assert!(assemble(&spec, &Context::default(), c).is_err());
    let mut c = Computed::default();
    c.table("tc").rows = rows(1.0, 2.0);
    assert!(assemble(&spec, &Context::default(), c).is_err());
}

#[test]
fn inconsistencies_are_found() {
    assert!(toy("").problems().is_empty());
    let broken = [
        // a claim on a column that does not exist
        (
            r#""${t}/poly/err"] }"#,
            r#""${t}/poly/rmse"] }"#,
            "no column `rmse`",
        ),
        // a claim on a row that does not exist
        (
            r#""${t}/poly/err"] }"#,
            r#""${t}/hmm/err"] }"#,
            "no row `hmm`",
        ),
        // a paper figure in a column that is not a paper column
        (
            r#"column = "paper""#,
            r#"column = "err""#,
            "not a paper column",
        ),
        // a paper figure in a table that does not exist
        (r#"table = "ta""#, r#"table = "tz""#, "no table `tz`"),
        // a quantity that is not declared
        (r#"quantities = ["speed"]"#, "quantities = []", "`speed`"),
        // a row with too few labels
        (r#"labels = ["fit"]"#, "labels = []", "0 labels"),
    ];
    for (from, to, expected) in broken {
        assert!(TOY.contains(from), "{from}");
        let spec = toy_from(&TOY.replace(from, to), "");
        let problems = spec.problems();
        assert!(
            problems.iter().any(|p| p.contains(expected)),
            "{from} -> {to}: expected {expected:?} in {problems:?}"
        );
    }
}
