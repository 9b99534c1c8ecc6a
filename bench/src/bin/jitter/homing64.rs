//! The 64-axis machine under load: while the supervisor's cycle is measured,
//! `motionctl home --parallel` homes all 64 axes again and again, so that
//! the latency is measured with every axis moving, next to the idle demo
//! machine. The homings themselves are counted too (all homed, a failed
//! axis, cut off by the slice's end).

use crate::supervisor;
use motion_bench::drive::{self, Tally};
use motion_bench::proc::{self, Running};
use serde_json::{json, Value};
use std::path::Path;
use std::time::{Duration, Instant};

/// The homings of the 64-axis machine during its slices.
#[derive(Default)]
pub struct Homing64 {
    /// `motionctl home --parallel` commands started.
    pub started: u64,
    /// ... in which every axis homed (PC, homed, no error).
    pub ok: u64,
    /// ... in which some axis did not, while the supervisor ran on.
    pub failed: u64,
    /// ... ended by the end of the slice (the supervisor stops every axis).
    pub cut_off: u64,
    /// Per axis, the homings that were not cut off.
    pub tally: Tally,
    /// Seconds from a homing's start to its end (complete ones).
    pub durations: Vec<f64>,
}

impl Homing64 {
    /// Adds one slice's homings.
    pub fn merge(&mut self, h: Homing64) {
        self.started += h.started;
        self.ok += h.ok;
        self.failed += h.failed;
        self.cut_off += h.cut_off;
        self.tally.merge(&h.tally);
        self.durations.extend(h.durations);
    }

    /// The report's line for `secs` s of 64-axis slices.
    pub fn line(&self, secs: f64) -> String {
        let mean = if self.durations.is_empty() {
            0.0
        } else {
            self.durations.iter().sum::<f64>() / self.durations.len() as f64
        };
        format!(
            "64 axes: {} parallel homing(s) in {:.0} s ({:.1} s each): {} all homed, {} with a failed axis, {} cut off by a slice's end; \
             axis homings {}: {} ok, {} ERR 12/40 (feedback lost), {} other error(s), {} not homed",
            self.started,
            secs,
            mean,
            self.ok,
            self.failed,
            self.cut_off,
            self.tally.axis_homings,
            self.tally.ok,
            self.tally.feedback_lost,
            self.tally.other_errors,
            self.tally.not_homed
        )
    }

    /// The JSON report's `homing` object.
    pub fn json(&self) -> Value {
        json!({
            "started": self.started,
            "all_homed": self.ok,
            "with_failed_axis": self.failed,
            "cut_off_by_slice_end": self.cut_off,
            "axes": self.tally,
            "mean_duration_s": if self.durations.is_empty() { 0.0 }
                else { self.durations.iter().sum::<f64>() / self.durations.len() as f64 },
        })
    }
}

/// Runs `motion-supervisor run` on the 64-axis `toml` for `len` s (as
/// [`supervisor::run`]) and, while it runs, homes every axis in parallel
/// with `motionctl home --parallel`, one homing after the other.
#[allow(clippy::too_many_arguments)]
pub fn run(
    supervisor: &Path,
    motionctl: &Path,
    tmp: &Path,
    tag: &str,
    toml: &str,
    prefix: &str,
    len: f64,
    hlog: &Path,
) -> Result<(proc::Ended, Homing64), String> {
    let mut cmd = supervisor::run_command(supervisor, tmp, tag, toml, prefix, len, hlog)?;
    let t0 = Instant::now();
    let mut r = Running::spawn(&mut cmd, "motion-supervisor", true, false)?;
    let mut h = Homing64::default();
    if drive::wait_until_ready(motionctl, prefix, &mut r, Duration::from_secs_f64(len)).is_ok() {
        while r.running() && !proc::stop_requested() && t0.elapsed().as_secs_f64() < len {
            let started = Instant::now();
            h.started += 1;
            let run = drive::ctl_home(motionctl, prefix, &[], true, len + 10.0)?;
            let all_ok = !run.rows.is_empty() && run.rows.iter().all(|x| x.succeeded());
            if all_ok {
                h.ok += 1;
                h.tally.add(&format!("{prefix} homing {}", h.started), &run);
                h.durations.push(started.elapsed().as_secs_f64());
            } else if (!r.running() || t0.elapsed().as_secs_f64() >= len - 0.5)
                && run.rows.iter().all(|x| {
                    x.succeeded() || (x.er && x.err == 12 && x.exerr == 1) || (!x.er && !x.homed)
                })
            {
                // the supervisor's --duration ended it: every axis stopped
                // (ERR 12/1), the homed ones unhomed; any other code counts
                h.cut_off += 1;
            } else {
                h.failed += 1;
                h.tally.add(&format!("{prefix} homing {}", h.started), &run);
            }
        }
    }
    let left = Duration::from_secs_f64(len + 60.0).saturating_sub(t0.elapsed());
    Ok((r.wait(left, Duration::from_secs(10)), h))
}
