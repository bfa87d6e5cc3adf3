//! The `trajpred` binary as a user runs it: on files this test writes, and on bad input.

use std::path::PathBuf;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trajpred"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// [`run`], asserting that the command succeeded (its stderr shown when not).
fn run_ok(args: &[&str]) -> Output {
    let out = run(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trajpred-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A CSV track `t,x,y` moving at (2, 1) m/s with a gentle curve, 1 s sampling.
fn write_track(dir: &std::path::Path, name: &str, n: usize, phase: f64) -> PathBuf {
    let mut s = String::from("t,x,y\n");
    for i in 0..n {
        let t = i as f64;
        s.push_str(&format!(
            "{t},{},{}\n",
            2.0 * t + (0.05 * t + phase).sin(),
            1.0 * t
        ));
    }
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn predict_prints_a_forecast() {
    let dir = scratch("predict");
    let track = write_track(&dir, "track.csv", 40, 0.0);
    let out = run_ok(&[
        "predict",
        "--method",
        "poly1",
        "--horizon",
        "3",
        "--input",
        track.to_str().unwrap(),
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "step,t,x,y");
    assert_eq!(lines.len(), 4);
    // step 1 at t = 40: y = 40 exactly for a line through y = t
    let step1: Vec<f64> = lines[1].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(step1[1], 40.0);
    assert!((step1[3] - 40.0).abs() < 1e-6);
    let json = run(&[
        "predict",
        "--method",
        "kf-dynamic",
        "--horizon",
        "2",
        "--format",
        "json",
        "--input",
        track.to_str().unwrap(),
    ]);
    assert!(json.status.success());
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(v["dim"], 2);
}

#[test]
fn evaluate_prints_a_table_for_every_method() {
    let dir = scratch("evaluate");
    // three taxis in the T-Drive format (one file per taxi), 5 s sampling, each on its own
    // street (exact copies of a track are left out of splits)
    let tdir = dir.join("taxis");
    std::fs::create_dir_all(&tdir).unwrap();
    for id in 1..=3 {
        let mut taxi = String::new();
        for i in 0..200 {
            let t = 1_000_000 + i * 5;
            let (h, m, s) = ((t / 3600) % 24, (t / 60) % 60, t % 60);
            taxi.push_str(&format!(
                "{id},2008-02-02 {h:02}:{m:02}:{s:02},{:.6},{:.6}\n",
                116.3 + 0.0001 * i as f64,
                39.9 + 0.001 * f64::from(id) + 0.00005 * (i as f64 * 0.1).sin()
            ));
        }
        std::fs::write(tdir.join(format!("{id}.txt")), &taxi).unwrap();
    }
    // the same evaluation settings, with the methods and any extra options given
    let evaluate = |methods: &str, extra: &[&str]| {
        let mut args = vec![
            "evaluate",
            "--dataset",
            "tdrive",
            "--path",
            tdir.to_str().unwrap(),
            "--methods",
            methods,
            "--history",
            "10",
            "--horizon",
            "3",
            "--train-fraction",
            "0.34",
            "--format",
            "csv",
        ];
        args.extend_from_slice(extra);
        run(&args)
    };
    let out = evaluate("kf-dynamic,poly2,hmm", &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert!(rows[0].starts_with("method,trajectories,forecasts,failures,mean err step 1"));
    assert_eq!(rows.len(), 4, "{text}");
    for (row, name) in rows[1..].iter().zip(["kf-dynamic", "poly2", "hmm"]) {
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells[0], name);
        assert!(cells[2].parse::<usize>().unwrap() > 100, "{row}");
        assert_eq!(cells[3], "0", "{row}");
    }
    // a method named twice runs once, in the order first named
    let twice = evaluate("poly2,kf-dynamic,poly2", &[]);
    assert!(twice.status.success());
    let text = String::from_utf8(twice.stdout).unwrap();
    let names: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|r| r.split(',').next().unwrap())
        .collect();
    assert_eq!(names, ["poly2", "kf-dynamic"], "{text}");
    // --max-origins caps the forecasts of every trajectory at that many
    let capped = evaluate("poly1", &["--max-origins", "7"]);
    assert!(capped.status.success());
    let text = String::from_utf8(capped.stdout).unwrap();
    let cells: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
    let trajectories: usize = cells[1].parse().unwrap();
    assert!(trajectories >= 1, "{text}");
    assert_eq!(
        cells[2].parse::<usize>().unwrap(),
        7 * trajectories,
        "{text}"
    );
}

#[test]
fn plot_writes_svg_and_png() {
    let dir = scratch("plot");
    let track = write_track(&dir, "track.csv", 60, 0.3);
    for ext in ["svg", "png"] {
        let out_file = dir.join(format!("plot.{ext}"));
        run_ok(&[
            "plot",
            "--input",
            track.to_str().unwrap(),
            "--method",
            "kf-dynamic",
            "--horizon",
            "5",
            "--output",
            out_file.to_str().unwrap(),
        ]);
        let bytes = std::fs::read(&out_file).unwrap();
        if ext == "svg" {
            assert!(bytes.starts_with(b"<svg"));
        } else {
            assert!(bytes.starts_with(b"\x89PNG"));
        }
    }
}

#[test]
fn bad_input_gives_one_clear_line_and_a_failure_code() {
    let dir = scratch("bad");
    let track = write_track(&dir, "track.csv", 20, 0.0);
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "predict",
                "--method",
                "nope",
                "--input",
                track.to_str().unwrap(),
            ],
            "unknown method `nope`",
        ),
        (
            vec![
                "predict",
                "--method",
                "poly1",
                "--input",
                "/no/such/file.csv",
            ],
            "/no/such/file.csv",
        ),
        (
            vec![
                "predict",
                "--method",
                "poly1",
                "--dataset",
                "foo",
                "--input",
                track.to_str().unwrap(),
            ],
            "unknown dataset `foo`",
        ),
        (
            vec![
                "predict",
                "--method",
                "poly1",
                "--horizon",
                "0",
                "--input",
                track.to_str().unwrap(),
            ],
            "horizon",
        ),
        (
            vec![
                "plot",
                "--input",
                track.to_str().unwrap(),
                "--output",
                "/tmp/x.gif",
            ],
            ".svg or .png",
        ),
        (
            // checked before the data are loaded: the missing path is never reached
            vec![
                "evaluate",
                "--dataset",
                "csv",
                "--path",
                "/no/such/folder",
                "--max-origins",
                "0",
            ],
            "max_origins_per_trajectory",
        ),
    ];
    for (args, needle) in cases {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(
            err.starts_with("error: ") && err.contains(needle),
            "{args:?}: {err}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    // an argument clap rejects exits with 2 and its usage message
    let out = run(&["evaluate", "--dataset", "csv"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn evaluate_says_how_many_repeated_segments_it_left_out() {
    let dir = scratch("repeats");
    // three users' tracks, then a fourth file that copies the first byte for byte
    let a = write_track(&dir, "a.csv", 60, 0.0);
    write_track(&dir, "b.csv", 60, 1.0);
    write_track(&dir, "c.csv", 60, 2.0);
    let evaluate = |path: &std::path::Path| {
        run_ok(&[
            "evaluate",
            "--dataset",
            "csv",
            "--path",
            path.to_str().unwrap(),
            "--methods",
            "cv-time",
            "--history",
            "10",
            "--horizon",
            "3",
            "--split",
            "by-track",
            "--train-fraction",
            "0.5",
        ])
    };
    let stderr = String::from_utf8(evaluate(&dir).stderr).unwrap();
    assert!(!stderr.contains("exact repeats"), "{stderr}");
    std::fs::copy(&a, dir.join("d.csv")).unwrap();
    let stderr = String::from_utf8(evaluate(&dir).stderr).unwrap();
    // wherever the split puts the two copies, one of them is left out and counted
    let line = stderr
        .lines()
        .find(|l| l.contains("training and"))
        .unwrap_or_else(|| panic!("{stderr}"));
    let counts: Vec<usize> = line
        .split("left out as exact repeats of other segments: ")
        .nth(1)
        .unwrap_or_else(|| panic!("{line}"))
        .split(", ")
        .map(|c| c.split(' ').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(counts.iter().sum::<usize>(), 1, "{line}");
}
