//! Every loader on the hand-written fixtures of `fixtures/data/` (made by
//! `make_fixtures.py`; the expected counts and lines are annotated there, line by line).

use std::path::PathBuf;
use trajpred_core::Error as CoreError;
use trajpred_data::geodesy::{FOOT, Geodetic, LocalFrame};
use trajpred_data::{
    Error, Frame, LoadOptions, LoadReport, Projection, SkipReason, adsb, csvfile, geolife, tdrive,
};

fn fixture(rel: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data")).join(rel)
}

/// The lines skipped for `reason`.
fn lines(r: &LoadReport, reason: SkipReason) -> Vec<usize> {
    r.skips()
        .iter()
        .filter(|s| s.reason == reason)
        .map(|s| s.line)
        .collect()
}

fn check_invariant(r: &LoadReport) {
    assert_eq!(r.records_read, r.points_kept + r.skipped_total(), "{r}");
}

#[test]
fn geolife_user_with_crlf_repeats_and_malformed_lines() {
    let (tracks, r) =
        geolife::load_user(&fixture("geolife/Data/000"), &LoadOptions::geolife()).unwrap();
    check_invariant(&r);
    assert_eq!((r.files_read, r.groups, r.trajectories), (2, 2, 2));
    assert_eq!((r.records_read, r.header_lines, r.blank_lines), (12, 12, 1));
    assert_eq!(lines(&r, SkipReason::Malformed), vec![11, 12, 13]);
    assert_eq!(lines(&r, SkipReason::RepeatedTimestamp), vec![9]);
    assert_eq!(r.points_kept, 8);
    assert_eq!(tracks[0].id, "000/20081023025304");
    assert_eq!(tracks[0].first_line, 7);
    let tr = &tracks[0].trajectory;
    assert_eq!(tr.len(), 5);
    assert_eq!(tr.dim(), 2);
    // 2008-10-23 02:53:04 UTC = 1224730384 (`date -u -d ... +%s`)
    assert_eq!(tr.times()[0], 1_224_730_384.0);
    assert_eq!(tr.times()[1] - tr.times()[0], 6.0);
    // ENU around the first point, which is the origin
    let Frame::Enu(origin) = tracks[0].frame else {
        panic!("expected ENU, got {:?}", tracks[0].frame)
    };
    assert_eq!((origin.lat_deg, origin.lon_deg), (39.984702, 116.318417));
    let frame = LocalFrame::new(origin).unwrap();
    let p = frame.to_enu(&Geodetic::new(39.984683, 116.318450, 0.0).unwrap());
    assert!((tr.axis(0)[1] - p.east).abs() < 1e-9 && (tr.axis(1)[1] - p.north).abs() < 1e-9);
    // the line 9 point (repeated time) was dropped, the line 10 point kept
    assert!(
        (tr.axis(0)[2]
            - frame
                .to_enu(&Geodetic::new(39.984688, 116.318385, 0.0).unwrap())
                .east)
            .abs()
            < 1e-9
    );
}

#[test]
fn geolife_altitude_in_feet_and_unknown_altitude() {
    let opts = LoadOptions {
        altitude: true,
        projection: Projection::Geodetic,
        ..LoadOptions::geolife()
    };
    let f = fixture("geolife/Data/000/Trajectory/20081024020959.plt");
    let (tracks, r) = geolife::load_plt(&f, &opts).unwrap();
    check_invariant(&r);
    assert_eq!(lines(&r, SkipReason::MissingValue), vec![8]);
    let tr = &tracks[0].trajectory;
    assert_eq!(tracks[0].frame, Frame::Geodetic);
    assert_eq!(tr.axis(0), &[40.008304, 40.007171]);
    assert_eq!(tr.axis(2), &[492.0 * 0.3048, 491.0 * 0.3048]);
}

