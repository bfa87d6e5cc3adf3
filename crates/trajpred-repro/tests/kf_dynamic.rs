//! The KF-dynamic paper's runner (`docs/papers.md` B.4): without data, on tiny fixtures written
//! here in the GeoLife and T-Drive formats, and (when `../shared/data` is present) on the real
//! subset in quick mode.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use trajpred_repro::report::ColumnKind;
use trajpred_repro::{Context, Paper, PaperResult, Table, Value, papers, reproduce_into};

#[path = "../../../testing/skip.rs"]
mod skip;

/// Metres per degree of latitude (a rough conversion; the test reads the fixtures back
/// through the loader, so it need not match the loader's projection).
const M_PER_DEG: f64 = 111_320.0;
/// Points per fixture trajectory: history 50 + 5 steps, so each has exactly one origin.
const LEN: usize = 55;

/// The common shape of every GeoLife fixture trajectory: (seconds from start, east m, north m).
fn geolife_shape() -> Vec<(f64, f64, f64)> {
    let mut t: f64 = 0.0;
    (0..LEN)
        .map(|i| {
            let p = (
                t,
                3.0 * t + 0.02 * t * t + 2.0 * (0.3 * t).sin(),
                2.0 * t + 5.0 * (t / 10.0).sin(),
            );
            // irregular 1..3 s sampling, never above the paper's 5 s limit
            t += [1.0, 2.0, 3.0][i % 3];
            p
        })
        .collect()
}

fn write_geolife(root: &Path) -> PathBuf {
    let shape = geolife_shape();
    let mut first = None;
    for user in ["000", "001"] {
        let dir = root.join("geolife/Data").join(user).join("Trajectory");
        std::fs::create_dir_all(&dir).expect("fixture folder");
        for day in 0..4u32 {
            let mut s = String::from(
                "Geolife trajectory\r\nWGS 84\r\nAltitude is in Feet\r\nReserved 3\r\n\
                 0,2,255,My Track,0,0,2,8421376\r\n0\r\n",
            );
            let day_of_month = 23 + day + if user == "001" { 4 } else { 0 };
            for &(t, x, y) in &shape {
                let lat = 39.9 + y / M_PER_DEG;
                let lon = 116.3 + x / (M_PER_DEG * 39.9f64.to_radians().cos());
                let secs = 7200.0 + t;
                let days = 39744.0 + f64::from(day_of_month - 23) + secs / 86400.0;
                let (hh, mm, ss) = (
                    (secs / 3600.0) as u32,
                    ((secs % 3600.0) / 60.0) as u32,
                    (secs % 60.0) as u32,
                );
                let _ = write!(
                    s,
                    "{lat:.6},{lon:.6},0,100,{days:.10},2008-10-{day_of_month:02},\
                     {hh:02}:{mm:02}:{ss:02}\r\n"
                );
            }
            let path = dir.join(format!("200810{day_of_month:02}020000.plt"));
            std::fs::write(&path, s).expect("fixture file");
            first.get_or_insert(path);
        }
    }
    first.expect("at least one fixture file")
}

fn write_tdrive(root: &Path) {
    let dir = root.join("tdrive/taxi_log_2008_by_id");
    std::fs::create_dir_all(&dir).expect("fixture folder");
    for taxi in 1..=4u32 {
        let mut s = String::new();
        for i in 0..70u32 {
            let t = 60 * i;
            let x = 8.0 * f64::from(t) + 300.0 * (f64::from(t) / 600.0 + f64::from(taxi)).sin();
            let y = 5.0 * f64::from(t) * f64::from(taxi) / 4.0;
            let lat = 39.9 + y / M_PER_DEG;
            let lon = 116.3 + x / (M_PER_DEG * 39.9f64.to_radians().cos());
            let _ = writeln!(
                s,
                "{taxi},2008-02-02 {:02}:{:02}:{:02},{lon:.5},{lat:.5}",
                10 + t / 3600,
                (t % 3600) / 60,
                t % 60
            );
        }
        std::fs::write(dir.join(format!("{taxi}.txt")), s).expect("fixture file");
    }
}

fn ctx(data_dir: Option<PathBuf>) -> Context {
    Context {
        quick: true,
        data_dir,
        ..Context::default()
    }
}

