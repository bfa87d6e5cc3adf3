//! A mutation fuzzer for the trajectory parsers, written by hand (cargo-fuzz needs nightly).
//!
//! Seeds are the fixture files under `fixtures/data/` (GeoLife `.plt` and labels, T-Drive
//! `.txt`, ADS-B `.json` / `.json.gz`, CSV / `.csv.gz`) plus small hand-made inputs. Each
//! execution takes a seed, applies 1-8 random mutations and feeds the result to the matching
//! parser (gzip seeds through the library's file loaders, which detect gzip by its magic
//! bytes) under `catch_unwind`. A panic is counted and its input saved under
//! `target/fuzz-findings/`; so is an `Ok` whose report does not add up.
//!
//! ```text
//! cargo run --release -p trajpred-data --example fuzz_parsers -- <executions> <seed> [text|json|gz|all]
//! ```
//!
//! The model/parameter loaders that read JSON (`trajpred-neural`'s `persist`) are not
//! reachable from this crate's dependencies and are not fuzzed here.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Once;
use std::time::Instant;
use trajpred_data::{Error, LoadOptions, LoadReport, Track, adsb, csvfile, geolife, tdrive};

/// Largest input fed to a parser (bytes), so an execution stays cheap.
pub const MAX_INPUT: usize = 256 * 1024;
/// Longest run a "long line" mutation inserts.
pub const MAX_LONG_RUN: usize = 8 * 1024;

/// The parser an input is meant for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Target {
    /// GeoLife `.plt` (`geolife::parse_plt`).
    Plt,
    /// GeoLife `labels.txt` (`geolife::parse_labels`).
    Labels,
    /// T-Drive taxi log (`tdrive::parse`).
    TDrive,
    /// ADS-B JSON, records or columns (`adsb::parse_json`).
    Adsb,
    /// CSV (`csvfile::parse`).
    Csv,
    /// gzip ADS-B, through `adsb::load_file`.
    GzAdsb,
    /// gzip CSV, through `csvfile::load_file`.
    GzCsv,
}

impl Target {
    /// The family: `text`, `json` or `gz`.
    pub fn family(self) -> &'static str {
        match self {
            Target::Plt | Target::Labels | Target::TDrive | Target::Csv => "text",
            Target::Adsb => "json",
            Target::GzAdsb | Target::GzCsv => "gz",
        }
    }
}

/// One seed input. For gzip targets `bytes` is the decompressed text.
#[derive(Debug, Clone)]
pub struct Seed {
    /// Where it came from.
    pub name: String,
    /// Its parser.
    pub target: Target,
    /// Its bytes.
    pub bytes: Vec<u8>,
}

const PLT: &str = "Geolife trajectory\r\nWGS 84\r\nAltitude is in Feet\r\nReserved 3\r\n0,2,255,My Track,0,0,2,8421376\r\n0\r\n39.984702,116.318417,0,492,39744.1201851852,2008-10-23,02:53:04\r\n39.984683,116.318450,0,492,39744.1202546296,2008-10-23,02:53:10\r\n39.984686,116.318417,0,-777,39744.1202546296,2008-10-23,02:53:16\r\n";
const TDRIVE: &str = "7,2008-02-02 13:30:49,116.76038,39.79758\n7,2008-02-02 13:35:49,116.76135,39.79712\n7,2008-02-02 15:55:49,116.70000,39.80000\n";
const ADSB: &str = r#"[{"timestamp":1527693698000,"icao24":"484506","latitude":52.3239,"longitude":4.7394,"callsign":"TRA051","altitude":224.0},{"timestamp":1527693699000,"icao24":"484506","latitude":52.3251,"longitude":4.7396,"callsign":"TRA051","altitude":null}]"#;
const ADSB_COLS: &str = r#"{"timestamp":{"0":1576068400000,"1":1576068410000},"latitude":{"0":43.6,"1":43.7},"longitude":{"0":7.2,"1":null},"altitude":{"0":1000.0,"1":1033.3},"icao24":{"0":"39c902","1":"39c902"},"callsign":{"0":"FHMAC","1":"FHMAC"}}"#;
const CSV_XY: &str = "t,x,y,z\n0,0,0,1\n1,1,0.5,2\n2,2,1,3\n";
const CSV_LL: &str = "t,lat,lon,alt\n0,39.9,116.4,5\n1,39.9001,116.4001,6\n";
const CSV_ISO: &str = "track,time,lat,lon\na,2020-01-01T00:00:00Z,10,20\na,2020-01-01T00:00:01Z,10.001,20\nb,1577836800,11,21\n";
const LABELS: &str =
    "Start Time\tEnd Time\tTransportation Mode\n2008/10/23 02:53:04\t2008/10/23 02:53:40\tbus\n";

