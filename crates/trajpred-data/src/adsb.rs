//! ADS-B flights as the `traffic` Python package ships them: gzip-compressed (or plain) JSON,
//! either a list of records (`[{"timestamp": ..., "icao24": ..., ...}, ...]`) or pandas'
//! column-wise layout (`{"timestamp": {"0": ..., "1": ...}, "latitude": {...}, ...}`).
//!
//! Units: `timestamp` in milliseconds since the Unix epoch (UTC), `latitude`/`longitude` in
//! degrees, `altitude` (barometric) in feet, converted to metres and used as the height of
//! the 3-D point (see `docs/data.md`). Records are grouped into flights by
//! (`icao24`, `callsign`) within a file (and by `flight_id` too where records carry one), sorted by time (ties keep file order), cleaned with
//! the shared time rule and split at gaps longer than [`LoadOptions::max_gap`]. A record with
//! a null timestamp, latitude or longitude (or a null altitude when 3-D points are asked for)
//! is skipped as [`SkipReason::MissingValue`]. Line numbers
//! in the report are 1-based record indices.
//!
//! ```
//! use trajpred_data::{adsb, LoadOptions, SkipReason};
//! let f = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/adsb/columns.json.gz");
//! let (tracks, report) = adsb::load_file(f.as_ref(), &LoadOptions::adsb())?;
//! assert_eq!(tracks.len(), 1);
//! assert_eq!(report.skipped(SkipReason::MissingValue), 1);
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::{Error, Result};
use crate::geodesy::FOOT;
use crate::io::{list, read_all};
use crate::report::{LoadReport, SkipReason};
use crate::track::{Cleaner, FrameKind, LoadOptions, RawPoint, Track};
use serde::de::{
    self, Deserialize, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor,
};
use std::cell::Cell;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// (icao24, callsign, flight_id)
type FlightKey = (Option<String>, Option<String>, Option<String>);

/// One record, read leniently in a single pass: a field of the wrong type, or an element
/// that is not an object, marks the record bad (skipped as malformed) instead of failing the
/// whole document.
#[derive(Debug, Default)]
struct Record {
    timestamp: Option<f64>,
    icao24: Option<String>,
    callsign: Option<String>,
    latitude: Option<f64>,
    longitude: Option<f64>,
    altitude: Option<f64>,
    flight_id: Option<String>,
    bad: Option<String>,
}

