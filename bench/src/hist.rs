//! HdrHistograms in ns (the supervisor's bounds: 1 ns .. 10 s, 3 significant
//! digits), percentile summaries in µs, and HdrHistogram interval logs
//! (`.hlog`) read and written.

use hdrhistogram::serialization::interval_log::{
    IntervalLogIterator, IntervalLogWriterBuilder, LogEntry, Tag,
};
use hdrhistogram::serialization::{Deserializer, V2DeflateSerializer};
use hdrhistogram::Histogram;
use std::path::Path;
use std::time::{Duration, SystemTime};

pub use motion_supervisor::stats::{histogram as new_hist, HIGHEST_NS};

/// Adds `b` into `a`; values beyond `a`'s range saturate instead of failing.
pub fn merge(a: &mut Histogram<u64>, b: &Histogram<u64>) {
    if a.add(b).is_err() {
        for v in b.iter_recorded() {
            a.saturating_record_n(v.value_iterated_to(), v.count_at_value());
        }
    }
}

/// Distribution of one histogram, µs: the supervisor's own summary type, so
/// both tools' numbers are computed the same way.
pub type Pct = motion_supervisor::stats::Percentiles;

/// Column names of [`Pct::values`].
pub const COLUMNS: [&str; 6] = ["min", "p50", "p99", "p99.9", "p99.99", "max"];

/// A µs figure for a table cell: one decimal below 1000, none above.
pub fn us(x: f64) -> String {
    if x >= 1000.0 {
        format!("{x:.0}")
    } else {
        format!("{x:.1}")
    }
}

/// A ratio for a table cell.
pub fn ratio(x: Option<f64>) -> String {
    match x {
        Some(r) => format!("{r:.2}"),
        None => "-".into(),
    }
}

/// 12345678 → "12,345,678".
pub fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Standard base64 (with or without padding) → bytes.
pub fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    fn val(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    }
    let bytes = s.trim().trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    let mut acc = 0u32;
    let mut bits = 0u32;
    for &c in bytes {
        let v = val(c).ok_or_else(|| format!("invalid base64 character {:?}", c as char))?;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// One interval of an interval log.
pub struct Interval {
    pub tag: Option<String>,
    pub start: Duration,
    pub duration: Duration,
    pub hist: Histogram<u64>,
}

/// Parses a whole interval log (every interval deserialized).
pub fn read_interval_log(text: &[u8]) -> Result<Vec<Interval>, String> {
    let mut out = Vec::new();
    let mut de = Deserializer::new();
    for entry in IntervalLogIterator::new(text) {
        match entry {
            Ok(LogEntry::Interval(ilh)) => {
                let raw = base64_decode(ilh.encoded_histogram())?;
                let hist: Histogram<u64> = de
                    .deserialize(&mut std::io::Cursor::new(&raw))
                    .map_err(|e| format!("cannot decode a histogram: {e:?}"))?;
                out.push(Interval {
                    tag: ilh.tag().map(|t| t.as_str().to_string()),
                    start: ilh.start_timestamp(),
                    duration: ilh.duration(),
                    hist,
                });
            }
            Ok(_) => {}
            Err(e) => return Err(format!("interval log does not parse: {e:?}")),
        }
    }
    Ok(out)
}

/// Reads and parses an interval log file.
pub fn read_interval_log_file(path: &Path) -> Result<Vec<Interval>, String> {
    let text = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    read_interval_log(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Sum of the intervals tagged `tag`.
pub fn sum_tag(intervals: &[Interval], tag: &str) -> Histogram<u64> {
    let mut h = new_hist();
    for i in intervals.iter().filter(|i| i.tag.as_deref() == Some(tag)) {
        merge(&mut h, &i.hist);
    }
    h
}

/// Writes an interval log: `comments`, StartTime/BaseTime = `start`, then the
/// intervals in the given order (times relative to `start`).
pub fn write_interval_log(
    path: &Path,
    comments: &[String],
    start: SystemTime,
    intervals: &[(&str, Duration, Duration, &Histogram<u64>)],
) -> Result<(), String> {
    let err = |e: String| format!("cannot write {}: {e}", path.display());
    let mut buf = Vec::new();
    let mut ser = V2DeflateSerializer::new();
    {
        let mut b = IntervalLogWriterBuilder::new();
        for c in comments {
            b.add_comment(c);
        }
        let mut w = b
            .with_start_time(start)
            .with_base_time(start)
            .begin_log_with(&mut buf, &mut ser)
            .map_err(|e| err(e.to_string()))?;
        for (tag, at, len, h) in intervals {
            let tag = Tag::new(tag).ok_or_else(|| err(format!("bad tag {tag:?}")))?;
            w.write_histogram(h, *at, *len, Some(tag))
                .map_err(|e| err(format!("{e:?}")))?;
        }
    }
    std::fs::write(path, buf).map_err(|e| err(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("aGVsbG8").unwrap(), b"hello");
        assert_eq!(base64_decode("YWI=").unwrap(), b"ab");
        assert!(base64_decode("a$").is_err());
    }

    #[test]
    fn log_round_trip() {
        let mut a = new_hist();
        let mut b = new_hist();
        for v in 1..=1000u64 {
            a.record(v * 1000).unwrap();
            b.record(v * 2000).unwrap();
        }
        let dir = std::env::temp_dir().join(format!("mb-hist-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.hlog");
        let t0 = SystemTime::now();
        write_interval_log(
            &p,
            &["test".into()],
            t0,
            &[
                ("ours", Duration::ZERO, Duration::from_secs(1), &a),
                (
                    "cyclictest",
                    Duration::from_secs(1),
                    Duration::from_secs(1),
                    &b,
                ),
                ("ours", Duration::from_secs(2), Duration::from_secs(1), &a),
            ],
        )
        .unwrap();
        let iv = read_interval_log_file(&p).unwrap();
        assert_eq!(iv.len(), 3);
        assert_eq!(sum_tag(&iv, "ours").len(), 2000);
        assert_eq!(sum_tag(&iv, "cyclictest").max(), b.max());
        assert_eq!(iv[1].start, Duration::from_secs(1));
        let _ = std::fs::remove_dir_all(dir);
        assert_eq!(thousands(1234567), "1,234,567");
        assert_eq!(thousands(12), "12");
    }
}
