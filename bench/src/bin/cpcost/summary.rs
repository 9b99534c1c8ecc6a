//! The slices of each variant merged into one distribution per latency,
//! their counts and CPU use summed or averaged, and the verdict: missed
//! deadlines above [`MAX_MISS_RATIO`], client requests that failed while
//! the supervisor ran, or a variant that produced nothing. Percentiles never
//! fail the run.

use crate::clients::Clients;
use crate::slice::Slice;
use crate::variant::Variant;
use motion_bench::hist::{self, new_hist, Pct};
use motion_supervisor::stats::percentiles as pct_of;

/// Share of missed deadlines above which the run fails.
pub const MAX_MISS_RATIO: f64 = 0.01;

/// The slices of one variant, merged.
pub struct Group {
    pub variant: Variant,
    /// Wake-up, compute and I/O round trip, µs: percentiles of the merged
    /// interval logs, min and max exact from the JSON reports.
    pub w: Pct,
    pub c: Pct,
    pub r: Pct,
    /// Samples in the merged wake-up histogram.
    pub hlog_samples: u64,
    pub cycles: u64,
    pub misses: u64,
    pub late: u64,
    pub miss_ratio: f64,
    /// The supervisor process's CPU, share of one core, weighted by run time.
    pub cpu: Option<f64>,
    /// Its motion-io's.
    pub io_cpu: Option<f64>,
    /// Seconds measured.
    pub secs: f64,
    pub slices: usize,
    /// Mean seconds from a run's start to its clients attached.
    pub attach_s: Option<f64>,
    pub clients: Clients,
}

impl Group {
    pub fn of(variant: Variant, slices: &[&Slice]) -> Self {
        let mut wake = new_hist();
        let mut compute = new_hist();
        let mut rt = new_hist();
        let mut clients = Clients::default();
        for s in slices {
            hist::merge(&mut wake, &s.wakeup);
            hist::merge(&mut compute, &s.compute);
            hist::merge(&mut rt, &s.roundtrip);
            clients.merge(&s.clients);
        }
        let cycles: u64 = slices.iter().map(|s| s.cycles).sum();
        let misses: u64 = slices.iter().map(|s| s.misses).sum();
        let attach: Vec<f64> = slices.iter().filter_map(|s| s.attach_s).collect();
        Group {
            variant,
            w: exact(slices, pct_of(&wake), |s| s.json_wakeup),
            c: exact(slices, pct_of(&compute), |s| s.json_compute),
            r: exact(slices, pct_of(&rt), |s| s.json_roundtrip),
            hlog_samples: wake.len(),
            cycles,
            misses,
            late: slices.iter().map(|s| s.late).sum(),
            miss_ratio: misses as f64 / cycles.max(1) as f64,
            cpu: weighted(slices, |s| s.cpu),
            io_cpu: weighted(slices, |s| s.io_cpu),
            secs: slices.iter().map(|s| s.len).sum(),
            slices: slices.len(),
            attach_s: (!attach.is_empty())
                .then(|| attach.iter().sum::<f64>() / attach.len() as f64),
            clients,
        }
    }

    pub fn ran(&self) -> bool {
        self.slices > 0
    }

    /// What fails the run in this variant's figures.
    pub fn judge(&self, interrupted: bool, failures: &mut Vec<String>) {
        let name = self.variant.label();
        if !self.ran() {
            if !interrupted {
                failures.push(format!("{name}: no slice measured"));
            }
            return;
        }
        if self.miss_ratio > MAX_MISS_RATIO {
            failures.push(format!(
                "{name}: {} of {} cycles missed their deadline ({:.2} % > {:.0} %)",
                self.misses,
                self.cycles,
                self.miss_ratio * 100.0,
                MAX_MISS_RATIO * 100.0
            ));
        }
        if self.clients.failed() > 0 {
            failures.push(format!(
                "{name}: {} client request(s) failed while the supervisor ran",
                self.clients.failed()
            ));
        }
    }
}

/// `f` of the slices averaged, weighted by their run time (None if no slice
/// has it).
fn weighted(slices: &[&Slice], f: fn(&Slice) -> Option<f64>) -> Option<f64> {
    let (mut sum, mut wall) = (0.0, 0.0);
    for s in slices {
        if let Some(x) = f(s) {
            sum += x * s.wall_s;
            wall += s.wall_s;
        }
    }
    (wall > 0.0).then(|| sum / wall)
}

/// Percentiles of `p` (merged interval logs) with min and max taken exactly
/// from the slices' JSON.
fn exact(slices: &[&Slice], p: Pct, f: fn(&Slice) -> Pct) -> Pct {
    let v: Vec<Pct> = slices
        .iter()
        .map(|s| f(s))
        .filter(|p| p.count > 0)
        .collect();
    let mut p = p;
    if !v.is_empty() {
        p.min = v.iter().map(|p| p.min).fold(f64::INFINITY, f64::min);
        p.max = v.iter().map(|p| p.max).fold(0.0, f64::max);
    }
    p
}

/// The columns of the tables: indices into [`Pct::values`] (p99.99 left
/// out: a minute of cycles gives it 6 samples) and their names.
pub const COLUMNS: [(usize, &str); 5] =
    [(0, "min"), (1, "p50"), (2, "p99"), (3, "p99.9"), (5, "max")];

/// `a / b` per column of [`COLUMNS`].
pub fn ratios(a: &Pct, b: &Pct) -> Vec<Option<f64>> {
    let r = a.ratio(b);
    COLUMNS.iter().map(|&(i, _)| r[i]).collect()
}

/// `a / b` when both are there and `b` > 0.
pub fn ratio_of(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => Some(a / b),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratios_skip_p9999_and_zeros() {
        let a = Pct {
            min: 2.0,
            p50: 4.0,
            p99: 6.0,
            p999: 8.0,
            p9999: 100.0,
            max: 10.0,
            count: 1,
        };
        let b = Pct {
            min: 1.0,
            p50: 2.0,
            p99: 0.0,
            p999: 4.0,
            p9999: 1.0,
            max: 5.0,
            count: 1,
        };
        assert_eq!(
            ratios(&a, &b),
            vec![Some(2.0), Some(2.0), None, Some(2.0), Some(2.0)]
        );
        assert_eq!(ratio_of(Some(1.0), Some(4.0)), Some(0.25));
        assert_eq!(ratio_of(Some(1.0), Some(0.0)), None);
        assert_eq!(ratio_of(None, Some(1.0)), None);
    }
}