fn table<'a>(r: &'a PaperResult, id: &str) -> &'a Table {
    r.tables
        .iter()
        .find(|t| t.id == id)
        .unwrap_or_else(|| panic!("table {id} missing"))
}

fn num(v: Option<&Value>) -> f64 {
    match v {
        Some(Value::Num(x)) => *x,
        other => panic!("expected a number, got {other:?}"),
    }
}

/// The tables with their wall-time columns blanked (those depend on the machine).
fn without_timing(tables: &[Table]) -> Vec<Table> {
    tables
        .iter()
        .cloned()
        .map(|mut t| {
            for row in &mut t.rows {
                for (v, c) in row.iter_mut().zip(&t.columns) {
                    if c.kind == ColumnKind::Timing {
                        *v = Value::Missing;
                    }
                }
            }
            t
        })
        .collect()
}

#[test]
fn without_data_it_reports_what_is_missing() {
    let empty = tempfile::tempdir().expect("tempdir");
    for dir in [None, Some(empty.path().to_path_buf())] {
        let r = papers::kf_dynamic::run(&ctx(dir)).expect("runs without data");
        assert_eq!(r.missing.len(), 2, "{:?}", r.missing);
        assert!(r.missing[0].contains("geolife") && r.missing[1].contains("tdrive"));
        let h = table(&r, "headline");
        assert_eq!(h.get(0, "ours"), Some(&Value::Missing));
        assert_eq!(num(h.get(0, "paper")), 12.5);
        assert!(r.figures.is_empty());
    }
}

#[test]
fn fixtures_exercise_the_real_data_path_and_poly1_matches_a_direct_fit() {
    let root = tempfile::tempdir().expect("tempdir");
    let plt = write_geolife(root.path());
    write_tdrive(root.path());
    let c = ctx(Some(root.path().to_path_buf()));
    let r = papers::kf_dynamic::run(&c).expect("runs on fixtures");
    assert!(r.missing.is_empty(), "{:?}", r.missing);
    assert!(r.data.iter().any(|d| d.starts_with("GeoLife: read 2 of 2")));
    assert!(r.data.iter().any(|d| d.starts_with("T-Drive: read 4 of 4")));

    // the 5-point linear fit at history 10, recomputed by closed-form least squares: every
    // fixture trajectory has the same shape and exactly one origin (point 49)
    let (tracks, _) =
        trajpred_data::geolife::load_plt(&plt, &trajpred_data::LoadOptions::geolife())
            .expect("fixture loads");
    let tr = &tracks[0].trajectory;
    assert_eq!(tr.len(), LEN);
    let t = tr.times();
    let (x, y) = (tr.axis(0), tr.axis(1));
    let idx: Vec<usize> = (45..50).collect();
    let dt = (t[49] - t[45]) / 4.0;
    let fit = |v: &[f64], at: f64| {
        let n = idx.len() as f64;
        let mt = idx.iter().map(|&i| t[i]).sum::<f64>() / n;
        let mv = idx.iter().map(|&i| v[i]).sum::<f64>() / n;
        let sxy: f64 = idx.iter().map(|&i| (t[i] - mt) * (v[i] - mv)).sum();
        let sxx: f64 = idx.iter().map(|&i| (t[i] - mt).powi(2)).sum();
        mv + sxy / sxx * (at - mt)
    };
    let expected = (1..=5)
        .map(|k| {
            let at = t[49] + k as f64 * dt;
            let (px, py) = (fit(x, at), fit(y, at));
            ((px - x[49 + k]).powi(2) + (py - y[49 + k]).powi(2)).sqrt()
        })
        .sum::<f64>()
        / 5.0;
    let tbl = table(&r, "geolife_error_history");
    let row = tbl
        .rows
        .iter()
        .position(|row| row[0] == Value::Text("5-point linear".into()))
        .expect("linear row");
    let got = num(tbl.get(row, "h = 10"));
    assert!(expected > 0.1, "the fixture should not be a straight line");
    // the files' timestamps differ by the rounding of the fractional-day field (micro-
    // seconds), so the test trajectories agree with this one to about 1e-7, not exactly
    assert!(
        (got - expected).abs() <= 1e-6 * expected,
        "table {got}, direct fit {expected}"
    );
    // the same for every history (the same origin)
    assert!((num(tbl.get(row, "h = 50")) - got).abs() <= 1e-6 * got);

    // same seed, same tables
    let again = papers::kf_dynamic::run(&c).expect("second run");
    assert_eq!(without_timing(&r.tables), without_timing(&again.tables));

    // and the writer produces the files
    let out = tempfile::tempdir().expect("tempdir");
    reproduce_into(Paper::KfDynamic, &c, out.path(), "test").expect("writes");
    for f in [
        "README.md",
        "kf-dynamic/README.md",
        "kf-dynamic/run.json",
        "kf-dynamic/headline.csv",
        "kf-dynamic/tdrive_runtime.md",
        "kf-dynamic/geolife_error_step.svg",
    ] {
        assert!(out.path().join(f).is_file(), "{f} not written");
    }
}

