//! Calendar dates and times of the fixed text formats, to seconds since the Unix epoch,
//! parsed by hand (no time-zone database: every format here is UTC or treated as such).

/// Days from 1970-01-01 to the proleptic Gregorian date `y-m-d` (H. Hinnant's algorithm).
pub fn days_from_civil(y: i64, m: u32, d: u32) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = i64::from(m);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(d) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

fn is_leap(y: i64) -> bool {
    (y % 4 == 0 && y % 100 != 0) || y % 400 == 0
}

fn days_in_month(y: i64, m: u32) -> u32 {
    match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if is_leap(y) => 29,
        _ => 28,
    }
}

fn digits(s: &str) -> Option<u32> {
    if s.is_empty() || s.len() > 4 || !s.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    s.parse().ok()
}

/// Two ASCII digits at `b[i..i + 2]`.
fn two(b: &[u8], i: usize) -> Option<u32> {
    let (x, y) = (b[i].wrapping_sub(b'0'), b[i + 1].wrapping_sub(b'0'));
    (x < 10 && y < 10).then_some(u32::from(x) * 10 + u32::from(y))
}

/// A date `YYYY<sep>MM<sep>DD` (sep `-` or `/`) to days since 1970-01-01, with the month and
/// day checked against the calendar.
pub fn parse_date(s: &str) -> Option<i64> {
    // fast path for the zero-padded form of every format here (it matters in debug builds)
    let b = s.as_bytes();
    if b.len() == 10 && (b[4] == b'-' || b[4] == b'/') && b[7] == b[4] {
        let (y, m, d) = (two(b, 0)? * 100 + two(b, 2)?, two(b, 5)?, two(b, 8)?);
        let y = i64::from(y);
        if !(1..=12).contains(&m) || d == 0 || d > days_in_month(y, m) {
            return None;
        }
        return Some(days_from_civil(y, m, d));
    }
    let mut it = s.trim().split(['-', '/']);
    let (y, m, d) = (it.next()?, it.next()?, it.next()?);
    if it.next().is_some() || y.len() != 4 {
        return None;
    }
    let (y, m, d) = (i64::from(digits(y)?), digits(m)?, digits(d)?);
    if !(1..=12).contains(&m) || d == 0 || d > days_in_month(y, m) {
        return None;
    }
    Some(days_from_civil(y, m, d))
}

/// A time of day `HH:MM:SS` (seconds may carry a fraction) to seconds since midnight.
pub fn parse_time(s: &str) -> Option<f64> {
    let b = s.as_bytes();
    if b.len() == 8 && b[2] == b':' && b[5] == b':' {
        let (h, m, sec) = (two(b, 0)?, two(b, 3)?, two(b, 6)?);
        if h > 23 || m > 59 || sec > 59 {
            return None;
        }
        return Some(f64::from(h * 3600 + m * 60 + sec));
    }
    let mut it = s.trim().split(':');
    let (h, m, sec) = (it.next()?, it.next()?, it.next()?);
    if it.next().is_some() {
        return None;
    }
    let (h, m) = (digits(h)?, digits(m)?);
    let (whole, frac) = match sec.split_once('.') {
        Some((w, f)) if !f.is_empty() && f.bytes().all(|b| b.is_ascii_digit()) => {
            (w, format!("0.{f}").parse::<f64>().ok()?)
        }
        Some(_) => return None,
        None => (sec, 0.0),
    };
    let s = digits(whole)?;
    if h > 23 || m > 59 || s > 59 {
        return None;
    }
    Some(f64::from(h * 3600 + m * 60 + s) + frac)
}

/// `date` and `time` (see [`parse_date`], [`parse_time`]) to seconds since the Unix epoch.
pub fn parse_date_time(date: &str, time: &str) -> Option<f64> {
    Some(parse_date(date)? as f64 * 86_400.0 + parse_time(time)?)
}

/// `YYYY-MM-DD HH:MM:SS` (one space, or a `T`) to seconds since the Unix epoch.
pub fn parse_datetime(s: &str) -> Option<f64> {
    let s = s.trim_ascii();
    let b = s.as_bytes();
    if b.len() == 19 && (b[10] == b' ' || b[10] == b'T') {
        return parse_date_time(&s[..10], &s[11..]);
    }
    let (d, t) = s.split_once([' ', 'T'])?;
    parse_date_time(d, t)
}

/// An ISO 8601 date-time to seconds since the Unix epoch: `YYYY-MM-DDTHH:MM:SS` (or a space
/// instead of `T`), optional fractional seconds (`.5`), then optionally `Z` (UTC) or a UTC
/// offset `±HH:MM` / `±HHMM` / `±HH` (subtracted, so the result is UTC). Without a suffix the
/// time is read as UTC.
///
/// ```
/// use trajpred_data::time::parse_iso8601;
/// assert_eq!(parse_iso8601("2008-10-23T02:53:04Z"), Some(1_224_730_384.0));
/// assert_eq!(parse_iso8601("2008-10-23 02:53:04.5"), Some(1_224_730_384.5));
/// assert_eq!(parse_iso8601("2008-10-23T10:53:04+08:00"), Some(1_224_730_384.0));
/// assert_eq!(parse_iso8601("2008-10-23"), None); // a date alone is not a time
/// ```
pub fn parse_iso8601(s: &str) -> Option<f64> {
    let s = s.trim_ascii();
    let b = s.as_bytes();
    // the date part is exactly `YYYY-MM-DD`, then `T`, `t` or one space
    if b.len() < 19 || b[4] != b'-' || b[7] != b'-' || !matches!(b[10], b'T' | b't' | b' ') {
        return None;
    }
    let days = parse_date(s.get(..10)?)?;
    let rest = s.get(11..)?;
    let (time, offset) = split_offset(rest)?;
    // `HH:MM:SS` with optional fraction: at least 8 characters, two-digit fields
    let tb = time.as_bytes();
    if tb.len() < 8 || (tb.len() > 8 && tb[8] != b'.') {
        return None;
    }
    Some(days as f64 * 86_400.0 + parse_time(time)? - offset)
}

