//! HdrHistogram interval logs (`.hlog`), readable by HdrHistogram's
//! `HistogramLogProcessor` and plotters: one interval per statistics hand-off,
//! tagged `wakeup`, `compute` and `roundtrip`, values in ns.
//!
//! The daemon keeps the serialized intervals of the last hour in memory
//! ([`IntervalLines`]), so `motionctl stats --hlog FILE` can fetch them, and
//! `run --hlog FILE` writes them to a file as they come. The benches read
//! those files back ([`read`]) and write their own ([`write`]) through the
//! same functions, so there is one writer and one reader of the format.

use crate::stats::{histogram, HistSet};
use base64::engine::{general_purpose::GeneralPurpose, DecodePaddingMode, GeneralPurposeConfig};
use base64::Engine as _;
use hdrhistogram::serialization::interval_log::{
    IntervalLogIterator, IntervalLogWriterBuilder, LogEntry, Tag,
};
use hdrhistogram::serialization::{Deserializer, V2DeflateSerializer};
use hdrhistogram::Histogram;
use std::collections::VecDeque;
use std::io::Write;
use std::path::Path;
use std::time::{Duration, SystemTime};

/// The daemon's header comment.
const COMMENT: &str =
    "motion-supervisor latency log; values in ns; tags wakeup, compute, roundtrip";

/// The log's header lines, for a log that starts at `start`.
pub fn header(start: SystemTime) -> Vec<u8> {
    header_with(&[COMMENT], start)
}

/// Header lines: `comments`, then StartTime and BaseTime = `start`.
fn header_with(comments: &[&str], start: SystemTime) -> Vec<u8> {
    let mut out = Vec::new();
    let mut serializer = V2DeflateSerializer::new();
    let mut b = IntervalLogWriterBuilder::new();
    for c in comments {
        b.add_comment(c);
    }
    let _ = b
        .with_start_time(start)
        .with_base_time(start)
        .begin_log_with(&mut out, &mut serializer);
    out
}

/// Appends the line of one interval: `h`, tagged `tag`, from `start`
/// (relative to the log's base time) for `len`.
fn append(
    out: &mut Vec<u8>,
    serializer: &mut V2DeflateSerializer,
    (tag, start, len, h): Interval<'_>,
) -> Result<(), String> {
    let tag = Tag::new(tag).ok_or_else(|| format!("bad tag {tag:?}"))?;
    // A builder without headers writes nothing but the interval line.
    let mut w = IntervalLogWriterBuilder::new()
        .begin_log_with(out, serializer)
        .map_err(|e| e.to_string())?;
    w.write_histogram(h, start, len, Some(tag))
        .map_err(|e| format!("{e:?}"))
}

/// One interval to write: tag, start (relative to the log's start), length.
pub type Interval<'a> = (&'a str, Duration, Duration, &'a Histogram<u64>);

/// Writes a whole log to `path`: `comments`, StartTime/BaseTime = `start`,
/// then `intervals` in the given order.
pub fn write(
    path: &Path,
    comments: &[&str],
    start: SystemTime,
    intervals: &[Interval],
) -> Result<(), String> {
    let err = |e: String| format!("cannot write {}: {e}", path.display());
    let (mut out, mut serializer) = (header_with(comments, start), V2DeflateSerializer::new());
    for &i in intervals {
        append(&mut out, &mut serializer, i).map_err(err)?;
    }
    std::fs::write(path, out).map_err(|e| err(e.to_string()))
}

/// One interval of a log read back.
pub struct Read {
    pub tag: Option<String>,
    /// From the log's base time.
    pub start: Duration,
    pub hist: Histogram<u64>,
}

/// Reads a whole log, every interval deserialized.
pub fn read(path: &Path) -> Result<Vec<Read>, String> {
    // Standard base64, padded or not (HdrHistogram's tools pad).
    const BASE64: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
    );
    let err = |e: String| format!("{}: {e}", path.display());
    let text = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut de = Deserializer::new();
    let mut out = Vec::new();
    for entry in IntervalLogIterator::new(&text) {
        let i = match entry {
            Ok(LogEntry::Interval(i)) => i,
            Ok(_) => continue,
            Err(e) => return Err(err(format!("interval log does not parse: {e:?}"))),
        };
        let raw = BASE64
            .decode(i.encoded_histogram().trim())
            .map_err(|e| err(format!("invalid base64: {e}")))?;
        let hist = de
            .deserialize(&mut std::io::Cursor::new(&raw))
            .map_err(|e| err(format!("cannot decode a histogram: {e:?}")))?;
        out.push(Read {
            tag: i.tag().map(|t| t.as_str().to_string()),
            start: i.start_timestamp(),
            hist,
        });
    }
    Ok(out)
}

/// Adds `b` into `a`; values beyond `a`'s range saturate instead of failing.
pub fn merge(a: &mut Histogram<u64>, b: &Histogram<u64>) {
    if a.add(b).is_err() {
        for v in b.iter_recorded() {
            a.saturating_record_n(v.value_iterated_to(), v.count_at_value());
        }
    }
}

/// The sum of the intervals tagged `tag`.
pub fn sum(intervals: &[Read], tag: &str) -> Histogram<u64> {
    let mut h = histogram();
    for i in intervals.iter().filter(|i| i.tag.as_deref() == Some(tag)) {
        merge(&mut h, &i.hist);
    }
    h
}

