//! HdrHistograms in ns (the supervisor's bounds: 1 ns .. 10 s, 3 significant
//! digits) and HdrHistogram interval logs (`.hlog`) read and written.

use base64::engine::{general_purpose::GeneralPurpose, DecodePaddingMode, GeneralPurposeConfig};
use base64::Engine as _;
use hdrhistogram::serialization::interval_log::{
    IntervalLogIterator, IntervalLogWriterBuilder, LogEntry, Tag,
};
use hdrhistogram::serialization::{Deserializer, V2DeflateSerializer};
use hdrhistogram::Histogram;
use std::path::Path;
use std::time::{Duration, SystemTime};

pub use motion_supervisor::stats::{histogram as new_hist, percentiles as pct_of, HIGHEST_NS};

/// Distribution of one histogram, µs: the supervisor's own summary type, so
/// every tool's numbers are computed the same way.
pub type Pct = motion_supervisor::stats::Percentiles;

/// Standard base64, padded or not (the log's histograms are padded).
const BASE64: GeneralPurpose = GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
);

/// Adds `b` into `a`; values beyond `a`'s range saturate instead of failing.
pub fn merge(a: &mut Histogram<u64>, b: &Histogram<u64>) {
    if a.add(b).is_err() {
        for v in b.iter_recorded() {
            a.saturating_record_n(v.value_iterated_to(), v.count_at_value());
        }
    }
}

/// One interval of an interval log.
pub struct Interval {
    pub tag: Option<String>,
    pub start: Duration,
    pub hist: Histogram<u64>,
}

/// Reads and parses a whole interval log file (every interval deserialized).
pub fn read_interval_log(path: &Path) -> Result<Vec<Interval>, String> {
    let err = |e: String| format!("{}: {e}", path.display());
    let text = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut de = Deserializer::new();
    let mut out = Vec::new();
    for entry in IntervalLogIterator::new(&text) {
        let ilh = match entry {
            Ok(LogEntry::Interval(ilh)) => ilh,
            Ok(_) => continue,
            Err(e) => return Err(err(format!("interval log does not parse: {e:?}"))),
        };
        let raw = BASE64
            .decode(ilh.encoded_histogram().trim())
            .map_err(|e| err(format!("invalid base64: {e}")))?;
        let hist = de
            .deserialize(&mut std::io::Cursor::new(&raw))
            .map_err(|e| err(format!("cannot decode a histogram: {e:?}")))?;
        let tag = ilh.tag().map(|t| t.as_str().to_string());
        out.push(Interval {
            tag,
            start: ilh.start_timestamp(),
            hist,
        });
    }
    Ok(out)
}

/// Sum of the intervals tagged `tag`.
pub fn sum_tag(intervals: &[Interval], tag: &str) -> Histogram<u64> {
    let mut h = new_hist();
    for i in intervals.iter().filter(|i| i.tag.as_deref() == Some(tag)) {
        merge(&mut h, &i.hist);
    }
    h
}

/// One interval to write: tag, start (relative to the log's start), length.
pub type Written<'a> = (&'a str, Duration, Duration, &'a Histogram<u64>);

/// Writes an interval log: `comments`, StartTime/BaseTime = `start`, then the
/// intervals in the given order.
pub fn write_interval_log(
    path: &Path,
    comments: &[String],
    start: SystemTime,
    intervals: &[Written],
) -> Result<(), String> {
    let err = |e: String| format!("cannot write {}: {e}", path.display());
    let mut buf = Vec::new();
    let mut ser = V2DeflateSerializer::new();
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
    drop(w);
    std::fs::write(path, buf).map_err(|e| err(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_round_trip() {
        let (mut a, mut b) = (new_hist(), new_hist());
        for v in 1..=1000u64 {
            a.record(v * 1000).unwrap();
            b.record(v * 2000).unwrap();
        }
        let p = std::env::temp_dir().join(format!("mb-hist-{}.hlog", std::process::id()));
        let s = Duration::from_secs;
        let iv = [
            ("ours", s(0), s(1), &a),
            ("cyclictest", s(1), s(1), &b),
            ("ours", s(2), s(1), &a),
        ];
        write_interval_log(&p, &["test".into()], SystemTime::now(), &iv).unwrap();
        let iv = read_interval_log(&p).unwrap();
        let _ = std::fs::remove_file(p);
        assert_eq!(iv.len(), 3);
        assert_eq!(sum_tag(&iv, "ours").len(), 2000);
        assert_eq!(sum_tag(&iv, "cyclictest").max(), b.max());
        assert_eq!(iv[1].start, s(1));
        assert_eq!(BASE64.decode("aGVsbG8").unwrap(), b"hello");
    }
}