#[test]
fn geolife_strict_mode_names_the_first_bad_line() {
    let opts = LoadOptions {
        strict: true,
        ..LoadOptions::geolife()
    };
    let f = fixture("geolife/Data/000/Trajectory/20081023025304.plt");
    match geolife::load_plt(&f, &opts) {
        Err(Error::Parse { file, line, reason }) => {
            assert!(file.ends_with("20081023025304.plt"), "{file}");
            assert_eq!(line, 11);
            assert!(reason.contains("7 fields"), "{reason}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn geolife_labels() {
    let (labels, r) = geolife::load_labels(&fixture("geolife/Data/000/labels.txt"), false).unwrap();
    check_invariant(&r);
    assert_eq!(labels.len(), 2);
    assert_eq!(lines(&r, SkipReason::Malformed), vec![4, 5]);
    assert_eq!(
        geolife::mode_at(&labels, 1_224_730_384.0 + 10.0),
        Some("bus")
    );
    assert_eq!(geolife::mode_at(&labels, 1_224_730_384.0 + 60.0), None);
    assert!(matches!(
        geolife::load_labels(&fixture("geolife/Data/000/labels.txt"), true),
        Err(Error::Parse { line: 4, .. })
    ));
}

#[test]
fn geolife_data_dir_and_missing_dir() {
    let (tracks, r) = geolife::load_data_dir(&fixture("geolife"), &LoadOptions::geolife()).unwrap();
    assert_eq!((tracks.len(), r.files_read), (2, 2));
    match geolife::load_user(&fixture("geolife/Data/999"), &LoadOptions::geolife()) {
        Err(Error::Io { file, .. }) => assert!(file.contains("999"), "{file}"),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[test]
fn tdrive_cleaning_and_gap_split() {
    let (tracks, r) = tdrive::load_file(&fixture("tdrive/7.txt"), &LoadOptions::tdrive()).unwrap();
    check_invariant(&r);
    assert_eq!(r.records_read, 10);
    assert_eq!(lines(&r, SkipReason::DuplicateLine), vec![2]);
    assert_eq!(lines(&r, SkipReason::ZeroPosition), vec![4]);
    assert_eq!(lines(&r, SkipReason::OutsideBounds), vec![5]);
    assert_eq!(lines(&r, SkipReason::ForeignId), vec![6]);
    assert_eq!(lines(&r, SkipReason::Malformed), vec![7]);
    let ids: Vec<&str> = tracks.iter().map(|t| t.id.as_str()).collect();
    assert_eq!(ids, vec!["7", "7#1"]);
    assert_eq!(tracks[0].trajectory.len(), 3);
    assert_eq!(tracks[1].trajectory.len(), 2);
    assert_eq!(tracks[1].first_line, 9);
    // 2008-02-02 13:30:49 read as UTC = 1201959049
    assert_eq!(tracks[0].trajectory.times()[0], 1_201_959_049.0);
    // without the box, the Shanghai point stays and the gap around it splits differently
    let opts = LoadOptions {
        bbox: None,
        max_gap: None,
        ..LoadOptions::tdrive()
    };
    let (tracks, r) = tdrive::load_file(&fixture("tdrive/7.txt"), &opts).unwrap();
    assert_eq!(
        (
            tracks.len(),
            r.points_kept,
            r.skipped(SkipReason::OutsideBounds)
        ),
        (1, 6, 0)
    );
    // minimum length drops the 2-point segment, counted by points
    let opts = LoadOptions {
        min_points: 3,
        ..LoadOptions::tdrive()
    };
    let (tracks, r) = tdrive::load_file(&fixture("tdrive/7.txt"), &opts).unwrap();
    check_invariant(&r);
    assert_eq!(tracks.len(), 1);
    assert_eq!(r.skipped(SkipReason::ShortSegment), 2);
    assert_eq!(lines(&r, SkipReason::ShortSegment), vec![9]);
    let files = tdrive::files(&fixture("tdrive")).unwrap();
    assert_eq!(files.len(), 1);
}

#[test]
fn adsb_records_layout_plain_and_gzip_agree() {
    let opts = LoadOptions {
        projection: Projection::Geodetic,
        ..LoadOptions::adsb()
    };
    let (plain, r1) = adsb::load_file(&fixture("adsb/records.json"), &opts).unwrap();
    let (gz, r2) = adsb::load_file(&fixture("adsb/records.json.gz"), &opts).unwrap();
    assert_eq!(
        plain,
        gz.into_iter()
            .map(|mut t| {
                t.source = plain[0].source.clone();
                t
            })
            .collect::<Vec<_>>()
    );
    assert_eq!(r1.records_read, r2.records_read);
    check_invariant(&r1);
    assert_eq!(
        (r1.records_read, r1.groups, r1.trajectories, r1.points_kept),
        (11, 3, 3, 7)
    );
    assert_eq!(lines(&r1, SkipReason::Malformed), vec![7]);
    assert_eq!(lines(&r1, SkipReason::MissingValue), vec![5, 6]);
    assert_eq!(lines(&r1, SkipReason::RepeatedTimestamp), vec![4]);
    let ids: Vec<&str> = plain.iter().map(|t| t.id.as_str()).collect();
    assert_eq!(ids, vec!["484506/TRA051", "484506/TRA052", "3c6444/DLH1AB"]);
    // sorted by time, milliseconds to seconds, feet to metres
    let tr = &plain[0].trajectory;
    assert_eq!(
        tr.times(),
        &[1_527_693_698.0, 1_527_693_699.0, 1_527_693_700.0]
    );
    assert_eq!(tr.axis(0), &[52.3240, 52.3251, 52.3262]);
    assert_eq!(tr.axis(2), &[224.0 * FOOT, 262.0 * FOOT, 300.0 * FOOT]);
    // 2-D: the record with a null altitude is kept
    let opts2 = LoadOptions {
        altitude: false,
        ..opts
    };
    let (t2, r3) = adsb::load_file(&fixture("adsb/records.json"), &opts2).unwrap();
    assert_eq!(
        (t2[0].trajectory.len(), r3.skipped(SkipReason::MissingValue)),
        (4, 1)
    );
    // a short max_gap splits the DLH1AB flight (10 s between its two points)
    let opts3 = LoadOptions {
        max_gap: Some(5.0),
        ..opts
    };
    let (t3, _) = adsb::load_file(&fixture("adsb/records.json"), &opts3).unwrap();
    assert_eq!(t3.last().unwrap().id, "3c6444/DLH1AB#1");
}

#[test]
fn adsb_columns_layout() {
    let (tracks, r) =
        adsb::load_file(&fixture("adsb/columns.json.gz"), &LoadOptions::adsb()).unwrap();
    check_invariant(&r);
    assert_eq!((r.records_read, r.groups, tracks.len()), (4, 1, 1));
    assert_eq!(lines(&r, SkipReason::MissingValue), vec![3]);
    let tr = &tracks[0].trajectory;
    assert_eq!(tr.dim(), 3);
    assert_eq!(
        tr.times(),
        &[1_576_068_400.0, 1_576_068_410.0, 1_576_068_430.0]
    );
    assert_eq!(tracks[0].id, "39c902/FHMAC");
    // ENU at the first point: the first point is the origin, up = altitude difference
    assert_eq!(
        (tr.axis(0)[0], tr.axis(1)[0], tr.axis(2)[0]),
        (0.0, 0.0, 0.0)
    );
    assert!(tr.axis(2)[2] > 0.0);
    assert_eq!(adsb::files(&fixture("adsb")).unwrap().len(), 3);
}

#[test]
fn adsb_bad_documents_are_typed_errors() {
    let mut r = LoadReport::new();
    let o = LoadOptions::adsb();
    assert!(matches!(
        adsb::parse_json(b"[1, 2", "x", &o, &mut r),
        Err(Error::Parse { line: 1, .. })
    ));
    assert!(matches!(
        adsb::parse_json(b"42", "x", &o, &mut r),
        Err(Error::Parse { line: 1, .. })
    ));
    assert!(matches!(
        adsb::parse_json(b"", "x", &o, &mut r),
        Err(Error::Parse { .. })
    ));
    assert!(matches!(
        adsb::parse_json(br#"{"timestamp": {"a": 1}}"#, "x", &o, &mut r),
        Err(Error::Parse { .. })
    ));
    // records of the wrong type are counted, not fatal
    let mut r = LoadReport::new();
    let t = adsb::parse_json(b"[1, \"a\", null]", "x", &o, &mut r).unwrap();
    assert!(t.is_empty());
    assert_eq!(lines(&r, SkipReason::Malformed), vec![1, 2, 3]);
    // a column value of the wrong type marks its row (index + 1) malformed
    let mut r = LoadReport::new();
    let cols = br#"{"timestamp":{"0":1000,"1":2000},"latitude":{"0":"x","1":1.0},"longitude":{"0":1.0,"1":1.0}}"#;
    let t = adsb::parse_json(cols, "x", &LoadOptions::default(), &mut r).unwrap();
    assert_eq!((t.len(), r.records_read), (1, 2));
    assert_eq!(lines(&r, SkipReason::Malformed), vec![1]);
    let strict = LoadOptions { strict: true, ..o };
    assert!(matches!(
        adsb::parse_json(b"[{}, 1]", "x", &strict, &mut LoadReport::new()),
        Err(Error::Parse { line: 2, .. })
    ));
}

#[test]
fn csv_metres_and_degrees() {
    let (tracks, r) = csvfile::load_file(&fixture("csv/xy.csv"), &LoadOptions::default()).unwrap();
    check_invariant(&r);
    assert_eq!(lines(&r, SkipReason::MissingValue), vec![4]);
    assert_eq!(lines(&r, SkipReason::Malformed), vec![6]);
    assert_eq!(tracks[0].trajectory.times(), &[0.0, 1.0, 3.0, 5.0]);
    assert_eq!(tracks[0].trajectory.axis(1), &[0.0, 0.5, 1.5, 2.5]);
    assert_eq!(tracks[0].id, "xy");

    let opts = LoadOptions {
        altitude: true,
        projection: Projection::Geodetic,
        ..LoadOptions::default()
    };
    let (tracks, r) = csvfile::load_file(&fixture("csv/latlon.csv.gz"), &opts).unwrap();
    check_invariant(&r);
    assert_eq!(r.points_kept, 3);
    let tr = &tracks[0].trajectory;
    assert_eq!(tr.axis(0), &[39.9, 39.9001, 39.9002]);
    assert_eq!(tr.axis(1), &[116.4, 116.4001, 116.4002]);
    assert_eq!(tr.axis(2), &[50.0, 51.0, 52.0]);
}

#[test]
fn csv_errors() {
    let o = LoadOptions::default();
    let mut r = LoadReport::new();
    assert!(matches!(
        csvfile::parse(&b"a,b\n1,2\n"[..], "m", &o, &mut r),
        Err(Error::Parse { line: 1, .. })
    ));
    assert!(matches!(
        csvfile::parse(&b""[..], "m", &o, &mut r),
        Err(Error::Parse { line: 1, .. })
    ));
    let strict = LoadOptions {
        strict: true,
        ..o.clone()
    };
    assert!(matches!(
        csvfile::parse(&b"t,x,y\n0,0,0\n1,zz,0\n"[..], "m", &strict, &mut r),
        Err(Error::Parse { line: 3, .. })
    ));
    // non-increasing time in the user's file: the fewest points are dropped, and counted;
    // the 2 at line 3 runs ahead of the 1, 2, 3 that follow it (an outlier)
    let mut r = LoadReport::new();
    let t = csvfile::parse(
        &b"t,x,y\n0,0,0\n2,1,1\n1,2,2\n2,3,3\n3,4,4\n"[..],
        "m",
        &o,
        &mut r,
    )
    .unwrap();
    check_invariant(&r);
    assert_eq!(t[0].trajectory.times(), &[0.0, 1.0, 2.0, 3.0]);
    assert_eq!(lines(&r, SkipReason::TimeOutlier), vec![3]);
    assert_eq!(r.skipped(SkipReason::TimeBackwards), 0);
    // a point behind the track (line 6) is dropped as going backwards, a repeat as repeated
    let mut r = LoadReport::new();
    let t = csvfile::parse(
        &b"t,x,y\n0,0,0\n1,1,1\n1,9,9\n2,2,2\n0.5,3,3\n3,4,4\n"[..],
        "m",
        &o,
        &mut r,
    )
    .unwrap();
    check_invariant(&r);
    assert_eq!(t[0].trajectory.times(), &[0.0, 1.0, 2.0, 3.0]);
    assert_eq!(t[0].trajectory.axis(0), &[0.0, 1.0, 2.0, 4.0]);
    assert_eq!(lines(&r, SkipReason::RepeatedTimestamp), vec![4]);
    assert_eq!(lines(&r, SkipReason::TimeBackwards), vec![6]);
}

#[test]
fn invalid_options_are_rejected() {
    let bad = LoadOptions {
        max_gap: Some(-1.0),
        ..LoadOptions::default()
    };
    assert!(matches!(
        tdrive::load_file(&fixture("tdrive/7.txt"), &bad),
        Err(Error::Core(CoreError::InvalidParameter {
            name: "max_gap",
            ..
        }))
    ));
    let bad = LoadOptions {
        min_points: 0,
        ..LoadOptions::default()
    };
    assert!(matches!(
        csvfile::load_file(&fixture("csv/xy.csv"), &bad),
        Err(Error::Core(CoreError::InvalidParameter {
            name: "min_points",
            ..
        }))
    ));
    assert!(matches!(
        trajpred_data::BoundingBox::new(40.0, 39.0, 116.0, 117.0),
        Err(Error::Core(CoreError::InvalidParameter {
            name: "bbox",
            ..
        }))
    ));
}

#[test]
fn shared_reference_projection() {
    let beijing = Geodetic::new(39.9042, 116.4074, 0.0).unwrap();
    let opts = LoadOptions {
        projection: Projection::Enu(beijing),
        ..LoadOptions::tdrive()
    };
    let (tracks, _) = tdrive::load_file(&fixture("tdrive/7.txt"), &opts).unwrap();
    let frame = LocalFrame::new(beijing).unwrap();
    let want = frame.to_enu(&Geodetic::new(39.80000, 116.70000, 0.0).unwrap());
    let tr = &tracks[1].trajectory;
    assert!((tr.axis(0)[0] - want.east).abs() < 1e-9 && (tr.axis(1)[0] - want.north).abs() < 1e-9);
    assert!(tracks.iter().all(|t| t.frame == Frame::Enu(beijing)));
}

/// A fresh, empty folder under the system's temporary folder.
fn scratch(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("trajpred-data-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    std::fs::create_dir_all(&p).unwrap();
    p
}

#[test]
fn tdrive_root_folder_is_descended_into() {
    // the dataset's layout: tdrive/taxi_log_2008_by_id/*.txt
    let root = scratch("tdrive-root");
    let inner = root.join(tdrive::INNER_DIR);
    std::fs::create_dir_all(&inner).unwrap();
    std::fs::copy(fixture("tdrive/7.txt"), inner.join("7.txt")).unwrap();
    std::fs::write(root.join("SOURCE.md"), "not a taxi log\n").unwrap();
    let files = tdrive::files(&root).unwrap();
    assert_eq!(files, vec![inner.join("7.txt")]);
    let (from_root, r1) = tdrive::load_dir(&root, &LoadOptions::tdrive()).unwrap();
    let (from_inner, r2) = tdrive::load_dir(&inner, &LoadOptions::tdrive()).unwrap();
    assert_eq!((r1.files_read, r1.trajectories), (1, 2));
    assert_eq!((from_root, r1), (from_inner, r2));
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn track_groups_name_the_user_or_vehicle() {
    // GeoLife: the root and its Data/ folder alike; the group is the user
    let root = geolife::user_dirs(&fixture("geolife")).unwrap();
    let data = geolife::user_dirs(&fixture("geolife/Data")).unwrap();
    assert_eq!(root, data);
    assert_eq!(root, vec![fixture("geolife/Data/000")]);
    let (a, _) = geolife::load_data_dir(&fixture("geolife"), &LoadOptions::geolife()).unwrap();
    let (b, _) = geolife::load_data_dir(&fixture("geolife/Data"), &LoadOptions::geolife()).unwrap();
    assert_eq!(a, b);
    let groups: Vec<(&str, &str)> = a
        .iter()
        .map(|t| (t.id.as_str(), t.group.as_str()))
        .collect();
    assert_eq!(
        groups,
        [("000/20081023025304", "000"), ("000/20081024020959", "000")]
    );
    // T-Drive: the taxi id, on every segment
    let (t, _) = tdrive::load_file(&fixture("tdrive/7.txt"), &LoadOptions::tdrive()).unwrap();
    let groups: Vec<(&str, &str)> = t
        .iter()
        .map(|t| (t.id.as_str(), t.group.as_str()))
        .collect();
    assert_eq!(groups, [("7", "7"), ("7#1", "7")]);
    // ADS-B: the aircraft (icao24), whatever the callsign
    let (t, _) = adsb::load_file(&fixture("adsb/records.json"), &LoadOptions::adsb()).unwrap();
    let groups: Vec<&str> = t.iter().map(|t| t.group.as_str()).collect();
    assert_eq!(groups, ["484506", "484506", "3c6444"]);
    // CSV: the file stem
    let (t, _) = csvfile::load_file(&fixture("csv/xy.csv"), &LoadOptions::default()).unwrap();
    assert_eq!(t[0].group, "xy");
    // a GeoLife user folder with no Trajectory/ gives no user; an empty root no user either
    let empty = scratch("geolife-empty");
    assert!(geolife::user_dirs(&empty).unwrap().is_empty());
    let _ = std::fs::remove_dir_all(&empty);
}
