//! The evaluation path as a user meets it: segmentation before anything else, datasets read
//! from their root folders, CSV folders with several tracks per file and epoch-millisecond
//! times, a split by user, protocol presets from the command line, and no progress bars when
//! stderr is not a terminal.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use trajpred::dataset::{Dataset, Segment, Segmentation, load};
use trajpred::harness::{Split, segment_fingerprint, split_segments, split_segments_counted};
use trajpred_core::{Error, Trajectory};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trajpred"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A scratch folder of this test process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trajpred-path-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// Metres to degrees near Beijing (rough; the loader projects them back).
fn lat_lon(x: f64, y: f64) -> (f64, f64) {
    let m = 111_320.0;
    (39.9 + y / m, 116.3 + x / (m * 39.9f64.to_radians().cos()))
}

#[test]
fn segmentation_splits_at_gaps_and_resamples_inside_segments_only() {
    // 0..=4 s, then a 100 s gap, then 104..=108 s
    let times: Vec<f64> = (0..5)
        .map(f64::from)
        .chain((104..109).map(f64::from))
        .collect();
    let xs: Vec<f64> = times.iter().map(|t| 2.0 * t).collect();
    let tr = Trajectory::from_axes(times, vec![xs.clone(), xs]).expect("track");
    let seg = Segmentation {
        max_gap: Some(10.0),
        min_points: 3,
        resample: Some(0.5),
        ..Segmentation::default()
    };
    let parts = seg.split(&tr).expect("split");
    assert_eq!(parts.len(), 2);
    let track = trajpred_data::Track {
        id: "u/f".into(),
        group: "u".into(),
        source: "mem".into(),
        first_line: 1,
        frame: trajpred_data::Frame::Cartesian,
        trajectory: tr,
    };
    let (segments, counts) = seg.apply(std::slice::from_ref(&track)).expect("apply");
    assert_eq!(counts.segments_all, 2);
    assert_eq!(segments.len(), 2);
    // resampled at 0.5 s inside each segment: 9 points each, none inside the gap
    for s in &segments {
        assert_eq!(s.trajectory.len(), 9);
        assert_eq!(s.group, "u");
        assert!(
            s.trajectory
                .times()
                .iter()
                .all(|&t| !(4.0 < t && t < 104.0))
        );
    }
    assert_eq!(segments[1].trajectory.times()[0], 104.0);
    // a cap smaller than the 18 points it would create is refused before any allocation
    let capped = Segmentation {
        max_resampled_points: 17,
        ..seg
    };
    match capped.apply(std::slice::from_ref(&track)) {
        Err(Error::InvalidParameter { name, reason }) => {
            assert_eq!(name, "resample");
            assert!(reason.contains("18 points"), "{reason}");
        }
        other => panic!("expected the resampling cap, got {other:?}"),
    }
    // bad settings name themselves
    for (bad, name) in [
        (
            Segmentation {
                max_gap: Some(0.0),
                ..Segmentation::default()
            },
            "max_gap",
        ),
        (
            Segmentation {
                min_points: 0,
                ..Segmentation::default()
            },
            "min_points",
        ),
        (
            Segmentation {
                resample: Some(f64::NAN),
                ..Segmentation::default()
            },
            "resample",
        ),
    ] {
        assert!(
            matches!(bad.validate(), Err(Error::InvalidParameter { name: n, .. }) if n == name),
            "{name}"
        );
    }
}

#[test]
fn split_by_user_keeps_every_user_on_one_side() {
    let segments: Vec<Segment> = (0..40)
        .map(|i| Segment {
            group: format!("user{}", i % 7),
            id: format!("s{i}"),
            frame: trajpred_data::Frame::Cartesian,
            trajectory: Trajectory::uniform(0.0, 1.0, vec![vec![0.0, 1.0, f64::from(i)]])
                .expect("track"),
        })
        .collect();
    let how = Split::ByGroup {
        train_fraction: 0.3,
        seed: 5,
    };
    let (train, test) = split_segments(&segments, how).expect("split");
    assert_eq!(train.len() + test.len(), 40);
    let users = |v: &[Segment]| {
        let mut u: Vec<String> = v.iter().map(|s| s.group.clone()).collect();
        u.sort();
        u.dedup();
        u
    };
    let (a, b) = (users(&train), users(&test));
    assert!(a.iter().all(|u| !b.contains(u)), "{a:?} and {b:?} overlap");
    // round(7 * 0.3) = 2 users train
    assert_eq!(a.len(), 2);
    assert_eq!(b.len(), 5);
    // the same seed gives the same split, another seed another one
    assert_eq!(split_segments(&segments, how).expect("split").0, train);
    let other = Split::ByGroup {
        train_fraction: 0.3,
        seed: 6,
    };
    assert_ne!(
        users(&split_segments(&segments, other).expect("split").0),
        a
    );
    // by track, the same users do end up on both sides
    let (t1, t2) = split_segments(
        &segments,
        Split::ByTrajectory {
            train_fraction: 0.3,
            seed: 5,
        },
    )
    .expect("split");
    assert!(users(&t1).iter().any(|u| users(&t2).contains(u)));
    // one user's segments cannot be split by user: a typed error naming the split and the
    // user (before: an empty training part, reported only when a method was fitted)
    let one: Vec<Segment> = segments
        .iter()
        .filter(|s| s.group == "user3")
        .cloned()
        .collect();
    match split_segments(&one, how) {
        Err(trajpred_core::Error::InvalidParameter { name, reason }) => {
            assert_eq!(name, "split");
            assert!(reason.contains("got 1 (user3)"), "{reason}");
        }
        other => panic!("expected InvalidParameter split, got {other:?}"),
    }
}

