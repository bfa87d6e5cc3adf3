//! The real data of `../shared/data` (never copied into the repository), loaded through the
//! public API, against the counts of each folder's SOURCE.md and the independent figures of
//! `fixtures/data/real_data_reference.py` (plain Python + pymap3d 3.2.0; its output is
//! quoted beside each constant). Skips, saying so on stderr, when the folder is absent.

use std::path::{Path, PathBuf};
use trajpred_data::geodesy::Geodetic;
use trajpred_data::{LoadOptions, Projection, SkipReason, adsb, geolife, tdrive};

#[path = "../../../testing/skip.rs"]
mod skip;

fn data_dir(sub: &str) -> Option<PathBuf> {
    let p = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data")).join(sub);
    if p.is_dir() {
        Some(p)
    } else {
        skip::skipped(
            "trajpred-data/tests/real_data.rs",
            &format!("{} not found; real-data test not run", p.display()),
        );
        None
    }
}

/// The reference point of the GeoLife and T-Drive metre checks (Beijing).
fn beijing() -> Geodetic {
    Geodetic::new(39.9042, 116.4074, 0.0).unwrap()
}

/// Every point's east/north within the reference extents (pymap3d, same reference), and the
/// extremes reached to 1 m.
fn check_extents(tracks: &[trajpred_data::Track], want: [f64; 4]) {
    let mut got = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for t in tracks {
        for &e in t.trajectory.axis(0) {
            got[0] = got[0].min(e);
            got[1] = got[1].max(e);
        }
        for &n in t.trajectory.axis(1) {
            got[2] = got[2].min(n);
            got[3] = got[3].max(n);
        }
    }
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1.0, "extents {got:?} vs {want:?}");
    }
}

#[test]
fn geolife_counts_match_source_md() {
    let Some(dir) = data_dir("geolife/Data") else {
        return;
    };
    let opts = LoadOptions {
        projection: Projection::Enu(beijing()),
        ..LoadOptions::geolife()
    };
    let users = geolife::user_dirs(&dir).unwrap();
    assert_eq!(users.len(), 44); // SOURCE.md: 44 user folders
    // streamed one user at a time; the per-user counts of SOURCE.md
    let mut all = Vec::new();
    let mut report = trajpred_data::LoadReport::new();
    let mut labels = 0;
    for u in &users {
        let (t, r) = geolife::load_user(u, &opts).unwrap();
        let name = u.file_name().unwrap().to_string_lossy().into_owned();
        if name == "073" {
            assert_eq!((r.files_read, r.records_read), (112, 43_135)); // "073:112/43135"
        }
        if name == "060" {
            assert_eq!((r.files_read, r.records_read), (2, 17)); // "060:2/17"
        }
        let (l, lr) = geolife::load_labels(&u.join("labels.txt"), true).unwrap();
        assert_eq!(lr.skipped_total(), 0);
        labels += l.len();
        all.extend(t);
        report.merge(r);
    }
    eprintln!("GeoLife: {report}");
    // SOURCE.md: 1,334 .plt files, 504,551 points, 22,084 repeated timestamps, never backwards
    assert_eq!(report.files_read, 1_334);
    assert_eq!(report.records_read, 504_551);
    assert_eq!(report.header_lines, 6 * 1_334);
    assert_eq!(report.trajectories, 1_334);
    assert_eq!(report.skipped(SkipReason::RepeatedTimestamp), 22_084);
    assert_eq!(report.skipped_total(), 22_084);
    assert_eq!(report.points_kept, 504_551 - 22_084);
    assert_eq!(labels, 1_013); // SOURCE.md: 1,013 label rows
    // points per trajectory: min 3, max 12,371 before cleaning (SOURCE.md)
    assert!(all.iter().all(|t| t.trajectory.len() <= 12_371));
    // real_data_reference.py: enu_extents [-2400549.607860915, 515246.47293188126,
    // -1529751.1040730043, 873768.4650422418]
    check_extents(
        &all,
        [
            -2_400_549.607_860_915,
            515_246.472_931_881,
            -1_529_751.104_073_004,
            873_768.465_042_242,
        ],
    );
    // SOURCE.md: 2,853 gaps > 5 min inside single files -> 1,334 + 2,853 segments
    let mut n = 0;
    for t in &all {
        n += trajpred_data::segment::split_on_gaps(&t.trajectory, 300.0)
            .unwrap()
            .len();
    }
    assert_eq!(n, 1_334 + 2_853);
}