/// Hand-made seeds (as in `tests/robustness.rs`) plus a few degenerate ones.
pub fn handmade() -> Vec<Seed> {
    let s = |name: &str, target, text: &str| Seed {
        name: name.to_string(),
        target,
        bytes: text.as_bytes().to_vec(),
    };
    vec![
        s("hand:plt", Target::Plt, PLT),
        s("hand:tdrive", Target::TDrive, TDRIVE),
        s("hand:adsb", Target::Adsb, ADSB),
        s("hand:adsb_cols", Target::Adsb, ADSB_COLS),
        s("hand:csv_xy", Target::Csv, CSV_XY),
        s("hand:csv_ll", Target::Csv, CSV_LL),
        s("hand:csv_iso", Target::Csv, CSV_ISO),
        s("hand:labels", Target::Labels, LABELS),
        s("hand:empty_plt", Target::Plt, ""),
        s("hand:empty_json", Target::Adsb, "[]"),
        s("hand:empty_csv", Target::Csv, "t,x,y\n"),
        s("hand:gz_adsb", Target::GzAdsb, ADSB),
        s("hand:gz_csv", Target::GzCsv, CSV_LL),
    ]
}

/// The fixture root, `fixtures/data` of the workspace.
pub fn fixture_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/data")
}

fn gunzip(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(bytes)
        .take(MAX_INPUT as u64)
        .read_to_end(&mut out)
        .expect("fixture gzip decodes");
    out
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// Every fixture under `root` whose format is known, then the hand-made seeds.
pub fn corpus(root: &Path) -> Vec<Seed> {
    let mut files = Vec::new();
    walk(root, &mut files);
    files.sort();
    let mut seeds = Vec::new();
    for p in files {
        let name = p.strip_prefix(root).unwrap_or(&p).display().to_string();
        let Ok(bytes) = std::fs::read(&p) else {
            continue;
        };
        let gz = bytes.starts_with(&[0x1f, 0x8b]);
        let target = if name.ends_with(".plt") {
            Target::Plt
        } else if name.ends_with("labels.txt") {
            Target::Labels
        } else if name.starts_with("tdrive") {
            Target::TDrive
        } else if name.starts_with("adsb") {
            if gz { Target::GzAdsb } else { Target::Adsb }
        } else if name.starts_with("csv") {
            // notes.txt and README.txt are seeds of non-CSV text for the CSV parser
            if gz { Target::GzCsv } else { Target::Csv }
        } else {
            continue; // geodesy reference, scripts
        };
        let bytes = if gz { gunzip(&bytes) } else { bytes };
        let bytes = if bytes.len() > MAX_INPUT {
            bytes[..MAX_INPUT].to_vec()
        } else {
            bytes
        };
        seeds.push(Seed {
            name,
            target,
            bytes,
        });
    }
    seeds.extend(handmade());
    seeds
}

const EXTREMES: &[&str] = &[
    "1e308",
    "-1e308",
    "1.7976931348623157e309",
    "4.9e-324",
    "1e-320",
    "-0",
    "-0.0",
    "nan",
    "NaN",
    "-nan",
    "inf",
    "-inf",
    "Infinity",
    "91",
    "-91",
    "90",
    "180.0000001",
    "-181",
    "0",
    "",
    "18446744073709551616",
    "-9223372036854775809",
    "9223372036854775807",
    "99999999999999999999999999999999999999",
    "0000000000000000000000000000001",
    "1e",
    "--1",
    "1.2.3",
    "0x10",
    "+5",
    "1_000",
    "null",
    "true",
    "\"1\"",
    "2008-13-45",
    "25:61:61",
    "9999-12-31 23:59:59",
    "0000-00-00",
    "1970-01-01T00:00:00Z",
    "-62135596800",
    "253402300800000",
];

const TOKENS: &[&[u8]] = &[
    b",",
    b"\n",
    b"\r\n",
    b"\r",
    b"\t",
    b"\"",
    b"\"\"",
    b"{",
    b"}",
    b"[",
    b"]",
    b":",
    b"null",
    b"-",
    b".",
    b"e",
    b" ",
    b"\0",
    b"\xef\xbb\xbf",
];

fn is_num_byte(b: u8) -> bool {
    b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E')
}

/// Applies one random mutation to `v`; `other` is a second input for splicing.
pub fn mutate_once(rng: &mut ChaCha8Rng, v: &mut Vec<u8>, other: &[u8]) {
    let kind = rng.random_range(0..15u32);
    mutate_kind(rng, v, other, kind);
}

/// Applies mutation `kind` (0-14; see the arms) to `v`.
pub fn mutate_kind(rng: &mut ChaCha8Rng, v: &mut Vec<u8>, other: &[u8], kind: u32) {
    let len = v.len();
    let pos = |rng: &mut ChaCha8Rng, n: usize| rng.random_range(0..=n);
    match kind {
        0 if len > 0 => {
            // bit flips
            for _ in 0..rng.random_range(1..=4) {
                let i = rng.random_range(0..len);
                v[i] ^= 1 << rng.random_range(0..8);
            }
        }
        1 => {
            // insert random bytes
            let i = pos(rng, len);
            let n = rng.random_range(1..=16);
            let bytes: Vec<u8> = (0..n).map(|_| rng.random()).collect();
            v.splice(i..i, bytes);
        }
        2 if len > 0 => {
            // delete a run
            let i = rng.random_range(0..len);
            let n = rng.random_range(1..=(len - i).min(64));
            v.drain(i..i + n);
        }
        3 if len > 0 => {
            // duplicate a run
            let i = rng.random_range(0..len);
            let n = rng.random_range(1..=(len - i).min(256));
            let run = v[i..i + n].to_vec();
            let j = pos(rng, len);
            v.splice(j..j, run);
        }
        4 => {
            // splice: a prefix of this input, a suffix of the other
            let i = pos(rng, len);
            let j = pos(rng, other.len());
            v.truncate(i);
            v.extend_from_slice(&other[j..]);
        }
        5 | 6 if len > 0 => {
            // replace a number with an extreme value
            let start = rng.random_range(0..len);
            let Some(a) = (start..len)
                .chain(0..start)
                .find(|&i| v[i].is_ascii_digit())
            else {
                return;
            };
            let mut s = a;
            while s > 0 && is_num_byte(v[s - 1]) {
                s -= 1;
            }
            let mut e = a;
            while e < len && is_num_byte(v[e]) {
                e += 1;
            }
            let x = EXTREMES[rng.random_range(0..EXTREMES.len())];
            v.splice(s..e, x.bytes());
        }
        7 if len > 0 => {
            // empty a field: remove what lies between two separators
            let i = rng.random_range(0..len);
            let sep = |b: u8| matches!(b, b',' | b'\t' | b'\n' | b':');
            let s = (0..i).rev().find(|&k| sep(v[k])).map_or(0, |k| k + 1);
            let e = (i..len).find(|&k| sep(v[k])).unwrap_or(len);
            v.drain(s..e);
        }
        8 => {
            // a very long line (within a bound)
            let n = rng.random_range(1..=MAX_LONG_RUN);
            let b = [b'9', b'a', b',', b' ', b'"', 0xff][rng.random_range(0..6)];
            let i = pos(rng, len);
            v.splice(i..i, std::iter::repeat_n(b, n));
        }
        9 => {
            // random UTF-8 characters
            let i = pos(rng, len);
            let mut s = String::new();
            for _ in 0..rng.random_range(1..=4) {
                let c = loop {
                    if let Some(c) = char::from_u32(rng.random_range(0x80..0x11_0000)) {
                        break c;
                    }
                };
                s.push(c);
            }
            v.splice(i..i, s.bytes());
        }
        10 => {
            // bytes that are not UTF-8
            let bad: &[&[u8]] = &[
                b"\xff",
                b"\xc0\xaf",
                b"\xed\xa0\x80",
                b"\xe9",
                b"\x80\x80",
                b"\xf8\x88\x80\x80\x80",
            ];
            let i = pos(rng, len);
            v.splice(i..i, bad[rng.random_range(0..bad.len())].iter().copied());
        }
        11 => {
            // CRLF <-> LF
            let crlf = v.windows(2).any(|w| w == b"\r\n");
            let mut out = Vec::with_capacity(v.len() + v.len() / 16);
            for &b in v.iter() {
                match (crlf, b) {
                    (true, b'\r') => {}
                    (false, b'\n') => out.extend_from_slice(b"\r\n"),
                    _ => out.push(b),
                }
            }
            *v = out;
        }
        12 => {
            // truncation
            let i = pos(rng, len);
            v.truncate(i);
        }
        13 => {
            // a structural token
            let i = pos(rng, len);
            let t = TOKENS[rng.random_range(0..TOKENS.len())];
            v.splice(i..i, t.iter().copied());
        }
        _ if len > 0 => {
            // duplicate a whole line
            let i = rng.random_range(0..len);
            let s = (0..i).rev().find(|&k| v[k] == b'\n').map_or(0, |k| k + 1);
            let e = (i..len).find(|&k| v[k] == b'\n').map_or(len, |k| k + 1);
            let line = v[s..e].to_vec();
            v.splice(s..s, line);
        }
        _ => v.push(rng.random()),
    }
}

/// 1-8 mutations of `input`, at most [`MAX_INPUT`] bytes. One time in four every mutation
/// replaces a number by an extreme value, so that most inputs keep their structure (a JSON
/// document stays JSON) and reach the code past the syntax checks.
pub fn mutate(rng: &mut ChaCha8Rng, input: &[u8], other: &[u8]) -> Vec<u8> {
    let mut v = input.to_vec();
    let numbers_only = rng.random_bool(0.25);
    for _ in 0..rng.random_range(1..=8) {
        if numbers_only {
            mutate_kind(rng, &mut v, other, 5);
        } else {
            mutate_once(rng, &mut v, other);
        }
        v.truncate(MAX_INPUT);
    }
    v
}

/// The option sets the property tests (`tests/robustness.rs`) parse with too: default,
/// strict, gap splitting.
pub fn base_option_sets() -> Vec<LoadOptions> {
    vec![
        LoadOptions::default(),
        LoadOptions {
            altitude: true,
            strict: true,
            ..LoadOptions::adsb()
        },
        LoadOptions {
            min_points: 2,
            max_gap: Some(1.0),
            ..LoadOptions::tdrive()
        },
    ]
}

/// The option sets inputs are parsed with: [`base_option_sets`] and small limits.
pub fn option_sets() -> Vec<LoadOptions> {
    let mut sets = base_option_sets();
    sets.push(LoadOptions {
        max_line_bytes: 4096,
        max_track_points: 20,
        max_total_points: 40,
        max_json_bytes: 8192,
        ..LoadOptions::geolife()
    });
    sets
}

/// What one execution gave.
#[derive(Debug)]
pub enum Outcome {
    /// Data (or labels) and a report that adds up; the label names the kind.
    Ok,
    /// A typed error; the label names its variant.
    Err(String),
    /// An `Ok` whose report or data break the loader's rules.
    Violation(String),
}

fn label(e: &Error) -> String {
    match e {
        Error::Io { .. } => "Io".into(),
        Error::Parse { .. } => "Parse".into(),
        Error::Core(trajpred_core::Error::InvalidParameter { name, .. }) => {
            format!("InvalidParameter({name})")
        }
        Error::Layout { .. } => "Layout".into(),
        Error::LimitExceeded { option, .. } => format!("LimitExceeded({option})"),
        Error::Core(_) => "Core".into(),
        _ => "other".into(),
    }
}

fn judge(res: trajpred_data::Result<Vec<Track>>, r: &LoadReport) -> Outcome {
    match res {
        Ok(tracks) => {
            if r.records_read != r.points_kept + r.skipped_total() {
                return Outcome::Violation(format!(
                    "records_read {} != kept {} + skipped {}",
                    r.records_read,
                    r.points_kept,
                    r.skipped_total()
                ));
            }
            let n: usize = tracks.iter().map(|t| t.trajectory.len()).sum();
            if n != r.points_kept {
                return Outcome::Violation(format!("{n} points in tracks, {} kept", r.points_kept));
            }
            if !tracks
                .iter()
                .all(|t| t.trajectory.axes().all(|a| a.iter().all(|x| x.is_finite())))
            {
                return Outcome::Violation("non-finite coordinate kept".into());
            }
            Outcome::Ok
        }
        Err(e) => Outcome::Err(label(&e)),
    }
}

/// Runs `target`'s parser on `input`. Gzip targets write `input` to `scratch` and load it.
pub fn run_one(target: Target, input: &[u8], opts: &LoadOptions, scratch: &Path) -> Outcome {
    let mut r = LoadReport::new();
    match target {
        Target::Plt => judge(geolife::parse_plt(input, "f", "u/f", opts, &mut r), &r),
        Target::TDrive => judge(tdrive::parse(input, "f", opts, &mut r), &r),
        Target::Adsb => judge(adsb::parse_json(input, "f", opts, &mut r), &r),
        Target::Csv => judge(csvfile::parse(input, "f", opts, &mut r), &r),
        Target::Labels => match geolife::parse_labels(input, "f", opts.strict) {
            Ok((_, r)) if r.records_read != r.points_kept + r.skipped_total() => {
                Outcome::Violation("labels report does not add up".into())
            }
            Ok(_) => Outcome::Ok,
            Err(e) => Outcome::Err(label(&e)),
        },
        Target::GzAdsb | Target::GzCsv => {
            // a fresh file each time: rewriting a truncated one makes ext4 flush it on close
            let _ = std::fs::remove_file(scratch);
            if let Err(e) = std::fs::write(scratch, input) {
                return Outcome::Err(format!("scratch write failed: {e}"));
            }
            let res = if target == Target::GzAdsb {
                adsb::load_file(scratch, opts)
            } else {
                csvfile::load_file(scratch, opts)
            };
            match res {
                Ok((tracks, r)) => judge(Ok(tracks), &r),
                Err(e) => Outcome::Err(label(&e)),
            }
        }
    }
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).expect("gzip to memory");
    e.finish().expect("gzip to memory")
}