#[test]
fn no_split_puts_every_segment_on_both_sides_once_and_fingerprints_are_stable() {
    let seg = |g: &str, x0: f64| Segment {
        group: g.into(),
        id: g.into(),
        frame: trajpred_data::Frame::Cartesian,
        trajectory: Trajectory::new(vec![0.0, 1.0], vec![[x0, 0.0], [x0 + 1.0, 0.0]])
            .expect("track"),
    };
    // b repeats a exactly: each side keeps one copy, and no side is compared with the other
    let segments = vec![seg("a", 0.0), seg("b", 0.0), seg("c", 5.0)];
    let (train, test, r) = split_segments_counted(&segments, Split::None).expect("split");
    let groups = |v: &[Segment]| v.iter().map(|s| s.group.clone()).collect::<Vec<_>>();
    assert_eq!(groups(&train), ["a", "c"]);
    assert_eq!(groups(&test), ["a", "c"]);
    assert_eq!((r.train, r.test_of_train, r.test), (1, 0, 1));
    // evaluating with fitting on it would test on the training data: refused
    let p = trajpred::protocol::preset("kf-dynamic-geolife", 0, true).expect("preset");
    let p = trajpred::protocol::Protocol {
        split: Split::None,
        ..p
    };
    match trajpred::protocol::run(&p, &segments, &trajpred::protocol::Silent) {
        Err(Error::InvalidParameter { name, reason }) => {
            assert_eq!(name, "split");
            assert!(reason.contains("both sides"), "{reason}");
        }
        other => panic!(
            "expected InvalidParameter split, got {:?}",
            other.map(|r| r.labels)
        ),
    }
    // 64-bit FNV-1a over the little-endian bits (frame tag and origin, length, axes, times,
    // then each axis), computed independently in Python:
    // struct.pack('<Q', w) per word, h = ((h ^ byte) * 0x100000001b3) mod 2^64
    assert_eq!(segment_fingerprint(&segments[0]), 0xbdf4_49d3_7d43_f007);
    let enu = Segment {
        group: "d".into(),
        id: "d".into(),
        frame: trajpred_data::Frame::Enu(
            trajpred_data::geodesy::Geodetic::new(39.9, 116.4, 0.0).expect("origin"),
        ),
        trajectory: Trajectory::new(vec![10.0, 11.5], vec![[3.0, -1.0], [4.0, -2.0]])
            .expect("track"),
    };
    assert_eq!(segment_fingerprint(&enu), 0x8279_f3fe_d374_9881);
}

