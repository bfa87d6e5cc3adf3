//! `trajpred fit --output params.json`, then `evaluate --params` and `predict --params`, as a
//! user runs them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn trajpred(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trajpred"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn ok(out: Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8")
}

/// One CSV of eight tracks (`track` column), 80 points each at 1 s, every track its own
/// curve.
fn write_tracks(dir: &Path) -> PathBuf {
    write_tracks_of(dir, "tracks.csv", 0..8)
}

/// Tracks `ks` of the family of [`write_tracks`] in the CSV `name`.
fn write_tracks_of(dir: &Path, name: &str, ks: std::ops::Range<i32>) -> PathBuf {
    let mut s = String::from("track,t,x,y\n");
    for k in ks {
        let f = f64::from(k);
        for i in 0..80 {
            let t = f64::from(i);
            let x = (2.0 + 0.2 * f) * t + 4.0 * (0.1 * t + f).sin();
            let y = t + 3.0 * (0.07 * t * (1.0 + 0.1 * f)).cos();
            s.push_str(&format!("v{k},{t},{x},{y}\n"));
        }
    }
    let p = dir.join(name);
    std::fs::write(&p, s).expect("write");
    p
}

/// The common options of `fit` and `evaluate`: the same split.
fn common<'a>(data: &'a str, methods: &'a str, seed: &'a str) -> Vec<&'a str> {
    vec![
        "--dataset",
        "csv",
        "--path",
        data,
        "--methods",
        methods,
        "--history",
        "10",
        "--horizon",
        "3",
        "--train-fraction",
        "0.5",
        "--seed",
        seed,
    ]
}

/// The columns of a CSV table without the two timing columns (`fit (s)`, `forecast (s)`).
fn without_times(table: &str) -> Vec<String> {
    table
        .lines()
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            cells[..cells.len() - 2].join(",")
        })
        .collect()
}

#[test]
fn fit_then_evaluate_with_params_gives_the_table_of_evaluate_with_fitting() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = write_tracks(dir.path());
    let data = data.to_str().expect("utf-8");
    let params = dir.path().join("params.json");
    let params_s = params.to_str().expect("utf-8");
    let methods = "kf-cv,gsc,hmm,poly1";
    let mut fit = vec!["fit"];
    fit.extend(common(data, methods, "9"));
    fit.extend(["--output", params_s]);
    let summary = ok(trajpred(&fit));
    // one line per method, what it learned
    let lines: Vec<&str> = summary.lines().collect();
    assert_eq!(lines.len(), 4, "{summary}");
    assert!(lines[0].starts_with("kf-cv: q = "), "{summary}");
    assert!(
        lines[1].starts_with("gsc: frame and LAR steps chosen per axis")
            && lines[1].contains("(4 training segments"),
        "{summary}"
    );
    assert!(
        lines[2].starts_with("hmm: ") && lines[2].contains("motion states"),
        "{summary}"
    );
    assert!(
        lines[3].starts_with("poly1: learns nothing (4 training segments"),
        "{summary}"
    );
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&params).expect("written")).expect("JSON");
    assert_eq!(v["format"], "trajpred-params");
    assert_eq!(v["fitted_on"]["train_segments"], 4);
    assert_eq!(v["fitted_on"]["segments"], 8);

    let mut eval = vec!["evaluate"];
    eval.extend(common(data, methods, "9"));
    eval.extend(["--format", "csv"]);
    let fitted = ok(trajpred(&eval));
    eval.extend(["--params", params_s]);
    let out = trajpred(&eval);
    // the same split: no note about a different one
    assert!(!String::from_utf8_lossy(&out.stderr).contains("note:"));
    let loaded = ok(out);
    assert_eq!(without_times(&fitted), without_times(&loaded));
    assert_eq!(loaded.lines().count(), 5, "{loaded}");

    // another seed splits differently: said, and still evaluated
    let mut other = vec!["evaluate"];
    other.extend(common(data, methods, "10"));
    other.extend(["--params", params_s, "--format", "csv"]);
    let out = trajpred(&other);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("note:"),
        "{out:?}"
    );
    assert!(out.status.success());

    // predict with the saved HMM, and a method the file lacks
    let mut predict = vec![
        "predict",
        "--method",
        "hmm",
        "--horizon",
        "2",
        "--dataset",
        "csv",
        "--input",
        data,
    ];
    predict.extend(["--params", params_s]);
    let text = ok(trajpred(&predict));
    assert_eq!(text.lines().count(), 3, "{text}");
    let missing = trajpred(&[
        "predict",
        "--method",
        "kf-ca",
        "--dataset",
        "csv",
        "--input",
        data,
        "--params",
        params_s,
    ]);
    assert_eq!(missing.status.code(), Some(1));
    let err = String::from_utf8_lossy(&missing.stderr);
    assert!(
        err.contains("holds no parameters for method `kf-ca`"),
        "{err}"
    );
}

