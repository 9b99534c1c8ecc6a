//! The slices merged into one distribution per variant (demo, 64 axes,
//! EtherCAT, cyclictest), and the verdict on what they measured: missed
//! deadlines above [`MAX_MISS_RATIO`], or a variant that produced nothing
//! (a tool that failed is a failure already). Percentiles never fail the run.

use crate::cyclictest_slice::CtSlice;
use crate::slices::Collected;
use crate::supervisor::OurSlice;
use hdrhistogram::Histogram;
use motion_bench::cyclictest::CtHistogram;
use motion_bench::ecat::BusRun;
use motion_bench::hist::{self, new_hist, Pct};
use motion_supervisor::stats::percentiles as pct_of;

/// Share of missed deadlines above which the run fails.
pub const MAX_MISS_RATIO: f64 = 0.01;

/// The slices of one supervisor variant, merged.
pub struct Group {
    /// Wake-up latency of all slices (the plot's curve).
    pub wake: Histogram<u64>,
    /// Wake-up, compute and I/O round trip, µs ([`exact`]).
    pub w: Pct,
    pub c: Pct,
    pub r: Pct,
    pub cycles: u64,
    pub misses: u64,
    pub late: u64,
    pub miss_ratio: f64,
    /// Seconds measured.
    pub secs: f64,
    pub slices: usize,
}

impl Group {
    /// Wake-ups at least `period_us` late: what cyclictest's "samples ≥
    /// period" counts, for a like-for-like comparison (our deadline misses
    /// also count a cycle whose compute ends past the next deadline).
    pub fn wakeups_ge(&self, period_us: u32) -> u64 {
        let ns = u64::from(period_us) * 1000;
        if self.wake.is_empty() || self.wake.max() < ns {
            return 0;
        }
        self.wake.count_between(ns, self.wake.max())
    }

    pub fn of(slices: &[OurSlice]) -> Self {
        let mut wake = new_hist();
        let mut compute = new_hist();
        let mut rt = new_hist();
        for s in slices {
            hist::merge(&mut wake, &s.wakeup);
            hist::merge(&mut compute, &s.compute);
            hist::merge(&mut rt, &s.roundtrip);
        }
        let w = exact(slices, pct_of(&wake), |s| s.json_wakeup);
        let c = exact(slices, pct_of(&compute), |s| s.json_compute);
        let r = exact(slices, pct_of(&rt), |s| s.json_roundtrip);
        let cycles: u64 = slices.iter().map(|s| s.cycles).sum();
        let misses: u64 = slices.iter().map(|s| s.misses).sum();
        let late: u64 = slices.iter().map(|s| s.late).sum();
        Group {
            wake,
            w,
            c,
            r,
            cycles,
            misses,
            late,
            miss_ratio: misses as f64 / cycles.max(1) as f64,
            secs: slices.iter().map(|s| s.len.as_secs_f64()).sum(),
            slices: slices.len(),
        }
    }

    /// It produced at least one slice.
    pub fn ran(&self) -> bool {
        self.slices > 0
    }
}

/// cyclictest's slices, merged.
pub struct CtGroup {
    /// Its 1 µs bins as one HdrHistogram.
    pub hdr: Histogram<u64>,
    /// Overflows and max over all slices (the bins are in `hdr`).
    pub total: CtHistogram,
    pub w: Pct,
    /// Samples at or above one period (cyclictest does not count misses).
    pub ge_period: u64,
    pub secs: f64,
    pub slices: usize,
}

impl CtGroup {
    pub fn of(ct: &[CtSlice], period_us: u32) -> Self {
        let mut hdr = new_hist();
        let mut total = CtHistogram::default();
        for s in ct {
            hist::merge(&mut hdr, &s.hdr);
            total.overflows += s.hist.overflows;
            total.max_us = total.max_us.max(s.hist.max_us);
        }
        CtGroup {
            w: pct_of(&hdr),
            hdr,
            total,
            ge_period: ct
                .iter()
                .map(|s| s.hist.at_or_above(u64::from(period_us)))
                .sum(),
            secs: ct.iter().map(|s| s.len.as_secs_f64()).sum(),
            slices: ct.len(),
        }
    }

