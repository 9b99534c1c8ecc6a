//! The slices of one variant merged: the slice benches (jitter, cpcost)
//! run `motion-supervisor run --duration --json --hlog` in slices
//! ([`crate::runs`] starts one and reads it back) and report each
//! variant as one.

use crate::runs::Measured;
use hdrhistogram::Histogram;
use motion_report::{Latency, Percentiles};
use motion_supervisor::hlog;
use motion_supervisor::stats::{histogram, percentiles};
use serde_json::{json, Value};
use std::time::Duration;

/// Share of missed deadlines above which a bench fails.
pub const MAX_MISS_RATIO: f64 = 0.01;

/// One slice: when it started (from the bench's start), how many seconds
/// it ran, what it measured.
pub struct Slice {
    pub start: Duration,
    pub len: f64,
    pub m: Measured,
}

/// The slices of one variant merged: percentiles of the merged interval
/// logs with min and max exact from the reports, counts summed, CPU use
/// weighted by run time.
pub struct Group {
    /// Wake-up latency of every slice (the plot's curve).
    pub wake: Histogram<u64>,
    /// Wake-up, compute and I/O round trip, µs.
    pub w: Percentiles,
    pub c: Percentiles,
    pub r: Percentiles,
    pub cycles: u64,
    pub misses: u64,
    pub late: u64,
    pub miss_ratio: f64,
    pub cpu: Option<f64>,
    pub io_cpu: Option<f64>,
    /// Seconds measured.
    pub secs: f64,
    pub slices: usize,
}

impl Group {
    pub fn of(slices: &[&Slice]) -> Self {
        let merged = |f: fn(&Measured) -> &Histogram<u64>| {
            let mut h = histogram();
            slices.iter().for_each(|s| hlog::merge(&mut h, f(&s.m)));
            h
        };
        // percentiles of the merged logs, min and max exact from the JSON
        let exact = |h: &Histogram<u64>, f: fn(&Latency) -> Percentiles| {
            let v = slices.iter().map(|s| f(&s.m.report.latency));
            let v = v.filter(|p| p.count > 0);
            let v: Vec<Percentiles> = v.collect();
            let mut p = percentiles(h);
            if !v.is_empty() {
                p.min = v.iter().map(|p| p.min).fold(f64::INFINITY, f64::min);
                p.max = v.iter().map(|p| p.max).fold(0.0, f64::max);
            }
            p
        };
        let weighted = |f: fn(&Measured) -> Option<f64>| {
            let v = slices
                .iter()
                .filter_map(|s| Some((f(&s.m)?, s.m.report.cpu.wall_s)));
            let (sum, wall) = v.fold((0.0, 0.0), |(a, w), (x, t)| (a + x * t, w + t));
            (wall > 0.0).then(|| sum / wall)
        };
        let sum =
            |f: fn(&Latency) -> u64| slices.iter().map(|s| f(&s.m.report.latency)).sum::<u64>();
        let wake = merged(|s| &s.wakeup);
        let (cycles, misses) = (sum(|l| l.cycles), sum(|l| l.deadline_misses));
        Group {
            w: exact(&wake, |l| l.wakeup_us),
            c: exact(&merged(|s| &s.compute), |l| l.compute_us),
            r: exact(&merged(|s| &s.roundtrip), |l| l.io_roundtrip_us),
            wake,
            cycles,
            misses,
            late: sum(|l| l.late_replies),
            miss_ratio: misses as f64 / cycles.max(1) as f64,
            cpu: weighted(Measured::cpu),
            io_cpu: weighted(Measured::io_cpu),
            secs: slices.iter().map(|s| s.len).sum(),
            slices: slices.len(),
        }
    }

    /// Its figures in a report's JSON.
    pub fn json(&self) -> Value {
        json!({
            "seconds": self.secs,
            "slices": self.slices,
            "cycles": self.cycles,
            "deadline_misses": self.misses,
            "deadline_miss_ratio": self.miss_ratio,
            "late_replies": self.late,
            "wakeup_us": self.w,
            "compute_us": self.c,
            "io_roundtrip_us": self.r,
        })
    }

    /// It produced at least one slice.
    pub fn ran(&self) -> bool {
        self.slices > 0
    }

    /// `(x.xx % > 1 %)` if it missed more than [`MAX_MISS_RATIO`] of its
    /// deadlines.
    pub fn too_many_misses(&self) -> Option<String> {
        let (r, max) = (self.miss_ratio * 100.0, MAX_MISS_RATIO * 100.0);
        (self.miss_ratio > MAX_MISS_RATIO).then(|| format!("({r:.2} % > {max:.0} %)"))
    }

    /// Wake-ups at least `period_us` late: what cyclictest's "samples ≥
    /// period" counts, for a like-for-like comparison (our deadline misses
    /// also count a cycle whose compute ends past the next deadline).
    pub fn wakeups_ge(&self, period_us: u32) -> u64 {
        let ns = u64::from(period_us) * 1000;
        match self.wake.is_empty() || self.wake.max() < ns {
            true => 0,
            false => self.wake.count_between(ns, self.wake.max()),
        }
    }
}

/// `a / b` per column of [`Percentiles::values`] in a report's JSON, two
/// decimals; null where `b` is 0.
pub fn ratio_json(a: &Percentiles, b: &Percentiles) -> Value {
    let keys = ["min", "p50", "p99", "p999", "p9999", "max"];
    let r = a.ratio(b).map(|x| x.map(|x| motion_report::round(x, 2)));
    Value::Object(
        keys.iter()
            .zip(r)
            .map(|(k, v)| (k.to_string(), json!(v)))
            .collect(),
    )
}