/// `trajpred evaluate --protocol` and the reproduction call the same preset and engine: on
/// the fixtures, the preset's table equals the runner's, row for row and column for column.
#[test]
fn the_protocol_preset_gives_the_runners_table() {
    let root = tempfile::tempdir().expect("tempdir");
    write_geolife(root.path());
    write_tdrive(root.path());
    let c = ctx(Some(root.path().to_path_buf()));
    let r = papers::kf_dynamic::run(&c).expect("runs on fixtures");
    for (name, folder, id) in [
        ("kf-dynamic-geolife", "geolife", "geolife_error_history"),
        ("kf-dynamic-tdrive", "tdrive", "tdrive_error_history"),
    ] {
        let p = trajpred::protocol::preset(name, c.seed, c.quick).expect("preset");
        // the dataset's root folder, as a user gives it
        let loaded = trajpred::dataset::load(
            p.dataset,
            &root.path().join(folder),
            &p.load_options,
            &p.segmentation,
            p.max_units,
        )
        .expect("loads");
        let run = trajpred::protocol::run(&p, &loaded.segments, &trajpred::protocol::Silent)
            .expect("runs");
        let ours = run.history_table();
        let theirs = table(&r, id);
        assert_eq!(ours.rows.len(), theirs.rows.len());
        for (row, (label, values)) in ours.rows.iter().enumerate() {
            assert_eq!(theirs.rows[row][0], Value::Text(label.clone()));
            for (col, v) in ours.columns.iter().zip(values) {
                if col == "accuracy (%)" {
                    continue; // in the accuracy table, not this one
                }
                let want = num(theirs.get(row, col));
                assert!(
                    v.to_bits() == want.to_bits(),
                    "{name} {label} {col}: preset {v}, runner {want}"
                );
            }
        }
    }
}

#[test]
fn quick_run_on_the_real_subset() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
    if !data.join("geolife").is_dir() || !data.join("tdrive").is_dir() {
        skip::skipped(
            "trajpred-repro/tests/kf_dynamic.rs",
            &format!(
                "the real data subset is not at {} (see docs/data.md)",
                data.display()
            ),
        );
        return;
    }
    let out = tempfile::tempdir().expect("tempdir");
    let info = reproduce_into(Paper::KfDynamic, &ctx(Some(data)), out.path(), "test")
        .expect("quick run on the real subset");
    assert!(info.missing.is_empty(), "{:?}", info.missing);
    let dir = out.path().join("kf-dynamic");
    for ds in ["geolife", "tdrive"] {
        for id in [
            "error_history",
            "accuracy_history",
            "error_step",
            "accuracy_step",
            "runtime",
            "kf_parameters",
        ] {
            for ext in ["md", "csv"] {
                let f = dir.join(format!("{ds}_{id}.{ext}"));
                assert!(f.is_file(), "{} not written", f.display());
            }
        }
        for id in ["error_history", "accuracy_history", "error_step", "runtime"] {
            for ext in ["svg", "png"] {
                let f = dir.join(format!("{ds}_{id}.{ext}"));
                assert!(f.is_file(), "{} not written", f.display());
            }
        }
    }
    assert_eq!(info.claims.len(), 2 * 7);
    let headline = std::fs::read_to_string(dir.join("headline.csv")).expect("headline");
    assert!(headline.contains("555.4"));
}