#[test]
fn fit_and_params_errors_are_one_clear_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = write_tracks(dir.path());
    let data = data.to_str().expect("utf-8");
    let out_file = dir.path().join("p.json");
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"format\": \"trajpred-params\", \"version\": 7}").expect("write");
    let mut neural = vec!["fit"];
    neural.extend(common(data, "kf-cv,lstm", "9"));
    neural.extend(["--output", out_file.to_str().expect("utf-8")]);
    let mut evaluate_bad = vec!["evaluate"];
    evaluate_bad.extend(common(data, "kf-cv", "9"));
    evaluate_bad.extend(["--params", bad.to_str().expect("utf-8")]);
    for (args, needle) in [
        (neural, "`lstm` cannot save or load fitted parameters"),
        (evaluate_bad, "format version 7 is not supported"),
    ] {
        let out = trajpred(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8(out.stderr).expect("utf-8");
        assert!(err.starts_with("error: ") && err.contains(needle), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    // nothing was written by the refused fit
    assert!(!out_file.exists());
}

/// The `trajectories` column of a CSV table's rows.
fn tested(table: &str) -> Vec<String> {
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = header
        .iter()
        .position(|c| *c == "trajectories")
        .expect("a trajectories column");
    lines
        .map(|l| l.split(',').nth(col).expect("cell").to_string())
        .collect()
}

#[test]
fn fit_on_one_dataset_and_evaluate_on_every_segment_of_another() {
    let dir = tempfile::tempdir().expect("tempdir");
    // ours: tracks 0-7; yours: tracks 6-13, of which 6 and 7 are copies of ours
    let ours = write_tracks_of(dir.path(), "ours.csv", 0..8);
    let yours = write_tracks_of(dir.path(), "yours.csv", 6..14);
    let (ours, yours) = (
        ours.to_str().expect("utf-8"),
        yours.to_str().expect("utf-8"),
    );
    let params = dir.path().join("params.json");
    let params_s = params.to_str().expect("utf-8");
    let args = |cmd: &str, data: &str| -> Vec<String> {
        [
            cmd,
            "--dataset",
            "csv",
            "--path",
            data,
            "--methods",
            "kf-cv,hmm",
            "--history",
            "10",
            "--horizon",
            "3",
            "--split",
            "none",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let run = |a: &[String]| trajpred(&a.iter().map(String::as_str).collect::<Vec<_>>());
    // fit on every segment of ours
    let mut fit = args("fit", ours);
    fit.extend(["--output".into(), params_s.into()]);
    let summary = ok(run(&fit));
    assert!(summary.contains("(8 training segments"), "{summary}");
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&params).expect("written")).expect("JSON");
    assert_eq!(v["fitted_on"]["split"], "None");
    assert_eq!(
        v["fitted_on"]["train_fingerprints"]
            .as_array()
            .map(Vec::len),
        Some(8)
    );

    // every segment of yours is tested but the two copies of ours the methods have seen
    let mut eval = args("evaluate", yours);
    eval.extend([
        "--params".into(),
        params_s.into(),
        "--format".into(),
        "csv".into(),
    ]);
    let out = run(&eval);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(err.contains("left out 2 test segments that"), "{err}");
    let table = ok(out);
    assert_eq!(tested(&table), ["6", "6"], "{table}");

    // without saved parameters nothing may be fitted on a test part: refused
    let out = run(&args("evaluate", yours));
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("`none` puts every segment on both sides"),
        "{err}"
    );

    // on ours itself every segment was seen in fitting: nothing is left to test
    let mut same = args("evaluate", ours);
    same.extend(["--params".into(), params_s.into()]);
    let out = run(&same);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("too few for a test part (8 test segments left out"),
        "{err}"
    );
}
