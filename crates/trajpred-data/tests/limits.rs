//! The loaders' limits (`LoadOptions::max_*`): a gzip bomb, an endless line, a file or a
//! track with too many points each stop with `Error::LimitExceeded` naming the file, the line
//! where known and the option to raise, never an abort on a huge allocation. Inputs are
//! generated here (nothing big is committed).

use flate2::Compression;
use flate2::write::GzEncoder;
use std::io::Write;
use std::path::PathBuf;
use trajpred_core::Error as CoreError;
use trajpred_data::{
    Error, LoadOptions, LoadReport, MAX_JSON_BYTES, MAX_LINE_BYTES, SkipReason, adsb, csvfile,
    geolife, tdrive,
};

/// A file in the temporary folder, removed when dropped.
struct TempFile(PathBuf);

impl TempFile {
    fn new(name: &str, bytes: &[u8]) -> Self {
        let p = std::env::temp_dir().join(format!("trajpred-limits-{}-{name}", std::process::id()));
        std::fs::write(&p, bytes).unwrap();
        TempFile(p)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// A gzip stream of `members` concatenated members, each `member_mib` MiB of `byte`: a
/// small file that decompresses to `members * member_mib` MiB.
fn gzip_bomb(byte: u8, member_mib: usize, members: usize) -> Vec<u8> {
    let mut enc = GzEncoder::new(Vec::new(), Compression::best());
    let chunk = vec![byte; 1 << 20];
    for _ in 0..member_mib {
        enc.write_all(&chunk).unwrap();
    }
    let member = enc.finish().unwrap();
    member.repeat(members)
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut enc = GzEncoder::new(Vec::new(), Compression::fast());
    enc.write_all(bytes).unwrap();
    enc.finish().unwrap()
}

/// Asserts a `LimitExceeded` for `option` at `line`, with a message naming the file and the
/// option.
#[track_caller]
fn assert_limit<T: std::fmt::Debug>(
    res: Result<T, Error>,
    option: &str,
    line: Option<usize>,
    file_part: &str,
) {
    match res {
        Err(e @ Error::LimitExceeded { .. }) => {
            let msg = e.to_string();
            let Error::LimitExceeded {
                file,
                line: l,
                option: o,
                ..
            } = e
            else {
                unreachable!()
            };
            assert_eq!(o, option, "{msg}");
            assert_eq!(l, line, "{msg}");
            assert!(file.contains(file_part), "{msg}");
            assert!(msg.contains(option), "{msg}");
        }
        other => panic!("expected LimitExceeded for {option}, got {other:?}"),
    }
}

const PLT_HEADER: &str = "Geolife trajectory\r\nWGS 84\r\nAltitude is in Feet\r\nReserved 3\r\n0,2,255,My Track,0,0,2,8421376\r\n0\r\n";

fn plt_lines(n: usize, lat: f64) -> String {
    let mut s = PLT_HEADER.to_string();
    for k in 0..n {
        s.push_str(&format!(
            "{lat},116.318417,0,492,39744.12,2008-10-23,02:{:02}:{:02}\r\n",
            k / 60,
            k % 60
        ));
    }
    s
}

fn tdrive_lines(n: usize) -> String {
    (0..n)
        .map(|k| format!("7,2008-02-02 13:{:02}:{:02},116.76,39.79\n", k / 60, k % 60))
        .collect()
}

fn csv_lines(n: usize) -> String {
    let mut s = "t,x,y\n".to_string();
    for k in 0..n {
        s.push_str(&format!("{k},{k},0\n"));
    }
    s
}

/// A 2 GiB gzip bomb of zero bytes (2 MB on disk) under the default options: every text
/// loader stops at the end of the first MiB (no line end in sight), naming line 1.
#[test]
fn a_gzip_bomb_stops_at_the_line_limit_with_default_options() {
    let bomb = gzip_bomb(0, 16, 128);
    assert!(bomb.len() < 4 << 20);
    let opts = LoadOptions::default();
    let plt = TempFile::new("bomb.plt", &bomb);
    assert_limit(
        geolife::load_plt(&plt.0, &opts),
        "max_line_bytes",
        Some(1),
        "bomb.plt",
    );
    let txt = TempFile::new("bomb.txt", &bomb);
    assert_limit(
        tdrive::load_file(&txt.0, &opts),
        "max_line_bytes",
        Some(1),
        "bomb.txt",
    );
    let csv = TempFile::new("bomb.csv.gz", &bomb);
    assert_limit(
        csvfile::load_file(&csv.0, &opts),
        "max_line_bytes",
        Some(1),
        "bomb.csv.gz",
    );
    assert_eq!(opts.max_line_bytes, MAX_LINE_BYTES);
}

/// Short lines all the way (a bomb of newlines): the decompressed-size limit stops it.
#[test]
fn a_bomb_of_short_lines_stops_at_the_file_size_limit() {
    let bomb = gzip_bomb(b'\n', 4, 4); // 16 MiB of empty lines
    let opts = LoadOptions {
        max_file_bytes: 1 << 20,
        ..LoadOptions::default()
    };
    let want_line = Some((1 << 20) + 1);
    let plt = TempFile::new("lines.plt", &bomb);
    assert_limit(
        geolife::load_plt(&plt.0, &opts),
        "max_file_bytes",
        want_line,
        "lines.plt",
    );
    let txt = TempFile::new("lines.txt", &bomb);
    assert_limit(
        tdrive::load_file(&txt.0, &opts),
        "max_file_bytes",
        want_line,
        "lines.txt",
    );
    // the CSV reader sees blocks, not lines: the line is where the block crossing the limit
    // began
    let csv = TempFile::new("lines.csv", &bomb);
    match csvfile::load_file(&csv.0, &opts) {
        Err(Error::LimitExceeded {
            option: "max_file_bytes",
            line: Some(l),
            limit,
            ..
        }) => {
            assert!(l <= (1 << 20) + 1, "{l}");
            assert_eq!(limit, 1 << 20);
        }
        other => panic!("{other:?}"),
    }
    // exactly at the limit is accepted: 1 MiB of empty lines
    let ok = TempFile::new("ok.txt", &gzip(&vec![b'\n'; 1 << 20]));
    let (tracks, report) = tdrive::load_file(&ok.0, &opts).unwrap();
    assert!(tracks.is_empty());
    assert_eq!(report.blank_lines, 1 << 20);
}

/// A JSON document is read whole: beyond `max_json_bytes` (decompressed) it is refused
/// before it is parsed.
#[test]
fn a_json_bomb_stops_at_the_json_size_limit() {
    let bomb = gzip_bomb(b' ', 4, 2); // 8 MiB of spaces
    let opts = LoadOptions {
        max_json_bytes: 1 << 20,
        ..LoadOptions::adsb()
    };
    let f = TempFile::new("bomb.json.gz", &bomb);
    assert_limit(
        adsb::load_file(&f.0, &opts),
        "max_json_bytes",
        None,
        "bomb.json.gz",
    );
    // a document of exactly the limit is read (and is then not JSON)
    let exact = TempFile::new("exact.json.gz", &gzip(&vec![b' '; 1 << 20]));
    assert!(matches!(
        adsb::load_file(&exact.0, &opts),
        Err(Error::Parse { .. })
    ));
    assert_eq!(LoadOptions::default().max_json_bytes, MAX_JSON_BYTES);
}

/// A line of `max_line_bytes` bytes is read; one byte more is an error naming its line, in
/// every text format (line ends do not count).
#[test]
fn a_line_longer_than_the_limit_names_its_line() {
    let opts = LoadOptions {
        max_line_bytes: 80,
        ..LoadOptions::default()
    };
    let pad = |s: &str, len: usize| format!("{s}{}", " ".repeat(len - s.len()));
    // GeoLife: line 8 (after 6 header lines and one good line)
    let good = "39.984702,116.318417,0,492,39744.1201851852,2008-10-23,02:53:04";
    let plt = format!(
        "{PLT_HEADER}{}\r\n{}\r\n",
        pad(good, 80),
        pad(
            "39.984683,116.318450,0,492,39744.12,2008-10-23,02:53:10",
            81
        )
    );
    let mut r = LoadReport::new();
    assert_limit(
        geolife::parse_plt(plt.as_bytes(), "long.plt", "u/long", &opts, &mut r),
        "max_line_bytes",
        Some(8),
        "long.plt",
    );
    let mut r = LoadReport::new();
    let fine = format!("{PLT_HEADER}{}\r\n", pad(good, 80));
    assert_eq!(
        geolife::parse_plt(fine.as_bytes(), "ok.plt", "u/ok", &opts, &mut r)
            .unwrap()
            .len(),
        1
    );
    // T-Drive: line 2
    let t = format!(
        "7,2008-02-02 13:30:49,116.76038,39.79758\n7,2008-02-02 13:35:49,116.76135,{}\n",
        "3".repeat(60)
    );
    let mut r = LoadReport::new();
    assert_limit(
        tdrive::parse(t.as_bytes(), "long.txt", &opts, &mut r),
        "max_line_bytes",
        Some(2),
        "long.txt",
    );
    // CSV: line 3, a long unquoted field; then a long quoted one
    let c = format!("t,x,y\n0,0,0\n1,1,{}\n", "1".repeat(100));
    let mut r = LoadReport::new();
    assert_limit(
        csvfile::parse(c.as_bytes(), "long.csv", &opts, &mut r),
        "max_line_bytes",
        Some(3),
        "long.csv",
    );
    let c = format!("t,x,y\n0,0,0\n\n1,1,\"{}\"\n", "1".repeat(100));
    let mut r = LoadReport::new();
    assert_limit(
        csvfile::parse(c.as_bytes(), "quoted.csv", &opts, &mut r),
        "max_line_bytes",
        Some(4),
        "quoted.csv",
    );
    // GeoLife labels
    let labels = format!(
        "Start Time\tEnd Time\tTransportation Mode\n2008/10/23 02:53:04\t2008/10/23 02:53:40\t{}\n",
        "b".repeat(2 << 20)
    );
    assert_limit(
        geolife::parse_labels(labels.as_bytes(), "labels.txt", false),
        "max_line_bytes",
        Some(2),
        "labels.txt",
    );
}

/// More points in one trajectory than `max_track_points`: an error at the line of the first
/// point too many.
#[test]
fn a_track_with_too_many_points_names_the_line() {
    let opts = LoadOptions {
        max_track_points: 3,
        ..LoadOptions::default()
    };
    let mut r = LoadReport::new();
    assert_limit(
        geolife::parse_plt(plt_lines(5, 39.9).as_bytes(), "p.plt", "u/p", &opts, &mut r),
        "max_track_points",
        Some(10),
        "p.plt",
    );
    let mut r = LoadReport::new();
    assert_eq!(
        geolife::parse_plt(plt_lines(3, 39.9).as_bytes(), "p.plt", "u/p", &opts, &mut r).unwrap()
            [0]
        .trajectory
        .len(),
        3
    );
    let mut r = LoadReport::new();
    assert_limit(
        tdrive::parse(tdrive_lines(5).as_bytes(), "t.txt", &opts, &mut r),
        "max_track_points",
        Some(4),
        "t.txt",
    );
    let mut r = LoadReport::new();
    assert_limit(
        csvfile::parse(csv_lines(5).as_bytes(), "c.csv", &opts, &mut r),
        "max_track_points",
        Some(5),
        "c.csv",
    );
    // with a track column the limit is per track: two tracks of 3 points are fine
    let two = "t,x,y,id\n0,0,0,a\n0,0,0,b\n1,1,0,a\n1,1,0,b\n2,2,0,a\n2,2,0,b\n";
    let mut r = LoadReport::new();
    assert_eq!(
        csvfile::parse(two.as_bytes(), "two.csv", &opts, &mut r)
            .unwrap()
            .len(),
        2
    );
    // ADS-B: the line is the record index
    let recs: Vec<String> = (0..5)
        .map(|k| {
            format!(
                r#"{{"timestamp":{},"icao24":"a","callsign":"X","latitude":52.0,"longitude":4.0,"altitude":100}}"#,
                1_527_693_698_000_u64 + k * 1000
            )
        })
        .collect();
    let json = format!("[{}]", recs.join(","));
    let mut r = LoadReport::new();
    assert_limit(
        adsb::parse_json(json.as_bytes(), "a.json", &opts, &mut r),
        "max_track_points",
        Some(4),
        "a.json",
    );
}

/// More points in one load than `max_total_points`, counting what the report already holds,
/// across files of a folder, and the records of a JSON document (held before grouping).
#[test]
fn a_load_with_too_many_points_stops() {
    let opts = LoadOptions {
        max_total_points: 4,
        ..LoadOptions::default()
    };
    // one CSV file, two tracks of 3
    let two = "t,x,y,id\n0,0,0,a\n0,0,0,b\n1,1,0,a\n1,1,0,b\n2,2,0,a\n2,2,0,b\n";
    let mut r = LoadReport::new();
    assert_limit(
        csvfile::parse(two.as_bytes(), "two.csv", &opts, &mut r),
        "max_total_points",
        Some(6),
        "two.csv",
    );
    // the points a shared report already counts
    let mut r = LoadReport::new();
    tdrive::parse(tdrive_lines(3).as_bytes(), "a.txt", &opts, &mut r).unwrap();
    assert_eq!(r.points_kept, 3);
    assert_limit(
        tdrive::parse(tdrive_lines(3).as_bytes(), "b.txt", &opts, &mut r),
        "max_total_points",
        Some(2),
        "b.txt",
    );
    // a folder of files: the limit is the folder's
    let dir = std::env::temp_dir().join(format!("trajpred-limits-{}-dir", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("1.txt"), tdrive_lines(3)).unwrap();
    std::fs::write(dir.join("2.txt"), tdrive_lines(3)).unwrap();
    let res = tdrive::load_dir(&dir, &opts);
    std::fs::write(dir.join("1.csv"), csv_lines(3)).unwrap();
    std::fs::write(dir.join("2.csv"), csv_lines(3)).unwrap();
    let res_csv = csvfile::load_path(&dir, &opts);
    let _ = std::fs::remove_dir_all(&dir);
    assert_limit(res, "max_total_points", Some(2), "2.txt");
    assert_limit(res_csv, "max_total_points", Some(3), "2.csv");
    // JSON records, both layouts
    let opts = LoadOptions {
        max_total_points: 2,
        ..LoadOptions::adsb()
    };
    let list = r#"[{"timestamp":1,"latitude":1,"longitude":1},{"timestamp":2},{"timestamp":3}]"#;
    let mut r = LoadReport::new();
    assert_limit(
        adsb::parse_json(list.as_bytes(), "l.json", &opts, &mut r),
        "max_total_points",
        None,
        "l.json",
    );
    let cols = r#"{"timestamp":{"0":1,"1":2,"2":3},"latitude":{"0":1}}"#;
    let mut r = LoadReport::new();
    assert_limit(
        adsb::parse_json(cols.as_bytes(), "c.json", &opts, &mut r),
        "max_total_points",
        None,
        "c.json",
    );
    let mut r = LoadReport::new();
    let two = r#"[{"timestamp":1,"latitude":1,"longitude":1},{"timestamp":2}]"#;
    assert!(adsb::parse_json(two.as_bytes(), "t.json", &opts, &mut r).is_ok());
}

#[test]
fn limits_of_zero_are_invalid_parameters() {
    for (name, opts) in [
        (
            "max_line_bytes",
            LoadOptions {
                max_line_bytes: 0,
                ..LoadOptions::default()
            },
        ),
        (
            "max_track_points",
            LoadOptions {
                max_track_points: 0,
                ..LoadOptions::default()
            },
        ),
        (
            "max_total_points",
            LoadOptions {
                max_total_points: 0,
                ..LoadOptions::default()
            },
        ),
    ] {
        let mut r = LoadReport::new();
        match tdrive::parse(tdrive_lines(1).as_bytes(), "x.txt", &opts, &mut r) {
            Err(Error::Core(CoreError::InvalidParameter { name: n, .. })) => assert_eq!(n, name),
            other => panic!("{name}: {other:?}"),
        }
    }
}

/// Latitude 91 everywhere: no trajectory, and the report says why (every point an invalid
/// coordinate, with its line), in every geodetic format; strict mode names the first line.
#[test]
fn latitude_beyond_90_is_reported_as_invalid_coordinate() {
    let opts = LoadOptions::default();
    let mut r = LoadReport::new();
    let tracks =
        geolife::parse_plt(plt_lines(4, 91.0).as_bytes(), "n.plt", "u/n", &opts, &mut r).unwrap();
    assert!(tracks.is_empty());
    assert_eq!(r.trajectories, 0);
    assert_eq!(r.records_read, 4);
    assert_eq!(r.skipped(SkipReason::InvalidCoordinate), 4);
    assert_eq!(r.skipped_total(), 4);
    let lines: Vec<usize> = r.skips().iter().map(|s| s.line).collect();
    assert_eq!(lines, [7, 8, 9, 10]);
    assert!(r.to_string().contains("invalid coordinate: 4"), "{r}");

    let t = "7,2008-02-02 13:30:49,116.76,91.0\n7,2008-02-02 13:35:49,116.76,91.5\n";
    let mut r = LoadReport::new();
    assert!(
        tdrive::parse(t.as_bytes(), "t.txt", &opts, &mut r)
            .unwrap()
            .is_empty()
    );
    assert_eq!(r.skipped(SkipReason::InvalidCoordinate), 2);

    let c = "t,lat,lon\n0,91,116\n1,95,116\n";
    let mut r = LoadReport::new();
    assert!(
        csvfile::parse(c.as_bytes(), "c.csv", &opts, &mut r)
            .unwrap()
            .is_empty()
    );
    assert_eq!(r.skipped(SkipReason::InvalidCoordinate), 2);

    let j = r#"[{"timestamp":1000,"icao24":"a","latitude":91.0,"longitude":4.0,"altitude":100}]"#;
    let mut r = LoadReport::new();
    assert!(
        adsb::parse_json(j.as_bytes(), "j.json", &LoadOptions::adsb(), &mut r)
            .unwrap()
            .is_empty()
    );
    assert_eq!(r.skipped(SkipReason::InvalidCoordinate), 1);

    let strict = LoadOptions {
        strict: true,
        ..opts
    };
    let mut r = LoadReport::new();
    match geolife::parse_plt(
        plt_lines(4, 91.0).as_bytes(),
        "n.plt",
        "u/n",
        &strict,
        &mut r,
    ) {
        Err(Error::Parse {
            line: 7, reason, ..
        }) => assert!(reason.contains("91"), "{reason}"),
        other => panic!("{other:?}"),
    }
}
