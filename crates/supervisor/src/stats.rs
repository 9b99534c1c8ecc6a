//! Latency statistics: wake-up latency, compute time and I/O round trip, in
//! preallocated HdrHistograms.
//!
//! The real-time thread only ever calls `saturating_record` on histograms whose
//! range was fixed at construction (1 ns .. 10 s, 3 significant digits), which
//! never allocates. Full sets are handed to the reporting thread and merged
//! there; see [`crate::shared`].

use hdrhistogram::Histogram;

/// Highest value a histogram holds, ns (larger values saturate).
pub const HIGHEST_NS: u64 = 10_000_000_000;

/// One interval's worth of measurements.
#[derive(Clone, Debug)]
pub struct HistSet {
    /// Wake-up latency: actual wake − absolute deadline.
    pub wakeup: Histogram<u64>,
    /// Compute: wake → command frame published (receive, every engine step, publish, notify).
    pub compute: Histogram<u64>,
    /// I/O round trip: command published → the feedback answering it arrived.
    pub roundtrip: Histogram<u64>,
    pub cycles: u64,
    /// Cycles that woke a whole period late or published after the next deadline.
    pub deadline_misses: u64,
    /// Cycles whose answer did not arrive within the wait budget.
    pub late_replies: u64,
    /// Monotonic time span covered, ns (0 = empty).
    pub start_ns: u64,
    pub end_ns: u64,
}

/// An empty histogram with the bounds every latency histogram uses.
pub fn histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, HIGHEST_NS, 3).expect("static histogram bounds are valid")
}

impl Default for HistSet {
    fn default() -> Self {
        Self::new()
    }
}

impl HistSet {
    pub fn new() -> Self {
        Self {
            wakeup: histogram(),
            compute: histogram(),
            roundtrip: histogram(),
            cycles: 0,
            deadline_misses: 0,
            late_replies: 0,
            start_ns: 0,
            end_ns: 0,
        }
    }

    pub fn reset(&mut self) {
        self.wakeup.reset();
        self.compute.reset();
        self.roundtrip.reset();
        self.cycles = 0;
        self.deadline_misses = 0;
        self.late_replies = 0;
        self.start_ns = 0;
        self.end_ns = 0;
    }

    /// Adds `other` into `self` (reporting thread only: may allocate).
    pub fn merge(&mut self, other: &HistSet) {
        // Same bounds on both sides: cannot fail.
        let _ = self.wakeup.add(&other.wakeup);
        let _ = self.compute.add(&other.compute);
        let _ = self.roundtrip.add(&other.roundtrip);
        self.cycles += other.cycles;
        self.deadline_misses += other.deadline_misses;
        self.late_replies += other.late_replies;
        if other.start_ns != 0 && (self.start_ns == 0 || other.start_ns < self.start_ns) {
            self.start_ns = other.start_ns;
        }
        self.end_ns = self.end_ns.max(other.end_ns);
    }

    pub fn summary(&self) -> LatencySummary {
        LatencySummary {
            cycles: self.cycles,
            deadline_misses: self.deadline_misses,
            late_replies: self.late_replies,
            wakeup: Percentiles::of(&self.wakeup),
            compute: Percentiles::of(&self.compute),
            roundtrip: Percentiles::of(&self.roundtrip),
        }
    }
}

/// Distribution of one histogram, in µs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Percentiles {
    pub count: u64,
    pub min: f64,
    pub p50: f64,
    pub p99: f64,
    pub p999: f64,
    pub p9999: f64,
    pub max: f64,
}

impl Percentiles {
    pub fn of(h: &Histogram<u64>) -> Self {
        if h.is_empty() {
            return Self::default();
        }
        let us = |ns: u64| ns as f64 / 1000.0;
        Self {
            count: h.len(),
            min: us(h.min()),
            p50: us(h.value_at_quantile(0.50)),
            p99: us(h.value_at_quantile(0.99)),
            p999: us(h.value_at_quantile(0.999)),
            p9999: us(h.value_at_quantile(0.9999)),
            max: us(h.max()),
        }
    }

    /// `[min, p50, p99, p99.9, p99.99, max]`, the order of every table.
    pub fn values(&self) -> [f64; 6] {
        [
            self.min, self.p50, self.p99, self.p999, self.p9999, self.max,
        ]
    }

    /// `self / other` per column (`None` where `other` is 0).
    pub fn ratio(&self, other: &Percentiles) -> [Option<f64>; 6] {
        let a = self.values();
        let b = other.values();
        std::array::from_fn(|i| (b[i] > 0.0).then(|| a[i] / b[i]))
    }

    /// Reads back what [`Self::to_json`] wrote (µs).
    pub fn from_json(v: &serde_json::Value) -> Option<Self> {
        let f = |k: &str| v.get(k).and_then(|x| x.as_f64());
        Some(Self {
            count: v.get("count").and_then(|x| x.as_u64())?,
            min: f("min")?,
            p50: f("p50")?,
            p99: f("p99")?,
            p999: f("p999")?,
            p9999: f("p9999")?,
            max: f("max")?,
        })
    }

    pub fn to_json(self) -> serde_json::Value {
        let r = |x: f64| (x * 10.0).round() / 10.0;
        serde_json::json!({
            "min": r(self.min), "p50": r(self.p50), "p99": r(self.p99),
            "p999": r(self.p999), "p9999": r(self.p9999), "max": r(self.max),
            "count": self.count,
        })
    }
}

/// What the `home` and `run` commands print.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LatencySummary {
    pub cycles: u64,
    pub deadline_misses: u64,
    pub late_replies: u64,
    pub wakeup: Percentiles,
    pub compute: Percentiles,
    pub roundtrip: Percentiles,
}

impl LatencySummary {
    /// The `latency` object of `home --json` (interface.md).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "cycles": self.cycles,
            "deadline_misses": self.deadline_misses,
            "late_replies": self.late_replies,
            "wakeup_us": self.wakeup.to_json(),
            "compute_us": self.compute.to_json(),
            "io_roundtrip_us": self.roundtrip.to_json(),
        })
    }

    /// A small fixed-width table.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:<16}{:>9}{:>9}{:>9}{:>9}{:>10}{:>10}\n",
            "latency (µs)", "min", "p50", "p99", "p99.9", "p99.99", "max"
        );
        for (name, p) in [
            ("wake-up", self.wakeup),
            ("compute", self.compute),
            ("I/O round trip", self.roundtrip),
        ] {
            s += &format!(
                "{:<16}{:>9.1}{:>9.1}{:>9.1}{:>9.1}{:>10.1}{:>10.1}\n",
                name, p.min, p.p50, p.p99, p.p999, p.p9999, p.max
            );
        }
        s += &format!(
            "cycles {}, deadline misses {}, late I/O replies {}\n",
            self.cycles, self.deadline_misses, self.late_replies
        );
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merge_and_percentiles() {
        let mut a = HistSet::new();
        let mut b = HistSet::new();
        for v in 1..=1000u64 {
            a.wakeup.saturating_record(v * 1000);
        }
        b.wakeup.saturating_record(HIGHEST_NS * 10); // saturates, no panic
        a.cycles = 1000;
        b.cycles = 1;
        b.deadline_misses = 1;
        a.merge(&b);
        let s = a.summary();
        assert_eq!(s.cycles, 1001);
        assert_eq!(s.deadline_misses, 1);
        assert!((s.wakeup.p50 - 501.0).abs() < 1.0, "{}", s.wakeup.p50);
        assert!(s.wakeup.max >= 9_990_000.0);
        assert_eq!(s.compute, Percentiles::default());
        assert!(s.table().contains("wake-up"));
    }
}
