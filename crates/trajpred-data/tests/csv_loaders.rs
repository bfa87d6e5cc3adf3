//! The CSV loader on the small files of `fixtures/data/csv/` (written by hand, values made
//! up): folders, track columns, time units, bytes that are not UTF-8, NaN coordinates,
//! repeated timestamps and a time outlier.

use std::path::PathBuf;
use trajpred_data::{
    Error, Frame, LoadOptions, LoadReport, Projection, SkipReason, TimeUnit, csvfile,
};

fn fixture(rel: &str) -> PathBuf {
    PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/data/csv"
    ))
    .join(rel)
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

/// 2008-10-23T02:53:04Z (`date -u -d '2008-10-23 02:53:04' +%s`).
const T0: f64 = 1_224_730_384.0;

fn geodetic() -> LoadOptions {
    LoadOptions {
        projection: Projection::Geodetic,
        ..LoadOptions::default()
    }
}

#[test]
fn load_path_reads_every_csv_file_of_a_folder_sorted_not_recursively() {
    let (tracks, r) = csvfile::load_path(&fixture("folder"), &LoadOptions::default()).unwrap();
    check_invariant(&r);
    // notes.txt and sub/c_ignored.csv are not read
    assert_eq!((r.files_read, r.trajectories, r.points_kept), (2, 2, 5));
    let ids: Vec<&str> = tracks.iter().map(|t| t.id.as_str()).collect();
    assert_eq!(ids, ["a_monday", "b_tuesday"]);
    assert!(tracks[1].source.ends_with("b_tuesday.csv.gz"));
    assert_eq!(tracks[1].trajectory.times(), &[10.0, 11.0]);
    let units: Vec<(&str, TimeUnit)> = r
        .time_units()
        .iter()
        .map(|(f, u)| (f.rsplit('/').next().unwrap_or(""), *u))
        .collect();
    assert_eq!(
        units,
        [
            ("a_monday.csv", TimeUnit::Seconds),
            ("b_tuesday.csv.gz", TimeUnit::Seconds)
        ]
    );
    assert_eq!(csvfile::files(&fixture("folder")).unwrap().len(), 2);
    // a file given to load_path is loaded like load_file
    let (one, r1) = csvfile::load_path(&fixture("xy.csv"), &LoadOptions::default()).unwrap();
    let (same, r2) = csvfile::load_file(&fixture("xy.csv"), &LoadOptions::default()).unwrap();
    assert_eq!((one, r1), (same, r2));
}