/// A JSON value read as a number (`null` is `None`); anything else is an error message.
struct Num(Result<Option<f64>, &'static str>);
/// A JSON value read as text (`null` is `None`; numbers and booleans are written out).
struct Text(Result<Option<String>, &'static str>);

macro_rules! lenient_visitor {
    ($name:ident, $out:ident, $expect:literal, num: $num:expr, text: $text:expr, bool: $bool:expr) => {
        struct $name;
        impl<'de> Visitor<'de> for $name {
            type Value = $out;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str($expect)
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<$out, E> {
                Ok($out($num(v, None)))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<$out, E> {
                Ok($out($num(v as f64, Some(v.to_string()))))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<$out, E> {
                Ok($out($num(v as f64, Some(v.to_string()))))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<$out, E> {
                Ok($out($text(v)))
            }
            fn visit_bool<E: de::Error>(self, v: bool) -> Result<$out, E> {
                Ok($out($bool(v)))
            }
            fn visit_unit<E: de::Error>(self) -> Result<$out, E> {
                Ok($out(Ok(None)))
            }
            fn visit_none<E: de::Error>(self) -> Result<$out, E> {
                Ok($out(Ok(None)))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<$out, A::Error> {
                while a.next_element::<IgnoredAny>()?.is_some() {}
                Ok($out(Err(concat!($expect, ", got an array"))))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<$out, A::Error> {
                while a.next_entry::<IgnoredAny, IgnoredAny>()?.is_some() {}
                Ok($out(Err(concat!($expect, ", got an object"))))
            }
        }
        impl<'de> Deserialize<'de> for $out {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                d.deserialize_any($name)
            }
        }
    };
}

lenient_visitor!(NumVisitor, Num, "a number or null",
    num: |v: f64, _: Option<String>| Ok(Some(v)),
    text: |_: &str| Err("a number or null, got a string"),
    bool: |_: bool| Err("a number or null, got a boolean"));
lenient_visitor!(TextVisitor, Text, "a string or null",
    num: |v: f64, s: Option<String>| Ok(Some(s.unwrap_or_else(|| v.to_string()))),
    text: |v: &str| Ok(Some(v.to_string())),
    bool: |v: bool| Ok(Some(v.to_string())));

/// The keys this loader reads; every other key is skipped without allocating.
enum Key {
    Timestamp,
    Icao24,
    Callsign,
    Latitude,
    Longitude,
    Altitude,
    FlightId,
    Other,
}

impl<'de> Deserialize<'de> for Key {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Key;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a field name")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Key, E> {
                Ok(match v {
                    "timestamp" => Key::Timestamp,
                    "icao24" => Key::Icao24,
                    "callsign" => Key::Callsign,
                    "latitude" => Key::Latitude,
                    "longitude" => Key::Longitude,
                    "altitude" => Key::Altitude,
                    "flight_id" => Key::FlightId,
                    _ => Key::Other,
                })
            }
        }
        d.deserialize_str(V)
    }
}

impl<'de> Deserialize<'de> for Record {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        fn not_object<T>(what: &str) -> Result<Record, T> {
            Ok(Record {
                bad: Some(format!("record is {what}, not an object")),
                ..Record::default()
            })
        }
        impl<'de> Visitor<'de> for V {
            type Value = Record;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a record")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<Record, A::Error> {
                let mut r = Record::default();
                while let Some(k) = a.next_key::<Key>()? {
                    let (name, res) = match k {
                        Key::Timestamp => (
                            "timestamp",
                            a.next_value::<Num>()?.0.map(|v| r.timestamp = v),
                        ),
                        Key::Latitude => {
                            ("latitude", a.next_value::<Num>()?.0.map(|v| r.latitude = v))
                        }
                        Key::Longitude => (
                            "longitude",
                            a.next_value::<Num>()?.0.map(|v| r.longitude = v),
                        ),
                        Key::Altitude => {
                            ("altitude", a.next_value::<Num>()?.0.map(|v| r.altitude = v))
                        }
                        Key::Icao24 => ("icao24", a.next_value::<Text>()?.0.map(|v| r.icao24 = v)),
                        Key::Callsign => (
                            "callsign",
                            a.next_value::<Text>()?.0.map(|v| r.callsign = v),
                        ),
                        Key::FlightId => (
                            "flight_id",
                            a.next_value::<Text>()?.0.map(|v| r.flight_id = v),
                        ),
                        Key::Other => {
                            a.next_value::<IgnoredAny>()?;
                            ("", Ok(()))
                        }
                    };
                    if let Err(e) = res
                        && r.bad.is_none()
                    {
                        r.bad = Some(format!("{name}: expected {e}"));
                    }
                }
                Ok(r)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<Record, A::Error> {
                while a.next_element::<IgnoredAny>()?.is_some() {}
                not_object("an array")
            }
            fn visit_f64<E: de::Error>(self, _: f64) -> Result<Record, E> {
                not_object("a number")
            }
            fn visit_i64<E: de::Error>(self, _: i64) -> Result<Record, E> {
                not_object("a number")
            }
            fn visit_u64<E: de::Error>(self, _: u64) -> Result<Record, E> {
                not_object("a number")
            }
            fn visit_str<E: de::Error>(self, _: &str) -> Result<Record, E> {
                not_object("a string")
            }
            fn visit_bool<E: de::Error>(self, _: bool) -> Result<Record, E> {
                not_object("a boolean")
            }
            fn visit_unit<E: de::Error>(self) -> Result<Record, E> {
                not_object("null")
            }
        }
        d.deserialize_any(V)
    }
}

/// pandas' column-wise layout: one object per column, keyed by row index.
#[derive(Default)]
struct Columns {
    timestamp: Vec<(usize, Num)>,
    latitude: Vec<(usize, Num)>,
    longitude: Vec<(usize, Num)>,
    altitude: Vec<(usize, Num)>,
    icao24: Vec<(usize, Text)>,
    callsign: Vec<(usize, Text)>,
    flight_id: Vec<(usize, Text)>,
}

/// The most records (rows of a column) a document may hold, and whether it crossed that.
#[derive(Clone, Copy)]
struct RowCap<'a> {
    max: usize,
    hit: &'a Cell<bool>,
}

impl RowCap<'_> {
    /// An error (and `hit` set) once `len` rows are held and one more arrives.
    fn check<E: de::Error>(&self, len: usize) -> Result<(), E> {
        if len >= self.max {
            self.hit.set(true);
            return Err(E::custom(format!("more than {} records", self.max)));
        }
        Ok(())
    }
}

/// The list layout: `[record, ...]`, at most `cap.max` records.
struct RecordList<'a>(RowCap<'a>);

impl<'de> DeserializeSeed<'de> for RecordList<'_> {
    type Value = Vec<Record>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Vec<Record>, D::Error> {
        struct V<'a>(RowCap<'a>);
        impl<'de> Visitor<'de> for V<'_> {
            type Value = Vec<Record>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an array of records")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<Vec<Record>, A::Error> {
                let mut out = Vec::new();
                while let Some(r) = a.next_element::<Record>()? {
                    self.0.check::<A::Error>(out.len())?;
                    out.push(r);
                }
                Ok(out)
            }
        }
        d.deserialize_seq(V(self.0))
    }
}

