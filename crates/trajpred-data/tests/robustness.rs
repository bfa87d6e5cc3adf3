//! Property tests: arbitrary bytes and arbitrary mutations of valid lines fed to every parser
//! never panic, and always give either data (with a consistent report) or a line-numbered
//! parse error.

use proptest::prelude::*;
use trajpred_data::{Error, LoadOptions, LoadReport, Track, adsb, csvfile, geolife, tdrive};

#[allow(dead_code)]
#[path = "../examples/fuzz_parsers.rs"]
mod fuzz;

use fuzz::base_option_sets as option_sets;

const PLT: &str = "Geolife trajectory\r\nWGS 84\r\nAltitude is in Feet\r\nReserved 3\r\n0,2,255,My Track,0,0,2,8421376\r\n0\r\n39.984702,116.318417,0,492,39744.1201851852,2008-10-23,02:53:04\r\n39.984683,116.318450,0,492,39744.1202546296,2008-10-23,02:53:10\r\n39.984686,116.318417,0,-777,39744.1202546296,2008-10-23,02:53:16\r\n";
const TDRIVE: &str = "7,2008-02-02 13:30:49,116.76038,39.79758\n7,2008-02-02 13:35:49,116.76135,39.79712\n7,2008-02-02 15:55:49,116.70000,39.80000\n";
const ADSB: &str = r#"[{"timestamp":1527693698000,"icao24":"484506","latitude":52.3239,"longitude":4.7394,"callsign":"TRA051","altitude":224.0},{"timestamp":1527693699000,"icao24":"484506","latitude":52.3251,"longitude":4.7396,"callsign":"TRA051","altitude":null}]"#;
const ADSB_COLS: &str = r#"{"timestamp":{"0":1576068400000,"1":1576068410000},"latitude":{"0":43.6,"1":43.7},"longitude":{"0":7.2,"1":null},"altitude":{"0":1000.0,"1":1033.3},"icao24":{"0":"39c902","1":"39c902"},"callsign":{"0":"FHMAC","1":"FHMAC"}}"#;
const CSV_XY: &str = "t,x,y,z\n0,0,0,1\n1,1,0.5,2\n2,2,1,3\n";
const CSV_LL: &str = "t,lat,lon,alt\n0,39.9,116.4,5\n1,39.9001,116.4001,6\n";
const LABELS: &str =
    "Start Time\tEnd Time\tTransportation Mode\n2008/10/23 02:53:04\t2008/10/23 02:53:40\tbus\n";

/// A track parser with its fixed file name and id: `(input, options, report)`.
type Parse = fn(&[u8], &LoadOptions, &mut LoadReport) -> Result<Vec<Track>, Error>;

/// Every track parser, each with whether it reads JSON (its errors number records, not lines).
fn parsers() -> [(Parse, bool); 4] {
    [
        (|i, o, r| geolife::parse_plt(i, "f", "u/f", o, r), false),
        (|i, o, r| tdrive::parse(i, "f", o, r), false),
        (|i, o, r| adsb::parse_json(i, "f", o, r), true),
        (|i, o, r| csvfile::parse(i, "f", o, r), false),
    ]
}

/// Either data whose report adds up and whose trajectories are valid, or a parse error with
/// a line number within the input (JSON: within the document's lines).
fn check(
    res: Result<Vec<Track>, Error>,
    report: &LoadReport,
    input: &[u8],
    json: bool,
) -> Result<(), TestCaseError> {
    // JSON records are numbered by record index: bounded by the byte count
    let lines = if json {
        input.len().max(1)
    } else {
        input.split(|&b| b == b'\n').count().max(1)
    };
    match res {
        Ok(tracks) => {
            prop_assert_eq!(
                report.records_read,
                report.points_kept + report.skipped_total()
            );
            prop_assert_eq!(
                tracks.iter().map(|t| t.trajectory.len()).sum::<usize>(),
                report.points_kept
            );
            for t in &tracks {
                prop_assert!(t.trajectory.axes().all(|a| a.iter().all(|v| v.is_finite())));
            }
            for s in report.skips() {
                prop_assert!(s.line >= 1);
            }
        }
        Err(Error::Parse { line, .. }) => {
            prop_assert!(line >= 1 && line <= lines, "line {} of {}", line, lines);
        }
        Err(e) => prop_assert!(false, "unexpected error {e:?}"),
    }
    Ok(())
}