#[test]
fn tdrive_counts_match_source_md() {
    let Some(dir) = data_dir("tdrive/taxi_log_2008_by_id") else {
        return;
    };
    let opts = LoadOptions {
        projection: Projection::Enu(beijing()),
        ..LoadOptions::tdrive()
    };
    let (tracks, r) = tdrive::load_dir(&dir, &opts).unwrap();
    eprintln!("T-Drive: {r}");
    // the dataset's root lists the same files as its inner folder
    if let Some(root) = dir.parent() {
        assert_eq!(tdrive::files(root).unwrap(), tdrive::files(&dir).unwrap());
    }
    // SOURCE.md: 599 files, 848,964 points, 54,413 exact duplicate lines
    assert_eq!(r.files_read, 599);
    assert_eq!(r.records_read, 848_964);
    assert_eq!(r.skipped(SkipReason::DuplicateLine), 54_413);
    // SOURCE.md counts 195 points at (0,0) and 3,844 outside the box over all lines;
    // after removing the duplicate lines first, real_data_reference.py finds 186 at (0,0),
    // 2 with |lon| > 180 or |lat| > 90 (invalid) and 3,481 outside the box, then 199 repeated
    // timestamps and none going backwards.
    assert_eq!(r.skipped(SkipReason::ZeroPosition), 186);
    assert_eq!(r.skipped(SkipReason::InvalidCoordinate), 2);
    assert_eq!(r.skipped(SkipReason::OutsideBounds), 3_481);
    assert_eq!(r.skipped(SkipReason::RepeatedTimestamp), 199);
    assert_eq!(r.skipped(SkipReason::TimeBackwards), 0);
    assert_eq!(r.skipped(SkipReason::Malformed), 0); // "No line in the subset is malformed"
    assert_eq!(r.skipped(SkipReason::ForeignId), 0); // "every line's id equals its file name"
    assert_eq!(r.points_kept, 790_683);
    // 596 files keep at least one point (295.txt is empty); 6,722 gaps over 30 min split them
    assert_eq!(r.trajectories, 596 + 6_722);
    // taxi 534 is the largest (34,108 points)
    let n534: usize = tracks
        .iter()
        .filter(|t| t.id == "534" || t.id.starts_with("534#"))
        .map(|t| t.trajectory.len())
        .sum();
    assert!(n534 > 30_000 && n534 <= 34_108, "{n534}");
    check_extents(
        &tracks,
        [
            -85_377.452_931_678,
            99_955.965_009_399,
            -55_361.075_289_520,
            131_483.374_369_959,
        ],
    );
}

#[test]
fn adsb_counts_match_source_md() {
    let Some(dir) = data_dir("adsb-traffic/samples") else {
        return;
    };
    let opts = LoadOptions {
        altitude: false,
        max_gap: None,
        ..LoadOptions::adsb()
    };
    let files = adsb::files(&dir).unwrap();
    assert_eq!(files.len(), 71);
    let mut report = trajpred_data::LoadReport::new();
    let mut max_h: f64 = 0.0;
    for f in &files {
        let (tracks, r) = adsb::load_file(f, &opts).unwrap();
        for t in &tracks {
            let (e, n) = (t.trajectory.axis(0), t.trajectory.axis(1));
            for (x, y) in e.iter().zip(n) {
                max_h = max_h.max(x.hypot(*y));
            }
        }
        report.merge(r);
    }
    eprintln!("ADS-B 2-D: {report}");
    // SOURCE.md: 71 files, 638,454 points, 1,744 (icao24, callsign) groups (flight_id in calfire)
    assert_eq!(report.files_read, 71);
    assert_eq!(report.records_read, 638_454);
    assert_eq!(report.groups, 1_744);
    assert_eq!(report.trajectories, 1_744);
    // real_data_reference.py: 1,701 records without a position, 2,298 repeated timestamps
    // within a group, max horizontal distance from a flight's first point 3,244,254.6 m
    assert_eq!(report.skipped(SkipReason::MissingValue), 1_701);
    assert_eq!(report.skipped(SkipReason::RepeatedTimestamp), 2_298);
    assert_eq!(report.skipped(SkipReason::Malformed), 0);
    assert!((max_h - 3_244_254.612_812_138).abs() < 1.0, "{max_h}");
    // 3-D, on the two column-layout files with null altitudes (real_data_reference.py:
    // noisy_ground 924 records, 229 null altitudes; noisy_takeoff 730 and 130)
    for (name, records, nulls) in [
        ("noisy/noisy_ground", 924, 229),
        ("noisy/noisy_takeoff", 730, 130),
    ] {
        let f = dir.join(format!("{name}.json.gz"));
        let (tracks, r) = adsb::load_file(&f, &LoadOptions::adsb()).unwrap();
        assert_eq!((r.records_read, r.groups), (records, 1));
        assert_eq!(r.skipped(SkipReason::MissingValue), nulls);
        assert!(tracks.iter().all(|t| t.trajectory.dim() == 3));
    }
}
