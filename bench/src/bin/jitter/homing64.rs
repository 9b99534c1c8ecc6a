//! The 64-axis machine under load: while the supervisor's cycle is measured,
//! `motionctl home --parallel` homes all 64 axes again and again, so that
//! the latency is measured with every axis moving, next to the idle demo
//! machine. The homings themselves are counted too (all homed, a failed
//! axis, cut off by the slice's end).

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

    fn mean_s(&self) -> f64 {
        let n = self.durations.len().max(1) as f64;
        self.durations.iter().sum::<f64>() / n
    }

    /// The progress line's part.
    pub fn progress(&self) -> String {
        let (n, ok, failed, cut) = (self.started, self.ok, self.failed, self.cut_off);
        format!("; {n} homing(s) of 64 axes: {ok} ok, {failed} failed, {cut} cut off by the slice's end")
    }

    /// The report's line for `secs` s of 64-axis slices.
    pub fn line(&self, secs: f64) -> String {
        let (n, ok, failed, cut, t) = (
            self.started,
            self.ok,
            self.failed,
            self.cut_off,
            &self.tally,
        );
        format!(
            "64 axes: {n} parallel homing(s) in {secs:.0} s ({:.1} s each): {ok} all homed, {failed} with a failed axis, {cut} cut off by a slice's end; \
             axis homings {}: {} ok, {} ERR 12/40 (feedback lost), {} other error(s), {} not homed",
            self.mean_s(), t.axis_homings, t.ok, t.feedback_lost, t.other_errors, t.not_homed
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
            "mean_duration_s": self.mean_s(),
        })
    }
}

/// While `sup` (started at `t0` for `len` s, prefix `prefix`) runs, homes
/// every axis in parallel with `motionctl home --parallel`, one homing
/// after the other.
pub fn home_while(
    motionctl: &Path,
    prefix: &str,
    sup: &mut Running,
    t0: Instant,
    len: f64,
) -> Result<Homing64, String> {
    let mut h = Homing64::default();
    if drive::wait_until_ready(motionctl, prefix, sup, Duration::from_secs_f64(len)).is_err() {
        return Ok(h);
    }
    let running = |sup: &mut Running| sup.running() && t0.elapsed().as_secs_f64() < len;
    while running(sup) && !proc::stop_requested() {
        let started = Instant::now();
        h.started += 1;
        let run = drive::ctl_home(motionctl, prefix, &[], true, len + 10.0)?;
        let what = format!("{prefix} homing {}", h.started);
        if run.succeeded() {
            h.ok += 1;
            h.tally.add(&what, &run);
            h.durations.push(started.elapsed().as_secs_f64());
        } else if (!sup.running() || t0.elapsed().as_secs_f64() >= len - 0.5)
            && (run.rows.iter()).all(|x| {
                x.succeeded() || (x.er && x.err == 12 && x.exerr == 1) || (!x.er && !x.homed)
            })
        {
            // the supervisor's --duration ended it: every axis stopped
            // (ERR 12/1), the homed ones unhomed; any other code counts
            h.cut_off += 1;
        } else {
            h.failed += 1;
            h.tally.add(&what, &run);
        }
    }
    Ok(h)
}
