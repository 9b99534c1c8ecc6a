//! The daemon (`motion-supervisor run`): starting it, knowing when it is
//! ready — its session is there and `motionctl status --json`, read as the
//! typed [`StatusReport`], shows its I/O processes attached — reading its
//! status, and stopping it (SIGTERM, its report collected). [`wait_ready`]
//! and [`status`] serve any daemon the caller started (the benches start
//! theirs with their own binaries); [`Daemon`] is a test's.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use motion_report::{AxisStatus, ErrorReport, StatusReport};

use crate::bins::test_bin;
use crate::check::named;
use crate::commands::{ctl, spawn_supervisor};
use crate::machines::TempConfig;
use crate::process::{self, Ended, Running};

/// Which I/O processes must show attached before the daemon counts as ready.
#[derive(Clone, Copy, Debug)]
pub enum Attached<'a> {
    /// At least one, and every one the status lists.
    All,
    /// These, by name (none: the status answering is enough).
    These(&'a [&'a str]),
}

impl Attached<'_> {
    fn in_(&self, s: &StatusReport) -> bool {
        let attached = |name: &str| s.io.iter().any(|i| i.name == name && i.attached);
        match self {
            Attached::All => !s.io.is_empty() && s.io.iter().all(|i| i.attached),
            Attached::These(names) => names.iter().all(|n| attached(n)),
        }
    }
}

/// `motionctl --service-prefix P status --json` (None: no answer).
pub fn status(motionctl: &Path, prefix: &str) -> Option<StatusReport> {
    let out = Command::new(motionctl)
        .args(["--service-prefix", prefix, "status", "--json"])
        .stdin(Stdio::null())
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    serde_json::from_slice(&out.stdout).ok()
}