/// Totals of a run.
#[derive(Debug, Default)]
pub struct Stats {
    /// Executions.
    pub executions: u64,
    /// Executions that panicked.
    pub panics: u64,
    /// `Ok` results whose report did not add up.
    pub violations: u64,
    /// Outcomes by target family and label (`Ok`, `Err(Parse)`, ...).
    pub outcomes: BTreeMap<String, u64>,
    /// Panic and violation messages, with the saved input's path.
    pub findings: Vec<String>,
    /// Wall time in seconds.
    pub seconds: f64,
}

thread_local! {
    /// The last panic's location and message on this thread (the hook runs on the
    /// panicking thread, so parallel runs do not mix their messages).
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
    /// Whether this thread is inside [`fuzz_with`]: its panics are recorded, not printed.
    static FUZZING: Cell<bool> = const { Cell::new(false) };
}

static HOOK: Once = Once::new();

/// Installs (once per process) a panic hook that records the panics of fuzzing threads in
/// `LAST_PANIC` and passes the others to the previous hook.
fn install_hook() {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !FUZZING.with(Cell::get) {
                return previous(info);
            }
            let msg = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_default();
            let at = info.location().map(|l| l.to_string()).unwrap_or_default();
            LAST_PANIC.with(|p| *p.borrow_mut() = Some(format!("{at}: {msg}")));
        }));
    });
}

