//! HdrHistogram interval logs (`.hlog`), readable by HdrHistogram's
//! `HistogramLogProcessor` and plotters: one interval per statistics hand-off,
//! tagged `wakeup`, `compute` and `roundtrip`, values in ns.
//!
//! The daemon keeps the serialized intervals of the last hour in memory
//! ([`IntervalLines`]), so `motionctl stats --hlog FILE` can fetch them, and
//! `run --hlog FILE` writes them to a file as they come.

use crate::stats::HistSet;
use hdrhistogram::serialization::interval_log::{IntervalLogWriterBuilder, Tag};
use hdrhistogram::serialization::V2DeflateSerializer;
use std::collections::VecDeque;
use std::io::Write;
use std::time::{Duration, SystemTime};

/// The log's header lines, for a log that starts at `start`.
pub fn header(start: SystemTime) -> Vec<u8> {
    let mut out = Vec::new();
    let mut serializer = V2DeflateSerializer::new();
    let _ = IntervalLogWriterBuilder::new()
        .add_comment("motion-supervisor latency log; values in ns; tags wakeup, compute, roundtrip")
        .with_start_time(start)
        .with_base_time(start)
        .begin_log_with(&mut out, &mut serializer);
    out
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
            // A builder without headers writes nothing but the interval line.
            if let Ok(mut w) =
                IntervalLogWriterBuilder::new().begin_log_with(&mut line, &mut self.serializer)
            {
                let _ = w.write_histogram(hist, start, len, Tag::new(tag));
            }
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

    #[test]
    fn a_log_parses_back() {
        use hdrhistogram::serialization::interval_log::{IntervalLogIterator, LogEntry};
        let mut lines = IntervalLines::new(2);
        for k in 0..3u64 {
            let mut h = HistSet::new();
            h.wakeup.saturating_record(1000 * (k + 1));
            h.cycles = 1;
            h.start_ns = 1_000_000_000 * (k + 1);
            h.end_ns = h.start_ns + 1_000_000_000;
            lines.add(&h);
        }
        let log = lines.log(SystemTime::now(), 0);
        let intervals = IntervalLogIterator::new(&log)
            .filter(|e| matches!(e, Ok(LogEntry::Interval(_))))
            .count();
        assert_eq!(intervals, 6, "the newest 2 intervals × 3 tags");
        let since = lines.log(SystemTime::now(), 2);
        let n = IntervalLogIterator::new(&since)
            .filter(|e| matches!(e, Ok(LogEntry::Interval(_))))
            .count();
        assert_eq!(n, 3);
    }
}
