//! The KFU-LSTM-Net runner in quick mode: the files it writes, the missing-data path, one
//! table cell recomputed independently, and determinism for a fixed seed.
//!
//! Two quick runs are shared by every test (one with the real data when `../shared/data`
//! is present, one without any data), so the whole file costs two quick runs.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::path::PathBuf;
use std::sync::OnceLock;
use trajpred_data::synthetic::PatentCurve;
use trajpred_repro::{Context, Paper, RunInfo, Table, Value, reproduce_into};

struct Run {
    dir: tempfile::TempDir,
    info: RunInfo,
    table: Table,
}

#[path = "../../../testing/skip.rs"]
mod skip;

fn data_dir() -> Option<PathBuf> {
    skip::shared_data("trajpred-repro/tests/kfu_lstm.rs", "adsb-traffic")
}

fn quick_run(data_dir: Option<PathBuf>) -> Run {
    let dir = tempfile::tempdir().expect("tempdir");
    let ctx = Context {
        quick: true,
        data_dir,
        ..Context::default()
    };
    let info = reproduce_into(Paper::KfuLstm, &ctx, dir.path(), "test").expect("quick run");
    let csv = dir.path().join("kfu-lstm/table3.csv");
    assert!(csv.is_file(), "table3.csv written");
    let table = read_table(&csv);
    Run { dir, info, table }
}

/// Reads a results CSV back as labels and numbers (columns kept by header).
fn read_table(path: &std::path::Path) -> Table {
    let mut rdr = csv::Reader::from_path(path).expect("csv");
    let headers: Vec<String> = rdr
        .headers()
        .expect("headers")
        .iter()
        .map(String::from)
        .collect();
    let mut t = Table::new("table3", "read back");
    for h in &headers {
        t = t.label(h);
    }
    for rec in rdr.records() {
        let rec = rec.expect("record");
        let row = rec
            .iter()
            .map(|c| {
                if c.is_empty() {
                    Value::Missing
                } else {
                    c.parse::<f64>()
                        .map_or_else(|_| Value::Text(c.to_string()), Value::Num)
                }
            })
            .collect();
        t.push(row).expect("row");
    }
    t
}

fn with_data() -> &'static Run {
    static R: OnceLock<Run> = OnceLock::new();
    R.get_or_init(|| quick_run(data_dir()))
}

fn without_data() -> &'static Run {
    static R: OnceLock<Run> = OnceLock::new();
    R.get_or_init(|| quick_run(None))
}

const CURVES: [&str; 3] = ["helix", "figure-eight", "climbing-turn"];

