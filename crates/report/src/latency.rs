//! Latency percentiles, µs.

use serde::{Deserialize, Serialize};

/// Distribution of one latency, in µs (all 0 when nothing was measured).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Percentiles {
    pub min: f64,
    pub p50: f64,
    pub p99: f64,
    pub p999: f64,
    pub p9999: f64,
    pub max: f64,
    /// Number of samples.
    pub count: u64,
}

impl Percentiles {
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

    /// Rounded to 0.1 µs for printing.
    pub fn rounded(self) -> Self {
        let r = |x: f64| crate::round(x, 1);
        Self {
            min: r(self.min),
            p50: r(self.p50),
            p99: r(self.p99),
            p999: r(self.p999),
            p9999: r(self.p9999),
            max: r(self.max),
            count: self.count,
        }
    }
}

/// One of the worst wake-ups and what the cycle before it did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LateWakeup {
    pub latency_us: f64,
    /// The previous cycle's compute time, and how long before this
    /// deadline it went back to sleep (negative: it overran).
    pub prev_compute_us: f64,
    pub prev_slack_us: f64,
    /// The previous cycle handed over a status snapshot / a histogram set.
    pub prev_snapshot: bool,
    pub prev_stats: bool,
}

/// The `latency` object of `home --json`, `run --json` and `stats --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Latency {
    pub cycles: u64,
    /// Cycles that woke a whole period late or published after the next deadline.
    pub deadline_misses: u64,
    /// Cycles whose I/O answer was not there at the next wake-up.
    pub late_replies: u64,
    /// Wake-up latency: actual wake − absolute deadline.
    pub wakeup_us: Percentiles,
    /// Compute: wake → every command frame published.
    pub compute_us: Percentiles,
    /// I/O round trip: command published → the answer to it published.
    pub io_roundtrip_us: Percentiles,
    /// The worst wake-ups, worst first, with what the cycle before did.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub worst: Vec<LateWakeup>,
}

impl Latency {
    /// A small fixed-width table.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:<16}{:>9}{:>9}{:>9}{:>9}{:>10}{:>10}\n",
            "latency (µs)", "min", "p50", "p99", "p99.9", "p99.99", "max"
        );
        for (name, p) in [
            ("wake-up", self.wakeup_us),
            ("compute", self.compute_us),
            ("I/O round trip", self.io_roundtrip_us),
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
        for w in self.worst.iter().take(3) {
            s += &format!(
                "late wake-up {:.1} µs: the cycle before computed {:.1} µs and slept {:.1} µs \
                 before this deadline{}{}\n",
                w.latency_us,
                w.prev_compute_us,
                w.prev_slack_us,
                if w.prev_snapshot {
                    ", handed a snapshot over"
                } else {
                    ""
                },
                if w.prev_stats {
                    ", handed statistics over"
                } else {
                    ""
                },
            );
        }
        s
    }
}