#[test]
fn splits_leave_out_exact_repeats_so_no_test_segment_is_a_training_one() {
    // 6 users with 3 tracks each; "copy" repeats user0's three (as GeoLife's user 059
    // repeats files of 058) and "twin" repeats user1's first, under its own id
    let track = |k: usize| {
        let xs: Vec<f64> = (0..30).map(|i| (i * (k + 1)) as f64).collect();
        Trajectory::uniform(100.0 * k as f64, 1.0, vec![xs, vec![k as f64; 30]]).expect("track")
    };
    let seg = |g: &str, k: usize| Segment {
        group: g.into(),
        id: format!("{g}/{k}"),
        frame: trajpred_data::Frame::Cartesian,
        trajectory: track(k),
    };
    let mut segments: Vec<Segment> = (0..18).map(|k| seg(&format!("user{}", k / 3), k)).collect();
    segments.extend((0..3).map(|k| seg("copy", k)));
    segments.push(seg("twin", 3));
    let mut straddled = 0;
    for seed in 0..12 {
        for how in [
            Split::ByGroup {
                train_fraction: 0.3,
                seed,
            },
            Split::ByTrajectory {
                train_fraction: 0.3,
                seed,
            },
        ] {
            let (train, test, r) = split_segments_counted(&segments, how).expect("split");
            assert_eq!(train.len() + test.len() + r.total(), segments.len());
            // every one of the 18 distinct tracks is kept exactly once
            let kept: Vec<&Trajectory> = train.iter().chain(&test).map(|s| &s.trajectory).collect();
            assert_eq!(kept.len(), 18, "{how:?}: {r:?}");
            for (i, a) in kept.iter().enumerate() {
                assert!(
                    kept[i + 1..].iter().all(|b| b != a),
                    "{how:?}: a repeat kept"
                );
            }
            for s in &test {
                assert!(
                    train.iter().all(|t| t.trajectory != s.trajectory),
                    "{how:?}: {} tests a copy of a training segment",
                    s.id
                );
            }
            straddled += r.test_of_train;
            // the plain split is the same split
            assert_eq!(
                split_segments(&segments, how).expect("split"),
                (train, test)
            );
        }
    }
    assert!(straddled > 0, "no seed put a copy on each side");
}

/// A CSV folder: two files, each with an `id` column holding two walkers, epoch-millisecond
/// times sampled every 2 s, and a 60 s pause in the middle of every track.
fn write_csv_folder(dir: &Path) {
    for (f, file) in ["mon.csv", "tue.csv"].iter().enumerate() {
        let mut s = String::from("id,timestamp,lat,lon\n");
        for i in 0..80u32 {
            for w in 0..2u32 {
                let pause = if i >= 40 { 60_000 } else { 0 };
                let ms = 1_224_730_384_000u64 + u64::from(i) * 2000 + pause;
                let t = f64::from(i) * 2.0;
                // each walker of each file its own track (exact copies are left out)
                let (lat, lon) = lat_lon(
                    1.5 * t + 50.0 * f64::from(f as u32),
                    (0.2 * t + f64::from(w)).sin() * 5.0 + t,
                );
                let _ = writeln!(s, "walker{f}{w},{ms},{lat:.7},{lon:.7}");
            }
        }
        std::fs::write(dir.join(file), s).expect("fixture file");
    }
}

#[test]
fn a_csv_folder_of_tracks_evaluates_by_user_without_progress_bars() {
    let dir = scratch("csv");
    write_csv_folder(&dir);
    let loaded = load(
        Dataset::Csv,
        &dir,
        &Dataset::Csv.options(),
        &Segmentation {
            max_gap: Some(5.0),
            min_points: 10,
            ..Segmentation::default()
        },
        None,
    )
    .expect("loads the folder");
    // 2 files x 2 walkers, each split at its pause
    assert_eq!(loaded.tracks, 4);
    assert_eq!(loaded.segments.len(), 8);
    assert!(loaded.segments.iter().all(|s| s.trajectory.len() == 40));
    // epoch milliseconds were read as such: 2 s steps
    let t = loaded.segments[0].trajectory.times();
    assert!((t[1] - t[0] - 2.0).abs() < 1e-9, "{t:?}");
    let out = run(&[
        "evaluate",
        "--dataset",
        "csv",
        "--path",
        dir.to_str().expect("path"),
        "--methods",
        "naive-kf-4d,poly1",
        "--max-gap",
        "5",
        "--history",
        "10",
        "--horizon",
        "3",
        "--split",
        "by-user",
        "--train-fraction",
        "0.5",
        "--format",
        "csv",
    ]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(out.status.success(), "{stderr}");
    let rows: Vec<&str> = stdout.lines().collect();
    assert_eq!(rows.len(), 3, "{stdout}");
    // rows carry the names asked for (the 4-D variant is not labelled `naive-kf`)
    assert!(rows[1].starts_with("naive-kf-4d,") && rows[2].starts_with("poly1,"));
    // 2 of 4 users test: their 4 segments of 40 points, origins 9..=36
    let cells: Vec<&str> = rows[1].split(',').collect();
    assert_eq!(cells[1], "4", "{stdout}");
    assert_eq!(cells[2], (4 * 28).to_string(), "{stdout}");
    assert!(stderr.contains("by-user split"), "{stderr}");
    // stderr is a pipe here: no progress bar was drawn (no carriage returns, no escapes)
    assert!(
        !stderr.contains('\r') && !stderr.contains('\u{1b}'),
        "{stderr:?}"
    );
    // a resampling past the cap is refused with the cap named
    let out = run(&[
        "evaluate",
        "--dataset",
        "csv",
        "--path",
        dir.to_str().expect("path"),
        "--resample",
        "0.001",
        "--max-resampled-points",
        "1000",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("more than the cap of 1000"));
    // the training users' tracks cut at a longer gap: their two tracks whole (the pause
    // kept), the test part as before
    let with_cut = |split: &str| {
        run(&[
            "evaluate",
            "--dataset",
            "csv",
            "--path",
            dir.to_str().expect("path"),
            "--methods",
            "cv-time",
            "--max-gap",
            "5",
            "--train-max-gap",
            "1000",
            "--history",
            "10",
            "--horizon",
            "3",
            "--split",
            split,
            "--train-fraction",
            "0.5",
            "--format",
            "csv",
        ])
    };
    let out = with_cut("by-user");
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("more than 1000 s apart: 4 segments of 4 kept (320 points)"),
        "{stderr}"
    );
    assert!(
        stderr.contains("2 training and 4 test segments"),
        "{stderr}"
    );
    let cells: Vec<&str> = stdout.lines().nth(1).expect("a row").split(',').collect();
    assert_eq!((cells[1], cells[2]), ("4", "112"), "{stdout}");
    // split by track, another cut of a test track could train: refused
    let out = with_cut("by-track");
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("train_segmentation"));
}

