//! The MKPF runner (`docs/papers.md` C.2): the quick run writes its files with and without the
//! ADS-B data, a table cell agrees with an independent computation, and the same seed gives the
//! same tables.

use std::path::PathBuf;
use trajpred_repro::papers::mkpf::experiment::{
    Method, Motion, Setup, choose_noise, load_flight, local_frame, run_method, synthetic_flight,
    to_geodetic, to_local,
};
use trajpred_repro::{Context, Paper, Value, reproduce_into, run_paper};

#[path = "../../../testing/skip.rs"]
mod skip;

fn data_dir() -> Option<PathBuf> {
    skip::shared_data("trajpred-repro/tests/mkpf.rs", "adsb-traffic")
}

fn quick(data_dir: Option<PathBuf>) -> Context {
    Context {
        quick: true,
        data_dir,
        ..Context::default()
    }
}

#[test]
fn quick_run_writes_its_files_with_and_without_data() {
    // without data: still succeeds, reports the missing data, writes the synthetic table
    let dir = tempfile::tempdir().expect("tempdir");
    let info = reproduce_into(Paper::Mkpf, &quick(None), dir.path(), "test").expect("run");
    assert_eq!(info.missing.len(), 1, "{:?}", info.missing);
    assert!(info.missing[0].contains("adsb-traffic"));
    let out = dir.path().join("mkpf");
    for f in [
        "README.md",
        "run.json",
        "table2.md",
        "table2.csv",
        "table2_noise.csv",
        "fig_synthetic_path.svg",
        "fig_synthetic_path.png",
        "fig_synthetic_error.svg",
        "fig_synthetic_error.png",
    ] {
        assert!(out.join(f).is_file(), "missing {f}");
    }
    assert!(!out.join("table1.csv").exists());
    assert!(!info.claims.is_empty());

    // with data (when the shared data is present): the real-flight table and figures too
    if let Some(d) = data_dir() {
        let dir = tempfile::tempdir().expect("tempdir");
        let info = reproduce_into(Paper::Mkpf, &quick(Some(d)), dir.path(), "test").expect("run");
        assert!(info.missing.is_empty(), "{:?}", info.missing);
        let out = dir.path().join("mkpf");
        for f in [
            "table1.md",
            "table1.csv",
            "table1_noise.csv",
            "fig_flight_path.svg",
            "fig_flight_path.png",
            "fig_flight_error.svg",
            "fig_flight_error.png",
        ] {
            assert!(out.join(f).is_file(), "missing {f}");
        }
        assert!(info.data.iter().any(|d| d.contains("quickstart")));
    }
}

fn num(v: Option<&Value>) -> f64 {
    match v {
        Some(Value::Num(x)) => *x,
        other => panic!("not a number: {other:?}"),
    }
}

#[test]
fn ukf_cell_matches_an_independent_computation() {
    let ctx = quick(None);
    let (result, _) = run_paper(Paper::Mkpf, &ctx).expect("run");
    let table = result
        .tables
        .iter()
        .find(|t| t.id == "table2")
        .expect("table2");
    let row = table
        .rows
        .iter()
        .position(|r| r[0] == Value::from("CT") && r[1] == Value::from("UKF"))
        .expect("CT UKF row");

    // rerun the UKF directly and recompute the paper's formula and the RMSE by hand
    let setup = Setup::paper().expect("the spec's settings");
    let flight = synthetic_flight(ctx.seed, true, &setup).expect("flight");
    let noise = choose_noise(&flight, &setup, Motion::Ct).expect("noise");
    let run = run_method(&flight, &setup, Motion::Ct, &noise, Method::Ukf, 0).expect("ukf");
    assert!(!run.frames.is_empty());
    let mut sum = 0.0;
    let mut count = 0.0;
    for (p, t) in run.predicted.iter().zip(&run.truth) {
        for a in 0..2 {
            sum += ((p[a] - t[a]) / t[a]).powi(2);
            count += 1.0;
        }
    }
    let rel_pct = 100.0 * (sum / count).sqrt();
    let cell = num(table.get(row, "relative error (%)"));
    assert!(
        (cell - rel_pct).abs() <= 1e-12 * rel_pct.abs(),
        "{cell} vs {rel_pct}"
    );

    // metres: from the geodetic points, through the flight's local frame
    let frame = local_frame(&flight).expect("frame");
    let mut se = 0.0;
    for (p, t) in run.predicted.iter().zip(&run.truth) {
        let (p, t) = (
            to_local(&frame, *p).expect("p"),
            to_local(&frame, *t).expect("t"),
        );
        se += (p[0] - t[0]).powi(2) + (p[1] - t[1]).powi(2);
    }
    let rmse = (se / run.predicted.len() as f64).sqrt();
    let cell = num(table.get(row, "RMSE (m)"));
    assert!((cell - rmse).abs() <= 1e-6 * rmse, "{cell} vs {rmse}");
}

#[test]
fn local_frame_round_trip_is_exact() {
    let setup = Setup::paper().expect("the spec's settings");
    let flight = synthetic_flight(3, true, &setup).expect("flight");
    let frame = local_frame(&flight).expect("frame");
    for p in flight.truth.iter().step_by(25) {
        let back = to_geodetic(&frame, to_local(&frame, *p).expect("local"));
        assert!((back[0] - p[0]).abs() < 1e-11 && (back[1] - p[1]).abs() < 1e-11);
    }
}

#[test]
fn same_seed_same_tables() {
    let ctx = quick(None);
    let (a, _) = run_paper(Paper::Mkpf, &ctx).expect("run a");
    let (b, _) = run_paper(Paper::Mkpf, &ctx).expect("run b");
    assert_eq!(a.tables.len(), b.tables.len());
    for (ta, tb) in a.tables.iter().zip(&b.tables) {
        for (ra, rb) in ta.rows.iter().zip(&tb.rows) {
            for ((va, vb), col) in ra.iter().zip(rb).zip(&ta.columns) {
                if col.kind != trajpred_repro::ColumnKind::Timing {
                    assert_eq!(va, vb, "{} column {}", ta.id, col.name);
                }
            }
        }
    }
}

#[test]
fn real_flight_rule_picks_a_long_clean_flight() {
    let Some(d) = data_dir() else { return };
    let setup = Setup::paper().expect("the spec's settings");
    let choice = load_flight(&d.join("adsb-traffic"), &setup, Some(200)).expect("flight");
    assert_eq!(choice.flight.times.len(), 200);
    // fresh reports only: no position repeats the previous one
    assert!(choice.flight.observed.windows(2).all(|w| w[0] != w[1]));
    assert!(choice.flight.times.windows(2).all(|w| w[1] > w[0]));
}