/// Serializes intervals into log lines.
pub struct IntervalLines {
    serializer: V2DeflateSerializer,
    /// Monotonic ns of the first interval (timestamps are relative to it).
    base_ns: Option<u64>,
    /// `(interval number, its three lines)`, the newest `cap`.
    lines: VecDeque<(u64, Vec<u8>)>,
    cap: usize,
    next: u64,
}

impl IntervalLines {
    pub fn new(cap: usize) -> Self {
        Self {
            serializer: V2DeflateSerializer::new(),
            base_ns: None,
            lines: VecDeque::new(),
            cap: cap.max(1),
            next: 0,
        }
    }

    /// Serializes one interval (three tagged histograms); returns its lines.
    pub fn add(&mut self, h: &HistSet) -> Option<&[u8]> {
        if h.cycles == 0 {
            return None;
        }
        let base = *self.base_ns.get_or_insert(h.start_ns);
        let start = Duration::from_nanos(h.start_ns.saturating_sub(base));
        let len = Duration::from_nanos(h.end_ns.saturating_sub(h.start_ns).max(1));
        let mut line = Vec::new();
        for (tag, hist) in [
            ("wakeup", &h.wakeup),
            ("compute", &h.compute),
            ("roundtrip", &h.roundtrip),
        ] {
            let _ = append(&mut line, &mut self.serializer, (tag, start, len, hist));
        }
        if self.lines.len() == self.cap {
            self.lines.pop_front();
        }
        self.lines.push_back((self.next, line));
        self.next += 1;
        self.lines.back().map(|(_, l)| l.as_slice())
    }

    /// Number the next interval gets (a reset mark).
    pub fn next_number(&self) -> u64 {
        self.next
    }

    /// A whole log (header + intervals numbered `from` and later).
    pub fn log(&self, start: SystemTime, from: u64) -> Vec<u8> {
        let mut out = header(start);
        for (n, l) in &self.lines {
            if *n >= from {
                out.extend_from_slice(l);
            }
        }
        out
    }
}

/// `run --hlog FILE`: the intervals written to a file as they come.
pub struct HlogFile {
    out: std::io::BufWriter<std::fs::File>,
}

impl HlogFile {
    pub fn create(path: &std::path::Path, start: SystemTime) -> Result<Self, String> {
        let file = std::fs::File::create(path)
            .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        let mut out = std::io::BufWriter::new(file);
        out.write_all(&header(start))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        Ok(Self { out })
    }

    pub fn write(&mut self, lines: &[u8]) {
        let _ = self.out.write_all(lines);
        let _ = self.out.flush();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A set of one wake-up of `us` µs in second `k` (from 1).
    fn set(k: u64, us: u64) -> HistSet {
        let mut h = HistSet::new();
        h.wakeup.saturating_record(us * 1000);
        h.cycles = 1;
        h.start_ns = 1_000_000_000 * k;
        h.end_ns = h.start_ns + 1_000_000_000;
        h
    }

    #[test]
    fn the_daemons_log_reads_back() {
        let mut lines = IntervalLines::new(2);
        for k in 1..=3u64 {
            lines.add(&set(k, k));
        }
        let p = std::env::temp_dir().join(format!("ms-hlog-{}.hlog", std::process::id()));
        let read_back = |log: Vec<u8>| {
            std::fs::write(&p, log).unwrap();
            read(&p).unwrap()
        };
        let all = read_back(lines.log(SystemTime::now(), 0));
        assert_eq!(all.len(), 6, "the newest 2 intervals × 3 tags");
        assert_eq!(
            sum(&all, "wakeup").max(),
            histogram().highest_equivalent(3000)
        );
        assert_eq!(
            (sum(&all, "compute").len(), all[3].start),
            (0, Duration::from_secs(2))
        );
        let since = read_back(lines.log(SystemTime::now(), 2));
        let _ = std::fs::remove_file(&p);
        assert_eq!(since.len(), 3);
    }

    #[test]
    fn a_written_log_reads_back_in_order() {
        let (mut a, mut b) = (histogram(), histogram());
        for v in 1..=1000u64 {
            a.record(v * 1000).unwrap();
            b.record(v * 2000).unwrap();
        }
        let p = std::env::temp_dir().join(format!("ms-hlog-w-{}.hlog", std::process::id()));
        let s = Duration::from_secs;
        let iv = [
            ("ours", s(0), s(1), &a),
            ("cyclictest", s(1), s(1), &b),
            ("ours", s(2), s(1), &a),
        ];
        write(&p, &["test"], SystemTime::now(), &iv).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        let iv = read(&p).unwrap();
        let _ = std::fs::remove_file(&p);
        assert!(text.starts_with("#test\n"), "{text}");
        assert_eq!((iv.len(), iv[1].start), (3, s(1)));
        assert_eq!(sum(&iv, "ours").len(), 2000);
        assert_eq!(sum(&iv, "cyclictest").max(), b.max());
        let bad = [("two words", s(0), s(1), &a)];
        assert!(write(&p, &[], SystemTime::now(), &bad).is_err());
        let mut c = Histogram::new_with_bounds(1, 1000, 3).unwrap();
        merge(&mut c, &b);
        assert_eq!(c.len(), 1000, "saturated, not dropped");
    }
}