#[test]
fn load_path_on_a_folder_without_csv_names_the_folder() {
    match csvfile::load_path(&fixture("no_csv"), &LoadOptions::default()) {
        Err(Error::Layout { path, reason }) => {
            assert!(path.ends_with("no_csv"), "{path}");
            assert!(reason.contains("csv"), "{reason}");
        }
        other => panic!("expected a layout error, got {other:?}"),
    }
    match csvfile::load_path(&fixture("does_not_exist"), &LoadOptions::default()) {
        Err(Error::Io { file, .. }) => assert!(file.ends_with("does_not_exist"), "{file}"),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[test]
fn track_column_splits_a_file_into_trajectories_in_order_of_first_appearance() {
    // ISO 8601 with Z; the two buses' rows interleave; extra columns are ignored
    let (tracks, r) = csvfile::load_file(&fixture("vehicles_iso.csv"), &geodetic()).unwrap();
    check_invariant(&r);
    assert_eq!((r.groups, r.trajectories, r.points_kept), (2, 2, 6));
    let ids: Vec<&str> = tracks.iter().map(|t| t.id.as_str()).collect();
    assert_eq!(ids, ["vehicles_iso/bus-12", "vehicles_iso/bus-7"]);
    assert_eq!(tracks[0].group, "vehicles_iso/bus-12");
    assert_eq!(tracks[0].trajectory.times(), &[T0, T0 + 6.0, T0 + 12.0]);
    assert_eq!(
        tracks[1].trajectory.times(),
        &[T0 + 1.0, T0 + 11.0, T0 + 21.0]
    );
    assert_eq!(tracks[1].trajectory.axis(0), &[39.99, 39.9901, 39.9902]);
    assert_eq!(tracks[1].first_line, 3);
    assert_eq!(r.time_units()[0].1, TimeUnit::Iso8601);

    // `id` column, epoch milliseconds, non-contiguous rows of one id
    let (tracks, r) = csvfile::load_file(&fixture("phone_epoch_ms.csv"), &geodetic()).unwrap();
    check_invariant(&r);
    let ids: Vec<&str> = tracks.iter().map(|t| t.id.as_str()).collect();
    assert_eq!(ids, ["phone_epoch_ms/walk", "phone_epoch_ms/drive"]);
    assert_eq!(tracks[0].trajectory.times(), &[T0, T0 + 6.0, T0 + 12.0]);
    assert_eq!(tracks[1].trajectory.times(), &[T0 + 7.5, T0 + 17.5]);
    assert_eq!(r.time_units()[0].1, TimeUnit::EpochMillis);
    assert_eq!(r.time_units()[0].1.to_string(), "epoch milliseconds");

    // segments of one id keep its group
    let split = LoadOptions {
        max_gap: Some(5.0),
        ..geodetic()
    };
    let (tracks, _) = csvfile::load_file(&fixture("phone_epoch_ms.csv"), &split).unwrap();
    let ids: Vec<(&str, &str)> = tracks
        .iter()
        .map(|t| (t.id.as_str(), t.group.as_str()))
        .collect();
    assert_eq!(
        ids,
        [
            ("phone_epoch_ms/walk", "phone_epoch_ms/walk"),
            ("phone_epoch_ms/walk#1", "phone_epoch_ms/walk"),
            ("phone_epoch_ms/walk#2", "phone_epoch_ms/walk"),
            ("phone_epoch_ms/drive", "phone_epoch_ms/drive"),
            ("phone_epoch_ms/drive#1", "phone_epoch_ms/drive"),
        ]
    );
}

#[test]
fn empty_track_value_is_a_missing_value() {
    let mut r = LoadReport::new();
    let t = csvfile::parse(
        &b"track,t,x,y\na,0,0,0\n,1,1,1\na,2,2,2\n"[..],
        "mem.csv",
        &LoadOptions::default(),
        &mut r,
    )
    .unwrap();
    check_invariant(&r);
    assert_eq!(t.len(), 1);
    assert_eq!(t[0].id, "mem/a");
    assert_eq!(lines(&r, SkipReason::MissingValue), vec![3]);
}

#[test]
fn iso_with_a_space_and_fractional_seconds() {
    let (tracks, r) =
        csvfile::load_file(&fixture("logger_iso_space.csv"), &LoadOptions::default()).unwrap();
    check_invariant(&r);
    assert_eq!(tracks[0].frame, Frame::Cartesian);
    assert_eq!(
        tracks[0].trajectory.times(),
        &[T0 + 0.5, T0 + 1.5, T0 + 2.0]
    );
    assert_eq!(r.time_units()[0].1, TimeUnit::Iso8601);
}

#[test]
fn a_time_column_mixing_units_is_a_parse_error_at_the_first_disagreeing_line() {
    match csvfile::load_file(&fixture("mixed_iso_and_seconds.csv"), &geodetic()) {
        Err(Error::Parse { file, line, reason }) => {
            assert!(file.ends_with("mixed_iso_and_seconds.csv"), "{file}");
            assert_eq!(line, 4);
            assert!(
                reason.contains("seconds") && reason.contains("ISO 8601"),
                "{reason}"
            );
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    // line 4 is blank: the milliseconds are on line 5
    match csvfile::load_file(&fixture("mixed_seconds_and_millis.csv"), &geodetic()) {
        Err(Error::Parse { file, line, reason }) => {
            assert!(file.ends_with("mixed_seconds_and_millis.csv"), "{file}");
            assert_eq!(line, 5);
            assert!(reason.contains("epoch milliseconds"), "{reason}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    // a malformed time does not decide the unit: it is skipped
    let mut r = LoadReport::new();
    let t = csvfile::parse(
        &b"t,x,y\nsoon,0,0\n2008-10-23T02:53:04,1,1\n"[..],
        "m",
        &LoadOptions::default(),
        &mut r,
    )
    .unwrap();
    assert_eq!(t[0].trajectory.times(), &[T0]);
    assert_eq!(lines(&r, SkipReason::Malformed), vec![2]);
}

#[test]
fn bytes_that_are_not_utf8_in_any_column_are_a_counted_skip_or_a_strict_error() {
    let (tracks, r) = csvfile::load_file(&fixture("latin1_place.csv"), &geodetic()).unwrap();
    check_invariant(&r);
    assert_eq!(tracks[0].trajectory.times(), &[T0, T0 + 12.0]);
    let bad: Vec<(usize, SkipReason, &str)> = r
        .skips()
        .iter()
        .map(|s| (s.line, s.reason, s.detail.as_str()))
        .collect();
    assert_eq!(bad, [(3, SkipReason::Malformed, "not UTF-8")]);
    let strict = LoadOptions {
        strict: true,
        ..geodetic()
    };
    match csvfile::load_file(&fixture("latin1_place.csv"), &strict) {
        Err(Error::Parse { line, reason, .. }) => {
            assert_eq!(line, 3);
            assert_eq!(reason, "not UTF-8");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn nan_coordinates_are_counted_invalid_and_never_kept() {
    let (tracks, r) =
        csvfile::load_file(&fixture("nan_coordinate.csv"), &LoadOptions::default()).unwrap();
    check_invariant(&r);
    assert_eq!(lines(&r, SkipReason::InvalidCoordinate), vec![4, 5]);
    assert_eq!(r.skipped(SkipReason::Malformed), 0);
    let tr = &tracks[0].trajectory;
    assert_eq!(tr.times(), &[0.0, 1.0, 4.0]);
    assert!(tr.axes().all(|a| a.iter().all(|v| v.is_finite())));
    // in strict mode the NaN is an error naming its line
    let strict = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    assert!(matches!(
        csvfile::load_file(&fixture("nan_coordinate.csv"), &strict),
        Err(Error::Parse { line: 4, .. })
    ));
    // geodetic: a NaN latitude too
    let mut r = LoadReport::new();
    let t = csvfile::parse(
        &b"t,lat,lon\n0,39.9,116.4\n1,NaN,116.4\n2,39.9,inf\n3,39.9,116.4\n"[..],
        "m",
        &geodetic(),
        &mut r,
    )
    .unwrap();
    assert_eq!(t[0].trajectory.times(), &[0.0, 3.0]);
    assert_eq!(lines(&r, SkipReason::InvalidCoordinate), vec![3, 4]);
}

#[test]
fn every_timestamp_twice_keeps_the_first_of_each_and_counts_the_repeats() {
    let (tracks, r) = csvfile::load_file(&fixture("repeated_timestamps.csv"), &geodetic()).unwrap();
    check_invariant(&r);
    assert_eq!(r.records_read, 8);
    assert_eq!(lines(&r, SkipReason::RepeatedTimestamp), vec![3, 5, 7, 9]);
    assert_eq!(r.skipped_total(), 4);
    let tr = &tracks[0].trajectory;
    assert_eq!(tr.times(), &[T0, T0 + 6.0, T0 + 12.0, T0 + 18.0]);
    assert_eq!(tracks[0].first_line, 2);
}

#[test]
fn one_timestamp_far_in_the_future_is_dropped_alone() {
    let (tracks, r) = csvfile::load_file(&fixture("future_outlier.csv"), &geodetic()).unwrap();
    check_invariant(&r);
    assert_eq!(lines(&r, SkipReason::TimeOutlier), vec![5]);
    assert_eq!(r.skipped(SkipReason::TimeBackwards), 0);
    assert_eq!(r.skipped_total(), 1);
    assert_eq!(tracks.len(), 1);
    let tr = &tracks[0].trajectory;
    assert_eq!(
        tr.times(),
        &[T0, T0 + 6.0, T0 + 12.0, T0 + 18.0, T0 + 24.0, T0 + 30.0]
    );
    assert_eq!(tr.axis(0)[3], 39.984655);
}

#[test]
fn line_numbers_count_empty_lines_crlf_and_quoted_line_ends() {
    let mut r = LoadReport::new();
    let input =
        b"t,x,y,note\r\n0,0,0,a\r\n\r\n\r\n1,zz,1,b\r\n2,2,2,\"two\nlines\"\r\n3,zz,3,c\r\n\r\n";
    let t = csvfile::parse(&input[..], "m", &LoadOptions::default(), &mut r).unwrap();
    check_invariant(&r);
    assert_eq!(t[0].trajectory.times(), &[0.0, 2.0]);
    assert_eq!(lines(&r, SkipReason::Malformed), vec![5, 8]);
    assert_eq!((r.header_lines, r.blank_lines), (1, 3));
}