#[test]
fn tdrive_evaluates_from_its_root_folder() {
    let root = scratch("tdrive");
    let inner = root.join("taxi_log_2008_by_id");
    std::fs::create_dir_all(&inner).expect("folder");
    for taxi in 1..=3u32 {
        let mut s = String::new();
        for i in 0..60u32 {
            let t = 60 * i;
            let (lat, lon) = lat_lon(8.0 * f64::from(t), 3.0 * f64::from(t * taxi) / 2.0);
            let _ = writeln!(
                s,
                "{taxi},2008-02-02 {:02}:{:02}:{:02},{lon:.5},{lat:.5}",
                10 + t / 3600,
                (t % 3600) / 60,
                t % 60
            );
        }
        std::fs::write(inner.join(format!("{taxi}.txt")), s).expect("fixture");
    }
    for path in [&root, &inner] {
        let out = run(&[
            "evaluate",
            "--dataset",
            "tdrive",
            "--path",
            path.to_str().expect("path"),
            "--methods",
            "poly1",
            "--max-gap",
            "300",
            "--format",
            "csv",
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        assert!(text(&out.stderr).contains("read 3 of 3 units"));
    }
}

#[test]
fn protocols_are_listed_and_unknown_ones_name_the_known() {
    let out = run(&["protocols"]);
    assert!(out.status.success());
    let s = text(&out.stdout);
    assert!(s.contains("kf-dynamic-geolife:") && s.contains("kf-dynamic-tdrive:"));
    assert!(s.contains("max gap 5 s, at least 55 points"), "{s}");
    assert!(
        s.contains("histories [10, 20, 30, 40, 50], horizon 5"),
        "{s}"
    );
    let out = run(&["evaluate", "--protocol", "nope", "--path", "."]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("known: kf-dynamic-geolife, kf-dynamic-tdrive"));
}

/// GeoLife in its real layout (`<root>/Data/<user>/Trajectory/*.plt`): 3 users, 2 files each
/// of 70 fixes 1-3 s apart, with a 20 s pause after fix 60.
fn write_geolife(root: &Path) {
    for (u, user) in ["010", "011", "012"].into_iter().enumerate() {
        let dir = root.join("Data").join(user).join("Trajectory");
        std::fs::create_dir_all(&dir).expect("folder");
        for day in 1..=2u32 {
            let mut s = String::from(
                "Geolife trajectory\nWGS 84\nAltitude is in Feet\nReserved 3\n\
                 0,2,255,My Track,0,0,2,8421376\n0\n",
            );
            let mut t = 0u32;
            for i in 0..70u32 {
                t += [1, 2, 3][(i % 3) as usize] + if i == 60 { 20 } else { 0 };
                let tf = f64::from(t);
                // each user's files their own (exact copies are left out of splits)
                let (lat, lon) = lat_lon(
                    2.0 * tf + (tf / 9.0).sin() * 4.0 + 100.0 * u as f64,
                    tf * f64::from(day),
                );
                let days = 39744.0 + f64::from(day) + f64::from(t) / 86400.0;
                let _ = writeln!(
                    s,
                    "{lat:.7},{lon:.7},0,100,{days:.10},2008-10-{:02},{:02}:{:02}:{:02}",
                    23 + day,
                    t / 3600,
                    (t / 60) % 60,
                    t % 60
                );
            }
            std::fs::write(dir.join(format!("2008102{day}000000.plt")), s).expect("file");
        }
    }
}

#[test]
fn a_protocol_runs_from_the_datasets_root_folder() {
    let root = scratch("geolife");
    write_geolife(&root);
    let out = run(&[
        "evaluate",
        "--protocol",
        "kf-dynamic-geolife",
        "--path",
        root.to_str().expect("path"),
    ]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(out.status.success(), "{stderr}");
    // 6 files split at their 20 s pause: 6 segments of at least 55 points (the rest is short)
    assert!(stderr.contains("read 3 of 3 units: 6 tracks"), "{stderr}");
    assert!(stderr.contains("6 segments of 12 kept"), "{stderr}");
    assert!(stdout.contains("| method | h = 10 | h = 20 | h = 30 | h = 40 | h = 50 | mean |"));
    assert!(stdout.contains("| 5-point linear |"), "{stdout}");
    // the protocol fixes the dataset: another one is refused
    let out = run(&[
        "evaluate",
        "--protocol",
        "kf-dynamic-geolife",
        "--dataset",
        "tdrive",
        "--path",
        root.to_str().expect("path"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("reads geolife, not tdrive"));
}

#[test]
fn predict_prints_the_frame_origin_and_times_steps_by_the_mean_interval() {
    let dir = scratch("predict");
    write_csv_folder(&dir);
    let file = dir.join("mon.csv");
    let out = run(&[
        "predict",
        "--input",
        file.to_str().expect("path"),
        "--method",
        "poly1",
        "--horizon",
        "2",
        "--history",
        "6",
        "--max-gap",
        "5",
        "--format",
        "json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["frame"]["kind"], "enu");
    let lat0 = v["frame"]["origin_lat_deg"].as_f64().expect("lat");
    assert!((lat0 - 39.9).abs() < 1e-3, "{v}");
    // the first segment of walker00 ends at fix 39 (t = 78 s after the first fix)
    assert_eq!(v["step_seconds"], 2.0);
    let t1 = v["steps"][0]["t"].as_f64().expect("t");
    let t0 = v["origin_time"].as_f64().expect("origin");
    assert_eq!(t1 - t0, 2.0);
    assert!(v["steps"][1]["lat_deg"].as_f64().is_some());
}

#[test]
fn a_huge_horizon_is_refused_before_any_model_is_sized_by_it() {
    let dir = scratch("horizon");
    write_csv_folder(&dir);
    let file = dir.join("mon.csv");
    for method in ["gskf", "kf-dynamic", "lstm"] {
        let out = run(&[
            "predict",
            "--input",
            file.to_str().expect("path"),
            "--method",
            method,
            "--horizon",
            "100000000000",
        ]);
        assert_eq!(out.status.code(), Some(1), "{method}");
        let err = text(&out.stderr);
        assert!(
            err.contains("--horizon must be between 1 and 100000"),
            "{err}"
        );
    }
    // a limit on the loaders, raised or lowered from the command line
    let out = run(&[
        "predict",
        "--input",
        file.to_str().expect("path"),
        "--method",
        "poly1",
        "--max-line-bytes",
        "10",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("max_line_bytes"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn charts_are_written_whole_or_not_at_all() {
    use trajpred::plot::{Chart, Series, write_chart};
    let dir = scratch("chart");
    let chart = Chart {
        title: "t".into(),
        x_label: "x".into(),
        y_label: "y".into(),
        series: vec![Series {
            label: "s".into(),
            points: vec![(0.0, 0.0), (1.0, 2.0), (2.0, 1.0)],
            markers: true,
        }],
        log_y: false,
    };
    let svg = dir.join("c.svg");
    std::fs::write(&svg, "old").expect("old file");
    write_chart(&chart, &svg).expect("writes");
    let text = std::fs::read_to_string(&svg).expect("svg");
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    // the rename cannot happen over a folder: the error names the output, and neither the
    // folder nor a temporary file is left changed behind
    let blocked = dir.join("blocked.png");
    std::fs::create_dir_all(blocked.join("inside")).expect("folder");
    match write_chart(&chart, &blocked) {
        Err(Error::Io(e)) => assert!(e.to_string().contains("blocked.png"), "{e}"),
        other => panic!("expected an I/O error naming the output, got {other:?}"),
    }
    assert!(blocked.join("inside").is_dir());
    let left: Vec<String> = std::fs::read_dir(&dir)
        .expect("dir")
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    assert!(left.iter().all(|n| !n.contains(".tmp")), "{left:?}");
}
