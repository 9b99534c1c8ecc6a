//! HdrHistogram interval logs (`.hlog`), readable by HdrHistogram's
//! `HistogramLogProcessor` and plotters: one interval per statistics hand-off,
//! tagged `wakeup`, `compute` and `roundtrip`, values in ns.

use crate::stats::HistSet;
use hdrhistogram::serialization::interval_log::{IntervalLogWriterBuilder, Tag};
use hdrhistogram::serialization::V2DeflateSerializer;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::time::{Duration, SystemTime};

pub struct HlogWriter {
    out: BufWriter<File>,
    serializer: V2DeflateSerializer,
    /// Monotonic ns of the first interval (timestamps are relative to it).
    base_ns: Option<u64>,
    line: Vec<u8>,
}

impl HlogWriter {
    pub fn create(path: &Path) -> Result<Self, String> {
        let file =
            File::create(path).map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        let mut out = BufWriter::new(file);
        let mut serializer = V2DeflateSerializer::new();
        IntervalLogWriterBuilder::new()
            .add_comment(
                "motion-supervisor latency log; values in ns; tags wakeup, compute, roundtrip",
            )
            .with_start_time(SystemTime::now())
            .with_base_time(SystemTime::now())
            .begin_log_with(&mut out, &mut serializer)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        Ok(Self {
            out,
            serializer,
            base_ns: None,
            line: Vec::new(),
        })
    }

    /// Appends one interval (three tagged histograms).
    pub fn interval(&mut self, h: &HistSet) {
        if h.cycles == 0 {
            return;
        }
        let base = *self.base_ns.get_or_insert(h.start_ns);
        let start = Duration::from_nanos(h.start_ns.saturating_sub(base));
        let len = Duration::from_nanos(h.end_ns.saturating_sub(h.start_ns).max(1));
        for (tag, hist) in [
            ("wakeup", &h.wakeup),
            ("compute", &h.compute),
            ("roundtrip", &h.roundtrip),
        ] {
            self.line.clear();
            // A builder without headers writes nothing but the interval line.
            if let Ok(mut w) =
                IntervalLogWriterBuilder::new().begin_log_with(&mut self.line, &mut self.serializer)
            {
                let _ = w.write_histogram(hist, start, len, Tag::new(tag));
            }
            let _ = self.out.write_all(&self.line);
        }
    }

    pub fn finish(&mut self) {
        let _ = self.out.flush();
    }
}
