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

/// Worst wake-ups kept per interval (and in the totals).
pub const WORST: usize = 8;

/// A late wake-up and what the cycle before it did: where a late cycle's
/// time went (its own timer, or something of ours just before).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LateCycle {
    /// Wake-up latency, ns.
    pub latency_ns: u64,
    /// Monotonic deadline of the late cycle.
    pub deadline_ns: u64,
    /// The previous cycle: its compute time, and how long before this
    /// deadline it went to sleep (negative slack = it overran).
    pub prev_compute_ns: u64,
    pub prev_slack_ns: i64,
    /// The previous cycle handed over a snapshot / a histogram set.
    pub prev_snapshot: bool,
    pub prev_stats: bool,
}

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
    /// The worst wake-ups, worst first (zeroed entries unused).
    pub worst: [LateCycle; WORST],
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
            worst: [LateCycle::default(); WORST],
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
        self.worst = [LateCycle::default(); WORST];
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
        for w in other.worst.iter().filter(|w| w.latency_ns > 0) {
            self.note_late(*w);
        }
        if other.start_ns != 0 && (self.start_ns == 0 || other.start_ns < self.start_ns) {
            self.start_ns = other.start_ns;
        }
        self.end_ns = self.end_ns.max(other.end_ns);
    }

    /// Keeps `c` if it is among the worst wake-ups (no allocation: a fixed
    /// array, insertion in place).
    pub fn note_late(&mut self, c: LateCycle) {
        let last = &self.worst[WORST - 1];
        if c.latency_ns <= last.latency_ns {
            return;
        }
        let mut i = WORST - 1;
        self.worst[i] = c;
        while i > 0 && self.worst[i - 1].latency_ns < self.worst[i].latency_ns {
            self.worst.swap(i - 1, i);
            i -= 1;
        }
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
            worst: self
                .worst
                .iter()
                .filter(|w| w.latency_ns > 0)
                .map(|w| motion_report::LateWakeup {
                    latency_us: motion_report::round(w.latency_ns as f64 / 1000.0, 1),
                    prev_compute_us: motion_report::round(w.prev_compute_ns as f64 / 1000.0, 1),
                    prev_slack_us: motion_report::round(w.prev_slack_ns as f64 / 1000.0, 1),
                    prev_snapshot: w.prev_snapshot,
                    prev_stats: w.prev_stats,
                })
                .collect(),
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
    fn the_worst_wake_ups_are_kept_in_order() {
        let mut a = HistSet::new();
        for (k, l) in [5u64, 90, 1, 40, 300, 7, 8, 9, 10, 11, 200]
            .iter()
            .enumerate()
        {
            a.note_late(LateCycle {
                latency_ns: *l,
                deadline_ns: k as u64,
                ..LateCycle::default()
            });
        }
        let kept: Vec<u64> = a.worst.iter().map(|w| w.latency_ns).collect();
        assert_eq!(kept, [300, 200, 90, 40, 11, 10, 9, 8]);
        let mut b = HistSet::new();
        b.note_late(LateCycle {
            latency_ns: 250,
            ..LateCycle::default()
        });
        a.merge(&b);
        assert_eq!(a.worst[1].latency_ns, 250);
        assert_eq!(a.summary().worst.len(), WORST);
    }

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