/// One column: `{"<row>": value, ...}`, at most `cap.max` rows; a row key that is not an
/// index fails the document.
struct Column<'a, T>(RowCap<'a>, std::marker::PhantomData<T>);

impl<'a, T> Column<'a, T> {
    fn new(cap: RowCap<'a>) -> Self {
        Column(cap, std::marker::PhantomData)
    }
}

impl<'de, T: Deserialize<'de>> DeserializeSeed<'de> for Column<'_, T> {
    type Value = Vec<(usize, T)>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        struct RowKey(usize);
        impl<'de> Deserialize<'de> for RowKey {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                struct V;
                impl Visitor<'_> for V {
                    type Value = RowKey;
                    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                        f.write_str("a row index")
                    }
                    fn visit_str<E: de::Error>(self, v: &str) -> Result<RowKey, E> {
                        v.parse()
                            .map(RowKey)
                            .map_err(|_| E::custom(format!("row key {v:?} is not an index")))
                    }
                }
                d.deserialize_str(V)
            }
        }
        struct V<'a, T>(RowCap<'a>, std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for V<'_, T> {
            type Value = Vec<(usize, T)>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of rows")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<Self::Value, A::Error> {
                let mut out = Vec::new();
                while let Some((k, v)) = a.next_entry::<RowKey, T>()? {
                    self.0.check::<A::Error>(out.len())?;
                    out.push((k.0, v));
                }
                Ok(out)
            }
        }
        d.deserialize_map(V(self.0, std::marker::PhantomData))
    }
}

/// pandas' column-wise layout, each column of at most `cap.max` rows.
struct ColumnsSeed<'a>(RowCap<'a>);

impl<'de> DeserializeSeed<'de> for ColumnsSeed<'_> {
    type Value = Columns;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Columns, D::Error> {
        struct V<'a>(RowCap<'a>);
        impl<'de> Visitor<'de> for V<'_> {
            type Value = Columns;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of columns")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<Columns, A::Error> {
                let cap = self.0;
                let mut c = Columns::default();
                while let Some(k) = a.next_key::<Key>()? {
                    match k {
                        Key::Timestamp => c.timestamp = a.next_value_seed(Column::new(cap))?,
                        Key::Latitude => c.latitude = a.next_value_seed(Column::new(cap))?,
                        Key::Longitude => c.longitude = a.next_value_seed(Column::new(cap))?,
                        Key::Altitude => c.altitude = a.next_value_seed(Column::new(cap))?,
                        Key::Icao24 => c.icao24 = a.next_value_seed(Column::new(cap))?,
                        Key::Callsign => c.callsign = a.next_value_seed(Column::new(cap))?,
                        Key::FlightId => c.flight_id = a.next_value_seed(Column::new(cap))?,
                        Key::Other => {
                            a.next_value::<IgnoredAny>()?;
                        }
                    }
                }
                Ok(c)
            }
        }
        d.deserialize_map(V(self.0))
    }
}

/// Deserializes the whole of `json` with `seed`, then checks nothing but whitespace follows.
fn from_slice_seed<'de, S: DeserializeSeed<'de>>(
    json: &'de [u8],
    seed: S,
) -> serde_json::Result<S::Value> {
    let mut de = serde_json::Deserializer::from_slice(json);
    let v = seed.deserialize(&mut de)?;
    de.end()?;
    Ok(v)
}

