//! Latency statistics: wake-up latency, compute time and I/O round trip, in
//! preallocated HdrHistograms.
//!
//! The real-time thread only ever calls `saturating_record` on histograms whose
//! range was fixed at construction (1 ns .. 10 s, 3 significant digits), which
//! never allocates. Full sets are handed to the reporting thread and merged
//! there; see [`crate::shared`].

use hdrhistogram::Histogram;
pub use motion_report::{Latency, Percentiles};

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

    /// Percentiles in µs (the `latency` object of the reports).
    pub fn summary(&self) -> Latency {
        Latency {
            cycles: self.cycles,
            deadline_misses: self.deadline_misses,
            late_replies: self.late_replies,
            wakeup_us: percentiles(&self.wakeup).rounded(),
            compute_us: percentiles(&self.compute).rounded(),
            io_roundtrip_us: percentiles(&self.roundtrip).rounded(),
        }
    }
}

/// Distribution of one histogram of ns, in µs.
pub fn percentiles(h: &Histogram<u64>) -> Percentiles {
    if h.is_empty() {
        return Percentiles::default();
    }
    let us = |ns: u64| ns as f64 / 1000.0;
    Percentiles {
        count: h.len(),
        min: us(h.min()),
        p50: us(h.value_at_quantile(0.50)),
        p99: us(h.value_at_quantile(0.99)),
        p999: us(h.value_at_quantile(0.999)),
        p9999: us(h.value_at_quantile(0.9999)),
        max: us(h.max()),
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
        assert!((s.wakeup_us.p50 - 501.0).abs() < 1.0, "{}", s.wakeup_us.p50);
        assert!(s.wakeup_us.max >= 9_990_000.0);
        assert_eq!(s.compute_us, Percentiles::default());
        assert!(s.table().contains("wake-up"));
    }
}
