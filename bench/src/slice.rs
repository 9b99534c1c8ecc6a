//! One `motion-supervisor run --json --hlog` slice as the slice benches
//! (jitter, cpcost) start and read it, and the slices of one variant merged.
//! The supervisor measures its own cycle; a bench only starts it and reads,
//! every bench the same way.

use crate::drive::{self, Binaries};
use crate::proc::{Ended, Running};
use crate::{histogram, hlog, percentiles};
use hdrhistogram::Histogram;
use motion_report::{Latency, Percentiles, RunReport};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Share of missed deadlines above which a bench fails.
pub const MAX_MISS_RATIO: f64 = 0.01;

/// Starts the daemon of the machine `toml` (written to `tmp/TAG.toml`)
/// under `prefix` for `len` s, its intervals logged to `tmp/TAG.hlog`, with
/// the `extra` arguments; returns it and the log's path.
pub fn start(
    b: &Binaries,
    tmp: &Path,
    (tag, toml, prefix): (&str, &str, &str),
    len: f64,
    extra: &[&str],
) -> Result<(Running, PathBuf), String> {
    let (cfg, log) = (
        tmp.join(format!("{tag}.toml")),
        tmp.join(format!("{tag}.hlog")),
    );
    std::fs::write(&cfg, toml).map_err(|e| format!("{}: {e}", cfg.display()))?;
    let mut cmd = drive::run_command(b, &cfg, prefix);
    cmd.args(["--duration", &len.to_string(), "--hlog"])
        .arg(&log);
    let run = Running::spawn(cmd.args(extra), "motion-supervisor run", true, false)?;
    Ok((run, log))
}

/// What one slice measured.
pub struct Slice {
    /// When it started, from the bench's start.
    pub start: Duration,
    /// Seconds it ran.
    pub len: f64,
    /// Wake-up, compute and I/O round trip of every cycle (its interval log).
    pub wakeup: Histogram<u64>,
    pub compute: Histogram<u64>,
    pub roundtrip: Histogram<u64>,
    /// Its report's exact figures: counts, min and max.
    pub lat: Latency,
    /// The supervisor process (all its threads) and its motion-io processes
    /// (summed), share of one core over `wall_s`.
    pub cpu: Option<f64>,
    pub io_cpu: Option<f64>,
    pub wall_s: f64,
}

/// Reads a finished run: it must have succeeded, printed its report and
/// measured cycles; errors carry the end of its stderr. Returns the slice
/// and the warnings of the run and of its real-time set-up (one more if the
/// cycle did not run SCHED_FIFO).
pub fn read(
    ended: &Ended,
    log: &Path,
    start: Duration,
    len: f64,
) -> Result<(Slice, Vec<String>), String> {
    let tail = match ended.stderr.trim() {
        "" => String::new(),
        e => format!("; its stderr: {}", drive::tail(e, 8)),
    };
    if !ended.success() {
        return Err(format!("{}{tail}", ended.describe()));
    }
    let report: RunReport = (ended.stdout.lines().rev())
        .find_map(|l| serde_json::from_str(l.trim()).ok())
        .ok_or_else(|| format!("no run report on its stdout{tail}"))?;
    if report.latency.cycles == 0 {
        return Err(format!("it measured no cycles{tail}"));
    }
    let (mut warnings, rt) = (report.warnings, report.rt);
    warnings.extend(rt.iter().flat_map(|r| r.warnings.iter().cloned()));
    if rt.as_ref().map(|r| r.policy.as_str()) != Some("SCHED_FIFO") {
        warnings.push(format!("the cycle did not run SCHED_FIFO (rt: {rt:?})"));
    }
    let iv = hlog::read(log)?;
    let io: Vec<f64> = report.cpu.io.iter().filter_map(|(_, c)| *c).collect();
    let slice = Slice {
        start,
        len,
        wakeup: hlog::sum(&iv, "wakeup"),
        compute: hlog::sum(&iv, "compute"),
        roundtrip: hlog::sum(&iv, "roundtrip"),
        lat: report.latency,
        cpu: report.cpu.supervisor,
        io_cpu: (!io.is_empty()).then(|| io.iter().sum()),
        wall_s: report.cpu.wall_s,
    };
    Ok((slice, warnings))
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
        let merged = |f: fn(&Slice) -> &Histogram<u64>| {
            let mut h = histogram();
            slices.iter().for_each(|s| hlog::merge(&mut h, f(s)));
            h
        };
        // percentiles of the merged logs, min and max exact from the JSON
        let exact = |h: &Histogram<u64>, f: fn(&Latency) -> Percentiles| {
            let v = slices.iter().map(|s| f(&s.lat)).filter(|p| p.count > 0);
            let v: Vec<Percentiles> = v.collect();
            let mut p = percentiles(h);
            if !v.is_empty() {
                p.min = v.iter().map(|p| p.min).fold(f64::INFINITY, f64::min);
                p.max = v.iter().map(|p| p.max).fold(0.0, f64::max);
            }
            p
        };
        let weighted = |f: fn(&Slice) -> Option<f64>| {
            let v = slices.iter().filter_map(|s| Some((f(s)?, s.wall_s)));
            let (sum, wall) = v.fold((0.0, 0.0), |(a, w), (x, t)| (a + x * t, w + t));
            (wall > 0.0).then(|| sum / wall)
        };
        let sum = |f: fn(&Latency) -> u64| slices.iter().map(|s| f(&s.lat)).sum::<u64>();
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
            cpu: weighted(|s| s.cpu),
            io_cpu: weighted(|s| s.io_cpu),
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
