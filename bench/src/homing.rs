//! Homing through the binaries, as the benches count it: one `home --json`
//! (of `motionctl` or `motion-supervisor`) run to its end and its rows, and
//! a tally of what became of many homings.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use motion_report::AxisResult;
use serde::Serialize;

use crate::proc::{stop_requested, tail, Ended, Running};

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

/// One homing of `axis` recorded by `motionctl trace AXIS --home --json
/// --out CSV` (every cycle); its result row from `motionctl status` once
/// the trace has ended, the trace's output and the status in its `json`.
pub fn traced_home(
    motionctl: &Path,
    prefix: &str,
    axis: &str,
    csv: &Path,
    timeout_s: f64,
) -> Result<HomeRun, String> {
    let mut cmd = Command::new(motionctl);
    cmd.args([
        "--service-prefix",
        prefix,
        "trace",
        axis,
        "--home",
        "--json",
        "--out",
    ]);
    cmd.arg(csv).args(["--timeout", &timeout_s.to_string()]);
    let limit = Duration::from_secs_f64(timeout_s + 30.0);
    let mut run = home_run(&mut cmd, "motionctl trace", limit)?;
    let status = motion_harness::daemon::status(motionctl, prefix);
    let row = |a: &motion_report::AxisStatus| AxisResult {
        name: a.name.clone(),
        pc: a.pc,
        er: a.er,
        err: a.err,
        exerr: a.exerr,
        homed: a.homed,
        error: a.error.clone(),
        duration_s: Some(a.elapsed_s),
        ..AxisResult::default()
    };
    let axes = status.iter().flat_map(|s| &s.axes);
    run.rows = axes.filter(|a| a.name == axis).map(row).collect();
    if let Some(st) = status {
        run.json = Some(serde_json::json!({"trace": run.json.take(), "status": st}));
    }
    Ok(run)
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

/// Parallel homings of every axis again and again while a daemon runs (the
/// jitter bench's 64-axis machine, measured with every axis moving), and
/// what became of them.
#[derive(Debug, Default)]
pub struct Repeated {
    /// `motionctl home --parallel` commands started.
    pub started: u64,
    /// ... in which every axis homed (PC, homed, no error).
    pub ok: u64,
    /// ... in which some axis did not, while the supervisor ran on.
    pub failed: u64,
    /// ... ended by the end of the run (the supervisor stops every axis).
    pub cut_off: u64,
    /// Per axis, the homings that were not cut off.
    pub tally: Tally,
    /// Seconds from a homing's start to its end (complete ones).
    pub durations: Vec<f64>,
}

impl Repeated {
    /// While the ready daemon `sup` (started at `t0` for `len` s, prefix
    /// `prefix`) runs, homes every axis in parallel, one homing after the
    /// other.
    pub fn run(
        motionctl: &Path,
        prefix: &str,
        sup: &mut Running,
        t0: Instant,
        len: f64,
    ) -> Result<Repeated, String> {
        let mut h = Repeated::default();
        let running = |sup: &mut Running| sup.running() && t0.elapsed().as_secs_f64() < len;
        while running(sup) && !stop_requested() {
            let started = Instant::now();
            h.started += 1;
            let run = ctl_home(motionctl, prefix, &[], true, len + 10.0)?;
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

    /// Adds another run's homings.
    pub fn merge(&mut self, h: Repeated) {
        self.started += h.started;
        self.ok += h.ok;
        self.failed += h.failed;
        self.cut_off += h.cut_off;
        self.tally.merge(&h.tally);
        self.durations.extend(h.durations);
    }

    /// The mean of [`Repeated::durations`], s (0 without any).
    pub fn mean_s(&self) -> f64 {
        let n = self.durations.len().max(1) as f64;
        self.durations.iter().sum::<f64>() / n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    /// Homings through a `motionctl` whose `home` answers, after 50 ms,
    /// with one row of X as given, while a daemon (a `sleep`) runs `len` s.
    fn repeat(dir: &Path, (pc, er, err, exerr): (bool, bool, u16, u16), len: f64) -> Repeated {
        let homed = pc && !er;
        let row = AxisResult {
            name: "X".into(),
            pc,
            er,
            err,
            exerr,
            homed,
            ..AxisResult::default()
        };
        let answer = serde_json::json!({ "axes": [row] }).to_string();
        std::fs::write(dir.join("answer"), answer).unwrap();
        let motionctl = dir.join("motionctl");
        let script = format!("#!/bin/sh\nsleep 0.05\ncat {}/answer\n", dir.display());
        std::fs::write(&motionctl, script).unwrap();
        std::fs::set_permissions(&motionctl, std::fs::Permissions::from_mode(0o755)).unwrap();
        let mut sup = Running::spawn(Command::new("sleep").arg("5"), "sleep", true, false).unwrap();
        Repeated::run(&motionctl, "p", &mut sup, Instant::now(), len).unwrap()
    }

    #[test]
    fn a_traced_homing_takes_its_row_from_the_status() {
        let dir = motion_harness::TempDir::new("traced");
        let mut st = motion_report::StatusReport::default();
        for (name, homed) in [("Y", false), ("X", true)] {
            let (pc, elapsed_s) = (homed, 1.5);
            let a = motion_report::AxisStatus {
                name: name.into(),
                pc,
                homed,
                elapsed_s,
                ..Default::default()
            };
            st.axes.push(a);
        }
        std::fs::write(
            dir.path().join("status"),
            serde_json::to_string(&st).unwrap(),
        )
        .unwrap();
        let motionctl = dir.path().join("motionctl");
        let script = format!(
            "#!/bin/sh\ncase $3 in\n  trace) echo '{{\"axis\":\"X\"}}' ;;\n  status) cat {}/status ;;\nesac\n",
            dir.path().display()
        );
        std::fs::write(&motionctl, script).unwrap();
        std::fs::set_permissions(&motionctl, std::fs::Permissions::from_mode(0o755)).unwrap();
        let csv = dir.path().join("x.csv");
        let run = traced_home(&motionctl, "p", "X", &csv, 5.0).unwrap();
        assert!(run.ended.success() && run.succeeded(), "{:?}", run.ended);
        assert_eq!((run.rows.len(), run.rows[0].duration_s), (1, Some(1.5)));
        let json = run.json.unwrap();
        assert_eq!(
            (
                json["trace"]["axis"].as_str(),
                json["status"]["axes"][1]["name"].as_str()
            ),
            (Some("X"), Some("X"))
        );
    }

    #[test]
    fn homings_are_repeated_while_the_daemon_runs_and_counted() {
        let dir = motion_harness::TempDir::new("repeated");
        let ok = repeat(dir.path(), (true, false, 0, 0), 0.4);
        assert!(ok.started >= 2 && ok.ok == ok.started, "{ok:?}");
        assert_eq!(
            (ok.failed, ok.cut_off, ok.durations.len() as u64),
            (0, 0, ok.started)
        );
        assert!(ok.mean_s() >= 0.05, "{ok:?}");
        // a failed axis while the daemon runs on; 12/1 at the run's end
        let failed = repeat(dir.path(), (false, true, 12, 40), 0.3);
        assert!(
            failed.failed >= 1 && failed.tally.feedback_lost == failed.failed,
            "{failed:?}"
        );
        let cut = repeat(dir.path(), (false, true, 12, 1), 0.3);
        assert!(
            cut.cut_off >= 1 && cut.failed == 0 && cut.tally.requests == 0,
            "{cut:?}"
        );
        let mut all = Repeated::default();
        all.merge(ok);
        all.merge(cut);
        assert_eq!(all.started, all.ok + all.cut_off);
    }
}