/// Where findings go: `target/fuzz-findings/` of the workspace (or of `CARGO_TARGET_DIR`).
pub fn findings_dir() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target"));
    target.join("fuzz-findings")
}

fn save(dir: &Path, name: &str, input: &[u8], note: &str) -> String {
    let _ = std::fs::create_dir_all(dir);
    let p = dir.join(format!("{name}.bin"));
    let _ = std::fs::write(&p, input);
    let _ = std::fs::write(dir.join(format!("{name}.txt")), note);
    p.display().to_string()
}

/// A parser call: the target, the input, the options and a scratch file for gzip targets.
pub type RunFn = dyn Fn(Target, &[u8], &LoadOptions, &Path) -> Outcome;

/// `executions` executions from `seed` over the seeds whose family is in `families`
/// (`all` for every family), with the parser call `run` (normally [`run_one`]); findings are
/// saved under `dir`.
pub fn fuzz_with(
    seeds: &[Seed],
    executions: u64,
    seed: u64,
    families: &str,
    run: &RunFn,
    dir: &Path,
) -> Stats {
    let pool: Vec<&Seed> = seeds
        .iter()
        .filter(|s| families == "all" || families.split(',').any(|f| f == s.target.family()))
        .collect();
    assert!(!pool.is_empty(), "no seeds for families {families}");
    let opts = option_sets();
    let _ = std::fs::create_dir_all(dir);
    let scratch = dir.join(format!("scratch-{}-{seed}.bin", std::process::id()));
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut stats = Stats::default();

    install_hook();
    FUZZING.with(|f| f.set(true));
    let start = Instant::now();
    for exec in 0..executions {
        let s = pool[rng.random_range(0..pool.len())];
        let other = pool[rng.random_range(0..pool.len())];
        let mut input = mutate(&mut rng, &s.bytes, &other.bytes);
        if matches!(s.target, Target::GzAdsb | Target::GzCsv) {
            input = gzip(&input);
            // half the time, damage the compressed stream itself
            if rng.random_bool(0.5) {
                for _ in 0..rng.random_range(1..=3) {
                    mutate_once(&mut rng, &mut input, &[]);
                }
            }
        }
        let o = &opts[rng.random_range(0..opts.len())];
        let out = catch_unwind(AssertUnwindSafe(|| run(s.target, &input, o, &scratch)));
        stats.executions += 1;
        let fam = s.target.family();
        // saves the input of a finding (`kind` `violation` or `panic`, with what went wrong)
        // and returns the line that lists it
        let keep = |kind: &str, why: &str| {
            let name = format!("{kind}-{seed}-{exec}-{:?}", s.target);
            let note = format!("{why}\nseed input {}\n{o:?}\n", s.name);
            let p = save(dir, &name, &input, &note);
            format!("{kind} {why} ({:?}, {p})", s.target)
        };
        let key = match out {
            Ok(Outcome::Ok) => format!("{fam} Ok"),
            Ok(Outcome::Err(l)) => format!("{fam} Err({l})"),
            Ok(Outcome::Violation(why)) => {
                stats.violations += 1;
                stats.findings.push(keep("violation", &why));
                format!("{fam} Violation")
            }
            Err(_) => {
                stats.panics += 1;
                let msg = LAST_PANIC
                    .with(|p| p.borrow_mut().take())
                    .unwrap_or_default();
                stats.findings.push(keep("panic", &msg));
                format!("{fam} PANIC")
            }
        };
        *stats.outcomes.entry(key).or_default() += 1;
    }
    stats.seconds = start.elapsed().as_secs_f64();
    FUZZING.with(|f| f.set(false));
    let _ = std::fs::remove_file(&scratch);
    stats
}