    pub fn ran(&self) -> bool {
        self.slices > 0
    }
}

/// Every variant, merged.
pub struct Summary {
    /// The demo machine, idle.
    pub ours: Group,
    /// The 64-axis machine, homing.
    pub axes64: Group,
    /// The EtherCAT backend.
    pub ecat: Group,
    /// Its bus round trips ([`bus_summary`]).
    pub bus: Option<BusRun>,
    pub ct: CtGroup,
}

impl Summary {
    pub fn of(c: &Collected, period_us: u32) -> Self {
        Summary {
            ours: Group::of(&c.ours),
            ecat: Group::of(&c.ours_ecat),
            bus: bus_summary(&c.bus_runs),
            axes64: Group::of(&c.ours64),
            ct: CtGroup::of(&c.ct, period_us),
        }
    }

    /// Adds the run's failures: too many missed deadlines, or (if nothing
    /// else failed and the bench was not interrupted) a variant that was
    /// asked for but produced nothing.
    pub fn judge(
        &self,
        axes64: bool,
        ethercat: bool,
        cyclictest: bool,
        interrupted: bool,
        failures: &mut Vec<String>,
    ) {
        let (ours, ecat, a64) = (&self.ours, &self.ecat, &self.axes64);
        if ours.miss_ratio > MAX_MISS_RATIO {
            failures.push(format!(
                "the supervisor missed {} of {} deadlines ({:.2} % > {:.0} %)",
                ours.misses,
                ours.cycles,
                ours.miss_ratio * 100.0,
                MAX_MISS_RATIO * 100.0
            ));
        }
        if ecat.ran() && ecat.miss_ratio > MAX_MISS_RATIO {
            failures.push(format!(
                "the supervisor (EtherCAT backend) missed {} of {} deadlines ({:.2} % > {:.0} %)",
                ecat.misses,
                ecat.cycles,
                ecat.miss_ratio * 100.0,
                MAX_MISS_RATIO * 100.0
            ));
        }
        if a64.ran() && a64.miss_ratio > MAX_MISS_RATIO {
            failures.push(format!(
                "the supervisor (64 axes homing) missed {} of {} deadlines ({:.2} % > {:.0} %)",
                a64.misses,
                a64.cycles,
                a64.miss_ratio * 100.0,
                MAX_MISS_RATIO * 100.0
            ));
        }
        if axes64 && !a64.ran() && failures.is_empty() && !interrupted {
            failures.push("the 64-axis machine produced no slice".into());
        }
        if ethercat && !ecat.ran() && failures.is_empty() && !interrupted {
            failures.push("the EtherCAT backend produced no slice".into());
        }
        if cyclictest && !self.ct.ran() && failures.is_empty() && !interrupted {
            failures.push("cyclictest produced no samples".into());
        }
    }
}

/// Percentiles of `p` (merged interval logs) with min and max taken exactly
/// from the slices' JSON.
fn exact(slices: &[OurSlice], p: Pct, f: fn(&OurSlice) -> Pct) -> Pct {
    let v: Vec<Pct> = slices.iter().map(f).filter(|p| p.count > 0).collect();
    let mut p = p;
    if !v.is_empty() {
        p.min = v.iter().map(|p| p.min).fold(f64::INFINITY, f64::min);
        p.max = v.iter().map(|p| p.max).fold(0.0, f64::max);
    }
    p
}

/// The bus round trips of all slices in one row: min and max over all,
/// p50 / p99 / p99.9 the highest of the slices (motion-io reports
/// percentiles per run, not its histogram).
fn bus_summary(runs: &[BusRun]) -> Option<BusRun> {
    let first = runs.first()?;
    Some(runs.iter().fold(
        BusRun {
            cycles: 0,
            lost: 0,
            ..*first
        },
        |a, b| BusRun {
            cycles: a.cycles + b.cycles,
            min: a.min.min(b.min),
            p50: a.p50.max(b.p50),
            p99: a.p99.max(b.p99),
            p999: a.p999.max(b.p999),
            max: a.max.max(b.max),
            lost: a.lost + b.lost,
        },
    ))
}