/// Waits until the supervisor of `prefix` has written its session file and
/// answers `status` with the `attached` I/O processes attached; fails when
/// `sup` ended first, a stop was requested, or `timeout` passed.
pub fn wait_ready(
    motionctl: &Path,
    prefix: &str,
    sup: &mut Running,
    attached: Attached,
    timeout: Duration,
) -> Result<StatusReport, String> {
    let until = Instant::now() + timeout;
    loop {
        if !sup.running() {
            return Err("the supervisor ended before it was ready".into());
        }
        if process::stop_requested() {
            return Err("interrupted".into());
        }
        if motion_ipc::Domain::join(prefix, None).is_ok() {
            if let Some(s) = status(motionctl, prefix).filter(|s| attached.in_(s)) {
                return Ok(s);
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

/// What the daemon logs when its cycle monitor stops an axis.
pub const MONITOR_TRIPPED: &str = "the cycle monitor tripped";

/// A test's daemon: `motion-supervisor run --config CFG`, stopped with
/// SIGTERM when dropped (a failed test leaves no daemon behind). Its end
/// (stop or drop) fails the test if the cycle monitor stopped an axis —
/// it never trips in normal operation — unless the test expects it
/// ([`Daemon::allow_monitor_trips`]).
pub struct Daemon {
    running: Option<Running>,
    pub prefix: String,
    motionctl: PathBuf,
    monitor_trips_allowed: bool,
}

impl Daemon {
    /// Starts the daemon of `cfg` without waiting for it.
    pub fn spawn(cfg: &TempConfig) -> Daemon {
        Daemon {
            running: Some(spawn_supervisor(&["run", "--config", cfg.arg()])),
            prefix: cfg.prefix.clone(),
            motionctl: test_bin("motionctl"),
            monitor_trips_allowed: false,
        }
    }

    /// The test provokes what the cycle monitor must stop: its trips do
    /// not fail the test.
    pub fn allow_monitor_trips(&mut self) {
        self.monitor_trips_allowed = true;
    }

    /// Starts the daemon and waits (20 s at most) until it answers with the
    /// I/O processes `attached` attached.
    #[track_caller]
    pub fn start(cfg: &TempConfig, attached: &[&str]) -> Daemon {
        let mut d = Daemon::spawn(cfg);
        d.wait_ready(Attached::These(attached));
        d
    }

    /// Waits (20 s at most) until the daemon is ready; panics with its
    /// stderr otherwise.
    #[track_caller]
    pub fn wait_ready(&mut self, attached: Attached) -> StatusReport {
        let running = self.running.as_mut().expect("running");
        wait_ready(
            &self.motionctl,
            &self.prefix,
            running,
            attached,
            Duration::from_secs(20),
        )
        .unwrap_or_else(|e| panic!("daemon not ready: {e}\n{}", running.stderr()))
    }

    /// The status report (the daemon must answer).
    #[track_caller]
    pub fn status(&self) -> StatusReport {
        let r = self.ctl(&["status", "--json"]);
        r.expect_code(0).report()
    }

    /// One axis of the status report.
    #[track_caller]
    pub fn axis(&self, name: &str) -> AxisStatus {
        named(&self.status().axes, name).clone()
    }

    /// `motionctl --service-prefix P <args>` against this daemon.
    pub fn ctl(&self, args: &[&str]) -> Ended {
        ctl(&self.prefix, args)
    }

    /// Waits (at most `secs`) until axis `name`'s status satisfies `f`; that
    /// status. Fails the test with the last status seen otherwise: states
    /// are awaited, never a wall-clock moment.
    #[track_caller]
    pub fn wait_axis(&self, name: &str, secs: u64, f: impl Fn(&AxisStatus) -> bool) -> AxisStatus {
        let mut last = AxisStatus::default();
        let ok = crate::wait_for(std::time::Duration::from_secs(secs), || {
            last = self.axis(name);
            f(&last)
        });
        assert!(ok, "{name} never got there: {last:#?}");
        last
    }

    /// `motionctl ARGS --json` against this daemon refused (exit 1) with
    /// ERR `err` / EXERR `exerr` among its errors.
    #[track_caller]
    pub fn refused_with(&self, args: &[&str], err: u16, exerr: u16) {
        let mut all = args.to_vec();
        all.push("--json");
        let r = self.ctl(&all);
        let e: ErrorReport = r.expect_code(1).report();
        assert!(
            e.errors
                .iter()
                .any(|x| x.err == Some(err) && x.exerr == Some(exerr)),
            "{args:?}: expected ERR {err} EXERR {exerr}: {}",
            r.stdout
        );
    }

    /// Its process id.
    pub fn pid(&self) -> u32 {
        self.running.as_ref().map_or(0, Running::pid)
    }

    /// Its stderr so far (and its spawned `motion-io`'s, which shares it).
    pub fn stderr(&self) -> String {
        self.running
            .as_ref()
            .map(Running::stderr)
            .unwrap_or_default()
    }

    /// Waits for a stderr line containing `needle`.
    pub fn wait_line(&self, needle: &str, timeout: Duration) -> bool {
        self.running
            .as_ref()
            .is_some_and(|r| r.wait_line(needle, timeout).is_some())
    }

    /// SIGTERM and the daemon's exit (external I/O processes may still hold
    /// the domain: check it with `assert_clean` once they are gone too).
    #[track_caller]
    pub fn stop(mut self) -> Ended {
        let ended = self.running.take().expect("running").stop();
        no_trip(self.monitor_trips_allowed, &ended.stderr);
        ended
    }
}

/// Panics when the daemon's log shows a trip of its cycle monitor and none
/// was allowed.
#[track_caller]
fn no_trip(allowed: bool, stderr: &str) {
    if let Some(line) = stderr.lines().find(|l| l.contains(MONITOR_TRIPPED)) {
        assert!(
            allowed,
            "the cycle monitor tripped in this test: {line}\n{stderr}"
        );
    }
}

impl Drop for Daemon {
    fn drop(&mut self) {
        if let Some(r) = self.running.take() {
            let ended = r.stop();
            if !std::thread::panicking() {
                no_trip(self.monitor_trips_allowed, &ended.stderr);
            }
        }
    }
}