/// [`fuzz_with`] with the real parsers, findings under [`findings_dir`].
pub fn fuzz(seeds: &[Seed], executions: u64, seed: u64, families: &str) -> Stats {
    fuzz_with(seeds, executions, seed, families, &run_one, &findings_dir())
}

/// Prints a run's figures.
#[allow(clippy::print_stdout)] // a report on the terminal is the point of the example
pub fn print(stats: &Stats) {
    println!(
        "executions {}  time {:.1} s  {:.0} exec/s  panics {}  violations {}",
        stats.executions,
        stats.seconds,
        stats.executions as f64 / stats.seconds.max(1e-9),
        stats.panics,
        stats.violations
    );
    for (k, n) in &stats.outcomes {
        println!("  {k:<40} {n:>10}");
    }
    for f in stats.findings.iter().take(20) {
        println!("  finding: {f}");
    }
}

#[allow(clippy::print_stdout)]
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let executions: u64 = args
        .first()
        .map_or(100_000, |s| s.parse().expect("executions"));
    let seed: u64 = args.get(1).map_or(0, |s| s.parse().expect("seed"));
    let families = args.get(2).map_or("all", String::as_str);
    let seeds = corpus(&fixture_root());
    println!(
        "{} seeds ({} fixture files), families {families}, seed {seed}",
        seeds.len(),
        seeds.len() - handmade().len()
    );
    let stats = fuzz(&seeds, executions, seed, families);
    print(&stats);
    if stats.panics > 0 || stats.violations > 0 {
        std::process::exit(1);
    }
}
