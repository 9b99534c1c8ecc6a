//! Homing through the binaries, as the benches count it: one `home --json`
//! (of `motionctl` or `motion-supervisor`) run to its end and its rows, and
//! a tally of what became of many homings.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use motion_report::AxisResult;
use serde::Serialize;

use crate::process::{Ended, Running};

/// One `motionctl home --json` (or `motion-supervisor home --json`): how it
/// ended and its rows.
pub struct HomeRun {
    pub ended: Ended,
    pub rows: Vec<AxisResult>,
    /// The whole JSON object it printed, if any.
    pub json: Option<serde_json::Value>,
    pub seconds: f64,
}

impl HomeRun {
    /// It gave rows, and every axis homed (PC, homed, no error).
    pub fn succeeded(&self) -> bool {
        !self.rows.is_empty() && self.rows.iter().all(AxisResult::succeeded)
    }
}

/// The last line of `stdout` that parses as a JSON object.
pub fn last_json(stdout: &str) -> Option<serde_json::Value> {
    stdout
        .lines()
        .rev()
        .find_map(|l| serde_json::from_str::<serde_json::Value>(l.trim()).ok())
        .filter(|v| v.is_object())
}

/// Rows of a `home --json` object.
pub fn rows_of(v: &serde_json::Value) -> Vec<AxisResult> {
    v.get("axes")
        .and_then(|a| serde_json::from_value(a.clone()).ok())
        .unwrap_or_default()
}

/// Runs `cmd` (a `home --json` of either binary) to its end (at most
/// `timeout`) and parses its rows.
pub fn home_run(cmd: &mut Command, label: &str, timeout: Duration) -> Result<HomeRun, String> {
    let t0 = Instant::now();
    let ended = Running::spawn(cmd, label, true, false)?.wait(timeout, Duration::from_secs(5));
    let json = last_json(&ended.stdout);
    let rows = json.as_ref().map(rows_of).unwrap_or_default();
    Ok(HomeRun {
        ended,
        rows,
        json,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// `motionctl --service-prefix P home [AXIS]... --json --timeout T [--parallel]`.
pub fn ctl_home(
    motionctl: &Path,
    prefix: &str,
    axes: &[&str],
    parallel: bool,
    timeout_s: f64,
) -> Result<HomeRun, String> {
    let mut cmd = Command::new(motionctl);
    cmd.args(["--service-prefix", prefix, "home"])
        .args(axes)
        .args(["--json", "--timeout", &format!("{timeout_s}")]);
    if parallel {
        cmd.arg("--parallel");
    }
    home_run(
        &mut cmd,
        "motionctl home",
        Duration::from_secs_f64(timeout_s + 30.0),
    )
}

/// What became of homings, counted per axis.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Tally {
    /// Homing requests (one `home` command each).
    pub requests: u64,
    /// Axis homings with a result row.
    pub axis_homings: u64,
    /// Rows with PC set, homed and no error.
    pub ok: u64,
    /// Rows failed with ERR 12 / EXERR 40 (feedback lost).
    pub feedback_lost: u64,
    /// Rows failed with any other error.
    pub other_errors: u64,
    /// Rows that ended not homed (failed ones included).
    pub not_homed: u64,
    /// Requests that gave no rows at all (crash, refusal, timeout).
    pub run_failures: u64,
    /// Axes found no longer homed before the next homing (daemon only).
    pub lost_between: u64,
    /// One line per problem.
    pub details: Vec<String>,
}

/// At most this many detail lines are kept.
const MAX_DETAILS: usize = 200;

impl Tally {
    /// Counts one run's rows (`what` names it in the details); false if
    /// anything failed.
    pub fn add(&mut self, what: &str, run: &HomeRun) -> bool {
        self.requests += 1;
        if run.rows.is_empty() {
            self.run_failures += 1;
            let errors = run
                .json
                .as_ref()
                .and_then(|j| j.get("errors"))
                .map(|e| e.to_string())
                .unwrap_or_default();
            self.note(format!(
                "{what}: no result rows ({}); {errors} {}",
                run.ended.describe(),
                tail(&run.ended.stderr, 3)
            ));
            return false;
        }
        let mut all_ok = true;
        for r in &run.rows {
            self.axis_homings += 1;
            if !r.homed {
                self.not_homed += 1;
            }
            if r.succeeded() {
                self.ok += 1;
                continue;
            }
            all_ok = false;
            if r.er && r.err == 12 && r.exerr == 40 {
                self.feedback_lost += 1;
            } else {
                self.other_errors += 1;
            }
            self.note(format!(
                "{what}: axis {}: pc {} er {} homed {} err {}/{} {}; duration {:?} s",
                r.name,
                r.pc,
                r.er,
                r.homed,
                r.err,
                r.exerr,
                r.error.as_deref().unwrap_or(""),
                r.duration_s
            ));
        }
        all_ok
    }

    pub fn note(&mut self, s: String) {
        if self.details.len() < MAX_DETAILS {
            self.details.push(s);
        }
    }

    pub fn merge(&mut self, o: &Tally) {
        self.requests += o.requests;
        self.axis_homings += o.axis_homings;
        self.ok += o.ok;
        self.feedback_lost += o.feedback_lost;
        self.other_errors += o.other_errors;
        self.not_homed += o.not_homed;
        self.run_failures += o.run_failures;
        self.lost_between += o.lost_between;
        for d in &o.details {
            self.note(d.clone());
        }
    }

    /// Rows that did not succeed plus requests without rows.
    pub fn failures(&self) -> u64 {
        self.axis_homings - self.ok + self.run_failures
    }
}

/// The last `n` lines of `s`, joined with " | ".
pub fn tail(s: &str, n: usize) -> String {
    let lines: Vec<&str> = s.trim().lines().collect();
    lines[lines.len().saturating_sub(n)..].join(" | ")
}