/// Parses one JSON document (already decompressed) named `file`, adding to `report`.
/// A document that is not JSON, or neither an array nor an object, is an
/// [`Error::Parse`]; a record of the wrong shape is skipped as malformed.
pub fn parse_json(
    json: &[u8],
    file: &str,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<Vec<Track>> {
    opts.validate()?;
    report.files_read += 1;
    // every record is held until the document is parsed: they count towards the points
    let hit = Cell::new(false);
    let cap = RowCap {
        max: opts.max_total_points.saturating_sub(report.points_kept),
        hit: &hit,
    };
    let mut c = Cleaner::new(opts, file, report);
    let json_err = |e: serde_json::Error| {
        if hit.get() {
            return Error::LimitExceeded {
                file: file.to_string(),
                line: None,
                option: "max_total_points",
                limit: opts.max_total_points as u64,
                what: "records (points) in one load",
            };
        }
        Error::parse(file, e.line(), format!("JSON: {e}"))
    };
    let first = json.iter().find(|b| !b.is_ascii_whitespace());
    let mut records: Vec<(usize, Record)> = Vec::new();
    match first {
        Some(b'[') => {
            let all: Vec<Record> = from_slice_seed(json, RecordList(cap)).map_err(json_err)?;
            records.reserve(all.len());
            for (i, mut r) in all.into_iter().enumerate() {
                c.report.records_read += 1;
                match r.bad.take() {
                    Some(e) => c.malformed(i + 1, format!("record: {e}"))?,
                    None => records.push((i + 1, r)),
                }
            }
        }
        Some(b'{') => {
            let cols: Columns = from_slice_seed(json, ColumnsSeed(cap)).map_err(json_err)?;
            let mut rows: BTreeMap<usize, Record> = BTreeMap::new();
            macro_rules! fill {
                ($col:expr, $field:ident, $name:literal) => {
                    for (row, v) in $col {
                        let r = rows.entry(row).or_default();
                        match v.0 {
                            Ok(x) => r.$field = x,
                            Err(e) => {
                                if r.bad.is_none() {
                                    r.bad = Some(format!(concat!($name, ": expected {}"), e));
                                }
                            }
                        }
                    }
                };
            }
            fill!(cols.timestamp, timestamp, "timestamp");
            fill!(cols.latitude, latitude, "latitude");
            fill!(cols.longitude, longitude, "longitude");
            fill!(cols.altitude, altitude, "altitude");
            fill!(cols.icao24, icao24, "icao24");
            fill!(cols.callsign, callsign, "callsign");
            fill!(cols.flight_id, flight_id, "flight_id");
            for (row, mut r) in rows {
                c.report.records_read += 1;
                match r.bad.take() {
                    Some(e) => c.malformed(row.saturating_add(1), e)?,
                    None => records.push((row.saturating_add(1), r)),
                }
            }
        }
        _ => {
            return Err(Error::parse(
                file,
                1,
                "not a JSON array of records or object of columns",
            ));
        }
    }
    // group by (icao24, callsign, flight_id) in order of first appearance; every parsed
    // record counts towards the groups, whether or not its position is usable
    let mut order: Vec<FlightKey> = Vec::new();
    let mut groups: HashMap<FlightKey, Vec<RawPoint>> = HashMap::new();
    for (line, r) in records {
        let key = (
            r.icao24,
            r.callsign.map(|s| s.trim().to_string()),
            r.flight_id,
        );
        let group = groups.entry(key.clone()).or_insert_with(|| {
            order.push(key);
            Vec::new()
        });
        let (Some(ts), Some(lat), Some(lon)) = (r.timestamp, r.latitude, r.longitude) else {
            c.report.skip(
                file,
                line,
                SkipReason::MissingValue,
                "timestamp/latitude/longitude",
            );
            continue;
        };
        let p = RawPoint {
            line,
            t: ts / 1000.0,
            a: lat,
            b: lon,
            alt: r.altitude.map(|ft| ft * FOOT),
        };
        if c.accept_geodetic(&p)? {
            c.hold(line, group.len())?;
            group.push(p);
        }
    }
    c.report.groups += order.len();
    let mut out = Vec::new();
    for key in order {
        let Some(mut pts) = groups.remove(&key) else {
            continue;
        };
        pts.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.line.cmp(&b.line)));
        let mut id = format!(
            "{}/{}",
            key.0.as_deref().unwrap_or("?"),
            key.1.as_deref().unwrap_or("?")
        );
        if let Some(f) = &key.2 {
            id = format!("{id}/{f}");
        }
        let aircraft = key.0.as_deref().unwrap_or("?");
        c.finish(&id, aircraft, pts, FrameKind::Geodetic, &mut out)?;
    }
    Ok(out)
}

/// Loads one `.json` or `.json.gz` file (gzip detected by its magic bytes). The document is
/// read whole, at most [`LoadOptions::max_json_bytes`] of it (decompressed): a larger one is
/// an [`Error::LimitExceeded`].
pub fn load_file(path: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    opts.validate()?;
    let bytes = read_all(path, opts.max_json_bytes, "max_json_bytes")?;
    let mut report = LoadReport::new();
    let tracks = parse_json(&bytes, &path.display().to_string(), opts, &mut report)?;
    Ok((tracks, report))
}

/// The `.json` and `.json.gz` files under `dir`, recursively, sorted by path.
pub fn files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in list(dir, |_| true)? {
        if p.is_dir() {
            out.extend(files(&p)?);
        } else {
            let name = p
                .file_name()
                .map(|s| s.to_string_lossy().to_lowercase())
                .unwrap_or_default();
            if name.ends_with(".json") || name.ends_with(".json.gz") {
                out.push(p);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Loads every file of [`files`]`(dir)`; [`LoadOptions::max_total_points`] bounds the
/// records of them all.
pub fn load_dir(dir: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    opts.validate()?;
    let mut tracks = Vec::new();
    let mut report = LoadReport::new();
    for f in files(dir)? {
        let bytes = read_all(&f, opts.max_json_bytes, "max_json_bytes")?;
        tracks.extend(parse_json(
            &bytes,
            &f.display().to_string(),
            opts,
            &mut report,
        )?);
    }
    Ok((tracks, report))
}