fn run_all(input: &[u8]) -> Result<(), TestCaseError> {
    for opts in option_sets() {
        for (parse, json) in parsers() {
            let mut r = LoadReport::new();
            let res = parse(input, &opts, &mut r);
            check(res, &r, input, json)?;
        }
        match geolife::parse_labels(input, "f", opts.strict) {
            Ok((_, r)) => prop_assert_eq!(r.records_read, r.points_kept + r.skipped_total()),
            Err(Error::Parse { line, .. }) => prop_assert!(line >= 1),
            Err(e) => prop_assert!(false, "unexpected error {e:?}"),
        }
    }
    Ok(())
}

#[derive(Debug, Clone)]
enum Mutation {
    Replace(usize, u8),
    Delete(usize),
    Insert(usize, u8),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let byte = prop_oneof![
        Just(b','),
        Just(b'\n'),
        Just(b'\r'),
        Just(b'-'),
        Just(b'.'),
        Just(b'9'),
        Just(b'e'),
        Just(b'"'),
        Just(b'{'),
        Just(b']'),
        Just(b':'),
        Just(0xff),
        any::<u8>(),
    ];
    prop_oneof![
        (any::<usize>(), byte.clone()).prop_map(|(i, b)| Mutation::Replace(i, b)),
        any::<usize>().prop_map(Mutation::Delete),
        (any::<usize>(), byte).prop_map(|(i, b)| Mutation::Insert(i, b)),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn apply(input: &str, muts: &[Mutation]) -> Vec<u8> {
    let mut v = input.as_bytes().to_vec();
    for m in muts {
        let n = v.len().max(1);
        match *m {
            Mutation::Replace(i, b) if !v.is_empty() => v[i % n] = b,
            Mutation::Delete(i) if !v.is_empty() => {
                v.remove(i % n);
            }
            Mutation::Insert(i, b) => v.insert(i % (v.len() + 1), b),
            Mutation::DuplicateLine(i) | Mutation::SwapLines(i, _) | Mutation::Truncate(i)
                if matches!(m, Mutation::Truncate(_)) =>
            {
                v.truncate(i % (v.len() + 1));
            }
            Mutation::DuplicateLine(i) => {
                let mut lines: Vec<Vec<u8>> =
                    v.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
                let k = i % lines.len();
                let l = lines[k].clone();
                lines.insert(k, l);
                v = lines.join(&b'\n');
            }
            Mutation::SwapLines(a, b) => {
                let mut lines: Vec<Vec<u8>> =
                    v.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
                let n = lines.len();
                lines.swap(a % n, b % n);
                v = lines.join(&b'\n');
            }
            _ => {}
        }
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        run_all(&bytes)?;
    }

    #[test]
    fn arbitrary_text_lines_never_panic(lines in proptest::collection::vec("[0-9,.:\\- eE{}\\[\\]\"a-z]{0,60}", 0..12)) {
        let text = lines.join("\n");
        run_all(text.as_bytes())?;
    }

    #[test]
    fn mutated_valid_files_never_panic(
        which in 0usize..7,
        muts in proptest::collection::vec(mutation(), 1..6),
    ) {
        let base = [PLT, TDRIVE, ADSB, ADSB_COLS, CSV_XY, CSV_LL, LABELS][which];
        let input = apply(base, &muts);
        run_all(&input)?;
    }
}

#[test]
fn unmutated_bases_parse_cleanly() {
    let o = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    // (input, index in parsers(), points of its first track)
    for (input, k, points) in [
        (PLT, 0, 3),
        (TDRIVE, 1, 3),
        (ADSB, 2, 2),
        (ADSB_COLS, 2, 1),
        (CSV_XY, 3, 3),
        (CSV_LL, 3, 2),
    ] {
        let mut r = LoadReport::new();
        let tracks = parsers()[k].0(input.as_bytes(), &o, &mut r).unwrap();
        assert_eq!(tracks[0].trajectory.len(), points, "{input}");
    }
    assert_eq!(
        geolife::parse_labels(LABELS.as_bytes(), "f", true)
            .unwrap()
            .0
            .len(),
        1
    );
}