/// Splits a time of day from its zone suffix: `Z`/`z` (0) or `±HH[:MM]`/`±HHMM` (seconds).
fn split_offset(s: &str) -> Option<(&str, f64)> {
    if let Some(t) = s.strip_suffix(['Z', 'z']) {
        return Some((t, 0.0));
    }
    let Some(i) = s.rfind(['+', '-']) else {
        return Some((s, 0.0));
    };
    let (time, zone) = (s.get(..i)?, s.get(i..)?);
    let sign = if zone.starts_with('-') { -1.0 } else { 1.0 };
    let digits: String = zone[1..].chars().filter(|c| *c != ':').collect();
    let colons = zone[1..].matches(':').count();
    let ok_shape = match (zone.len() - 1, colons) {
        (2, 0) | (4, 0) => true,
        (5, 1) => zone.as_bytes().get(3) == Some(&b':'),
        _ => false,
    };
    if !ok_shape || !digits.bytes().all(|c| c.is_ascii_digit()) {
        return None;
    }
    let h: u32 = digits.get(..2)?.parse().ok()?;
    let m: u32 = match digits.get(2..) {
        Some("") | None => 0,
        Some(m) => m.parse().ok()?,
    };
    if h > 23 || m > 59 {
        return None;
    }
    Some((time, sign * f64::from(h * 3600 + m * 60)))
}

/// The unit of a CSV file's time column, detected per file (see [`crate::csvfile`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum TimeUnit {
    /// Plain numbers (magnitude below 1e11), taken as seconds.
    Seconds,
    /// Numbers of magnitude at least 1e11: milliseconds since the Unix epoch (1e11 ms is
    /// 1973-03-03), divided by 1000.
    EpochMillis,
    /// ISO 8601 date-times (`2008-10-23T02:53:04Z`, see [`parse_iso8601`]), to seconds since
    /// the Unix epoch.
    Iso8601,
}

impl std::fmt::Display for TimeUnit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TimeUnit::Seconds => "seconds",
            TimeUnit::EpochMillis => "epoch milliseconds",
            TimeUnit::Iso8601 => "ISO 8601",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_epochs() {
        // `date -u -d '2008-10-23 02:53:04' +%s` = 1224730384
        assert_eq!(
            parse_date_time("2008-10-23", "02:53:04"),
            Some(1_224_730_384.0)
        );
        // `date -u -d '2008-02-02 15:36:08' +%s` = 1201966568
        assert_eq!(parse_datetime("2008-02-02 15:36:08"), Some(1_201_966_568.0));
        assert_eq!(parse_datetime("1970-01-01 00:00:00"), Some(0.0));
        assert_eq!(parse_date("2000-02-29"), Some(11_016));
        assert_eq!(parse_date("2008/05/30"), parse_date("2008-05-30"));
        assert_eq!(parse_time("00:00:01.5"), Some(1.5));
    }

    #[test]
    fn iso8601_forms() {
        let t = 1_224_730_384.0;
        for s in [
            "2008-10-23T02:53:04Z",
            "2008-10-23T02:53:04",
            "2008-10-23 02:53:04",
            "2008-10-23 02:53:04z",
            " 2008-10-23T02:53:04Z ",
            "2008-10-23T04:53:04+02:00",
            "2008-10-23T04:53:04+0200",
            "2008-10-23T04:53:04+02",
            "2008-10-22T21:53:04-05:00",
        ] {
            assert_eq!(parse_iso8601(s), Some(t), "{s}");
        }
        assert_eq!(parse_iso8601("2008-10-23T02:53:04.25Z"), Some(t + 0.25));
        for s in [
            "2008-10-23",
            "2008-10-23T02:53",
            "2008-10-23T2:53:04",
            "2008-10-23T02:53:04.",
            "2008-10-23T02:53:04+2:00",
            "2008-10-23T02:53:04+24:00",
            "2008-10-23T02:53:04+02:0",
            "2008-02-30T02:53:04Z",
            "2008/10/23T02:53:04Z",
            "2008-10-23X02:53:04",
            "1224730384",
            "",
        ] {
            assert_eq!(parse_iso8601(s), None, "{s}");
        }
    }

    #[test]
    fn rejects_impossible_dates() {
        for s in [
            "2001-02-29",
            "2008-13-01",
            "2008-00-10",
            "08-01-01",
            "2008-01-01-01",
            "x-1-1",
        ] {
            assert_eq!(parse_date(s), None, "{s}");
        }
        for s in [
            "24:00:00",
            "12:60:00",
            "12:00:60",
            "1:2",
            "a:b:c",
            "12:00:00.",
            "-1:00:00",
        ] {
            assert_eq!(parse_time(s), None, "{s}");
        }
    }
}