#[test]
fn quick_run_writes_every_file() {
    let run = with_data();
    let out = run.dir.path().join("kfu-lstm");
    let mut series: Vec<&str> = CURVES.to_vec();
    if data_dir().is_some() {
        series.push("flight");
        assert!(run.info.missing.is_empty(), "{:?}", run.info.missing);
    }
    for f in ["README.md", "table3.md", "table3.csv", "run.json"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    for s in &series {
        for kind in ["test", "loss"] {
            for ext in ["svg", "png"] {
                let f = out.join(format!("fig_{s}_{kind}.{ext}"));
                let len = std::fs::metadata(&f).map(|m| m.len()).unwrap_or(0);
                assert!(len > 1000, "{} missing or empty", f.display());
            }
        }
    }
    // five rows (two references, three networks) per series
    assert_eq!(run.table.rows.len(), 5 * series.len());
    assert!(run.dir.path().join("README.md").is_file(), "results index");
    assert!(!run.info.claims.is_empty());
}

#[test]
fn without_data_it_runs_the_curves_and_says_what_is_missing() {
    let run = without_data();
    assert_eq!(run.info.missing.len(), 1);
    assert!(run.info.missing[0].contains("adsb-traffic"));
    assert_eq!(run.table.rows.len(), 15);
    let out = run.dir.path().join("kfu-lstm");
    assert!(!out.join("fig_flight_test.svg").exists());
    assert!(out.join("fig_helix_test.svg").is_file());
    let readme = std::fs::read_to_string(out.join("README.md")).expect("README");
    assert!(readme.contains("Not run (data missing)"));
}

/// The raw-observation row of the helix, recomputed by hand from the documented noise rule:
/// quick run = 200 points at dt 0.1, σ = 0.5 m per axis, seed `ctx.seed + 0` for series 0,
/// axis by axis, point by point; test part = the last 40 points.
#[test]
fn raw_observation_rmse_matches_an_independent_computation() {
    let run = without_data();
    let seed = Context::default().seed;
    let (n, dt, sigma) = (200usize, 0.1, 0.5);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut err2 = vec![0.0; n];
    for _axis in 0..3 {
        for e in err2.iter_mut() {
            let z: f64 = StandardNormal.sample(&mut rng);
            *e += (sigma * z) * (sigma * z);
        }
    }
    let first = n * 4 / 5;
    let expected = (err2[first..].iter().sum::<f64>() / (n - first) as f64).sqrt();
    // the truth cancels in z(t) - y(t), but check the curve's length is what the run used
    assert_eq!(PatentCurve::Helix.generate(n, dt).expect("helix").len(), n);
    assert_eq!(
        run.table.get(0, "series"),
        Some(&Value::Text("helix".into()))
    );
    match run.table.get(0, "RMSE 3-D") {
        Some(Value::Num(v)) => assert!(
            (v - expected).abs() < 1e-9 * expected,
            "table {v}, by hand {expected}"
        ),
        other => panic!("unexpected cell {other:?}"),
    }
    // the persistence row: z(t-1) against y(t), recomputed with the curve
    let helix = PatentCurve::Helix.generate(n, dt).expect("helix");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noisy: Vec<Vec<f64>> = (0..3)
        .map(|k| {
            helix
                .axis(k)
                .iter()
                .map(|x| {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    x + sigma * z
                })
                .collect()
        })
        .collect();
    let mut s = 0.0;
    for t in first..n {
        for (k, z) in noisy.iter().enumerate() {
            s += (z[t - 1] - helix.axis(k)[t]).powi(2);
        }
    }
    let expected = (s / (n - first) as f64).sqrt();
    match run.table.get(1, "RMSE 3-D") {
        Some(Value::Num(v)) => assert!((v - expected).abs() < 1e-9 * expected),
        other => panic!("unexpected cell {other:?}"),
    }
}

/// The curves' rows of the two runs (same seed; one also ran the flight, which comes after
/// the curves and uses its own seeds) must agree exactly, network rows included; only the
/// wall-time column may differ.
#[test]
fn same_seed_gives_identical_tables() {
    let (a, b) = (&with_data().table, &without_data().table);
    assert_eq!(a.columns, b.columns);
    for (r, (ra, rb)) in a.rows.iter().zip(&b.rows).take(15).enumerate() {
        for ((va, vb), col) in ra.iter().zip(rb).zip(&a.columns) {
            if col.name != "train s" {
                assert_eq!(va, vb, "row {r}, column {}", col.name);
            }
        }
    }
}

fn num(t: &Table, row: usize, col: &str) -> Option<f64> {
    match t.get(row, col) {
        Some(Value::Num(x)) => Some(*x),
        _ => None,
    }
}

/// The fair test's two tables: three models per series, at least two seeds (so an sd), the
/// mean between min and max, a pooled sd on the baseline rows only; the curves' rows of the
/// two runs are identical (every job is seeded, whichever of the two workers ran it).
#[test]
fn fair_tables_are_consistent_and_reproducible() {
    for target in ["truth", "noisy"] {
        let file = format!("kfu-lstm/fair_{target}.csv");
        let a = read_table(&with_data().dir.path().join(&file));
        let b = read_table(&without_data().dir.path().join(&file));
        assert_eq!(b.rows.len(), 9, "{target}: 3 curves x 3 models");
        assert!(a.rows.len() == 9 || a.rows.len() == 12, "{target}: rows");
        for r in 0..a.rows.len() {
            let (mean, lo, hi) = (
                num(&a, r, "mean RMSE 3-D").expect("mean"),
                num(&a, r, "min").expect("min"),
                num(&a, r, "max").expect("max"),
            );
            assert!(
                mean.is_finite() && mean > 0.0,
                "{target} row {r}: mean {mean}"
            );
            assert!(
                lo <= mean && mean <= hi,
                "{target} row {r}: {lo} {mean} {hi}"
            );
            assert!(
                num(&a, r, "sd over seeds").is_some(),
                "{target} row {r}: sd"
            );
            let kfu = a.get(r, "method") == Some(&Value::Text("KFU-LSTM-Net".into()));
            assert_eq!(num(&a, r, "pooled sd with KFU").is_none(), kfu, "row {r}");
        }
        for (r, (ra, rb)) in a.rows.iter().zip(&b.rows).take(9).enumerate() {
            for ((va, vb), col) in ra.iter().zip(rb).zip(&a.columns) {
                if col.name != "grid train s" {
                    assert_eq!(va, vb, "{target} row {r}, column {}", col.name);
                }
            }
        }
    }
}
