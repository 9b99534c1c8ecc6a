//! Driving a running supervisor from the benches: its binaries, waiting for
//! its session, homing through `motionctl`, tallying homing results,
//! finding the `motion-io` it spawned, stress-ng, shared memory left over.

use crate::host;
use crate::proc::{self, Ended, Running};
use motion_report::AxisResult;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// `motion-supervisor` (given, or next to this binary) and `motion-io` and
/// `motionctl` next to it.
pub struct Binaries {
    pub supervisor: PathBuf,
    pub io: PathBuf,
    pub motionctl: PathBuf,
}

impl Binaries {
    pub fn find(supervisor: Option<&Path>) -> Result<Self, String> {
        let supervisor = match supervisor {
            Some(p) => p.to_path_buf(),
            None => host::sibling_exe("motion-supervisor").ok_or_else(|| {
                "motion-supervisor not found next to this binary; build it first: \
                 `cargo build --release --workspace --bins` (with the same CARGO_TARGET_DIR), \
                 or pass --supervisor PATH"
                    .to_string()
            })?,
        };
        let io = std::env::var_os("MOTION_IO_BIN")
            .map(PathBuf::from)
            .unwrap_or_else(|| supervisor.with_file_name("motion-io"));
        let motionctl = supervisor.with_file_name("motionctl");
        for p in [&supervisor, &io, &motionctl] {
            if !host::is_executable(p) {
                return Err(format!(
                    "{} is not an executable file (build the workspace's binaries: \
                     `cargo build --release --workspace --bins`)",
                    p.display()
                ));
            }
        }
        Ok(Self {
            supervisor,
            io,
            motionctl,
        })
    }
}

/// Waits until the supervisor of `prefix` has written its session file and
/// answers `motionctl status` with every I/O process attached, or `sup`
/// ended, or `timeout` passed.
pub fn wait_until_ready(
    motionctl: &Path,
    prefix: &str,
    sup: &mut Running,
    timeout: Duration,
) -> Result<(), String> {
    let until = Instant::now() + timeout;
    loop {
        if !sup.running() {
            return Err("the supervisor ended before it was ready".into());
        }
        if proc::stop_requested() {
            return Err("interrupted".into());
        }
        if motion_frames::Domain::join(prefix, None).is_ok() {
            if let Some(v) = status(motionctl, prefix) {
                let attached = v["io"]
                    .as_array()
                    .is_some_and(|a| !a.is_empty() && a.iter().all(|i| i["attached"] == true));
                if attached {
                    return Ok(());
                }
            }
        }
        if Instant::now() > until {
            return Err(format!(
                "the supervisor of prefix {prefix} was not ready (session, I/O attached) within {} s",
                timeout.as_secs_f64()
            ));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `motionctl --service-prefix P status --json`, parsed (None on failure).
pub fn status(motionctl: &Path, prefix: &str) -> Option<serde_json::Value> {
    let out = Command::new(motionctl)
        .args(["--service-prefix", prefix, "status", "--json"])
        .stdin(std::process::Stdio::null())
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    serde_json::from_slice(&out.stdout).ok()
}

/// One `motionctl home --json` (or `motion-supervisor home --json`): how it
/// ended and its rows.
pub struct HomeRun {
    pub ended: Ended,
    pub rows: Vec<AxisResult>,
    /// The whole JSON object it printed, if any.
    pub json: Option<serde_json::Value>,
    pub seconds: f64,
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

/// The `motion-io` processes whose parent is `parent`.
pub fn io_children(parent: u32) -> Vec<u32> {
    let mut v = Vec::new();
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return v;
    };
    for e in dir.flatten() {
        let Some(pid) = e.file_name().to_str().and_then(|s| s.parse::<u32>().ok()) else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
            continue;
        };
        // pid (comm) state ppid ...
        let (Some(open), Some(close)) = (stat.find('('), stat.rfind(')')) else {
            continue;
        };
        let comm = &stat[open + 1..close];
        let ppid = stat[close + 1..]
            .split_whitespace()
            .nth(1)
            .and_then(|s| s.parse::<u32>().ok());
        if comm == "motion-io" && ppid == Some(parent) {
            v.push(pid);
        }
    }
    v
}

/// `stress-ng --cpu 1 --taskset CPU --timeout BOUND` in its own process
/// group (ended with the returned handle, or by its own timeout).
pub fn stress(cpu: usize, bound: Duration) -> Result<Running, String> {
    let bin = host::find_in_path("stress-ng")
        .ok_or("stress-ng not found (apt-get install -y stress-ng)".to_string())?;
    let mut c = Command::new(bin);
    c.args([
        "--cpu",
        "1",
        "--taskset",
        &cpu.to_string(),
        "--timeout",
        &format!("{}s", bound.as_secs().max(1)),
        "--quiet",
    ]);
    let r = Running::spawn(&mut c, "stress-ng", true, true)?;
    std::thread::sleep(Duration::from_millis(300));
    Ok(r)
}

/// What a prefix left behind: its files in `/dev/shm` and its session file.
pub fn leftovers(prefix: &str) -> Vec<String> {
    let mut v = motion_frames::Domain::shm_files_of_prefix(prefix);
    let session =
        motion_frames::domain::session_path(&motion_frames::domain::default_runtime_dir(), prefix);
    if session.exists() {
        v.push(session.display().to_string());
    }
    v
}

/// What a prefix left behind once all its processes ended, and what of it
/// remains after `cleanup_stale_domains` (which touches only domains without
/// a live node). A client (`motionctl`) whose node exists while the
/// supervisor runs its final clean-up keeps the domain's node-counter
/// segment alive, and motionctl does not clean up after itself: that
/// segment is what is usually found here.
pub fn clean_leftovers(prefix: &str) -> (Vec<String>, Vec<String>) {
    let found = leftovers(prefix);
    if found.is_empty() {
        return (found, Vec::new());
    }
    motion_frames::cleanup::cleanup_stale_domains(
        prefix,
        &motion_frames::domain::default_runtime_dir(),
    );
    (found, leftovers(prefix))
}

/// `motion-supervisor run --config CFG --json --service-prefix P [--duration S] [--hlog F]`,
/// output captured, not waited for.
pub fn spawn_run(
    b: &Binaries,
    cfg: &Path,
    prefix: &str,
    duration: Option<f64>,
    hlog: Option<&Path>,
) -> Result<Running, String> {
    let mut cmd = Command::new(&b.supervisor);
    cmd.arg("run")
        .arg("--config")
        .arg(cfg)
        .arg("--json")
        .arg("--service-prefix")
        .arg(prefix);
    if let Some(d) = duration {
        cmd.arg("--duration").arg(format!("{d}"));
    }
    if let Some(h) = hlog {
        cmd.arg("--hlog").arg(h);
    }
    Running::spawn(&mut cmd, "motion-supervisor run", true, false)
}

/// Asks a running supervisor to stop (SIGTERM) and collects its output.
pub fn stop_run(r: Running, timeout: Duration) -> Ended {
    r.send_signal(libc::SIGTERM);
    r.wait(timeout, Duration::from_secs(5))
}
