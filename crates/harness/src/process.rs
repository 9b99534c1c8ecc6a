//! Child processes of the tests and the benches, with one set of rules for
//! all of them: stdin closed, stdout captured whole, stderr read line by
//! line as it comes (each line stamped with the instant it was read, so a
//! test can time a message), bounded waits, signals to the child or its
//! process group, and a guaranteed end — SIGTERM, a grace period, SIGKILL,
//! reaped — also when the handle is dropped, so a failed test or an
//! interrupted bench leaves no process behind.
//!
//! A process that installed `motion-rt`'s termination handler (a bench:
//! one handler for every binary of the workspace) has its SIGINT/SIGTERM
//! recorded; [`Running::wait`] sees it and ends the child.

use std::io::{BufRead, BufReader, Read};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use nix::sys::signal::Signal;
use nix::unistd::Pid;

/// A SIGINT or SIGTERM arrived (seen only where `motion-rt`'s termination
/// handler is installed).
pub fn stop_requested() -> bool {
    motion_rt::termination::received().is_some()
}

/// The last `n` lines of `s` (a child's output), joined with " | ".
pub fn tail(s: &str, n: usize) -> String {
    let lines: Vec<&str> = s.trim().lines().collect();
    lines[lines.len().saturating_sub(n)..].join(" | ")
}

/// How a child ended, with everything it printed.
#[derive(Debug)]
pub struct Ended {
    pub status: Option<ExitStatus>,
    pub stdout: String,
    pub stderr: String,
    pub timed_out: bool,
    pub interrupted: bool,
}

impl Ended {
    pub fn success(&self) -> bool {
        !self.timed_out && self.status.is_some_and(|s| s.success())
    }

    /// The exit code (`None`: killed by a signal, or never ended).
    pub fn code(&self) -> Option<i32> {
        self.status.and_then(|s| s.code())
    }

    /// Asserts the exit code, showing both outputs when it differs.
    #[track_caller]
    pub fn expect_code(&self, code: i32) -> &Self {
        assert_eq!(
            self.code(),
            Some(code),
            "{}\nstdout:\n{}\nstderr:\n{}",
            self.describe(),
            self.stdout,
            self.stderr
        );
        self
    }

    /// Stdout as one JSON object of type `T` (`--json` output); panics with
    /// both outputs when it is not.
    #[track_caller]
    pub fn report<T: serde::de::DeserializeOwned>(&self) -> T {
        serde_json::from_str(self.stdout.trim()).unwrap_or_else(|e| {
            panic!(
                "stdout is not a {} ({e}):\n{}\nstderr:\n{}",
                std::any::type_name::<T>(),
                self.stdout,
                self.stderr
            )
        })
    }

    /// Stdout as untyped JSON: for the tests that check the wire format
    /// itself (which keys are there), not for reading values.
    #[track_caller]
    pub fn json(&self) -> serde_json::Value {
        self.report()
    }

    /// "exit code 1", "killed by signal 9", "timed out", ...
    pub fn describe(&self) -> String {
        let mut s = match self.status {
            Some(st) => match (st.code(), st.signal()) {
                (Some(c), _) => format!("exit code {c}"),
                (None, Some(sig)) => format!("killed by signal {sig}"),
                _ => "ended".into(),
            },
            None => "did not end".into(),
        };
        if self.timed_out {
            s += " (timed out, terminated)";
        }
        if self.interrupted {
            s += " (interrupted)";
        }
        s
    }
}

/// Stderr lines as they arrive, with the instant each was read.
#[derive(Default)]
struct Lines {
    lines: Mutex<Vec<(Instant, String)>>,
    arrived: Condvar,
}

impl Lines {
    fn get(&self) -> std::sync::MutexGuard<'_, Vec<(Instant, String)>> {
        self.lines.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A running child. Dropping it ends it (SIGTERM, 3 s, SIGKILL) and reaps it.
pub struct Running {
    child: Option<Child>,
    /// The child leads its own process group; signals go to the group.
    group: bool,
    stdout: Option<JoinHandle<String>>,
    stderr: Arc<Lines>,
    stderr_reader: Option<JoinHandle<()>>,
    status: Option<ExitStatus>,
    pub label: String,
}

fn read_all<R: Read + Send + 'static>(mut r: R) -> Option<JoinHandle<String>> {
    std::thread::Builder::new()
        .name("harness-stdout".into())
        .spawn(move || {
            let mut buf = Vec::new();
            let _ = r.read_to_end(&mut buf);
            String::from_utf8_lossy(&buf).into_owned()
        })
        .ok()
}

/// Reads to the end (every holder of the pipe gone), line by line; bytes
/// that are not UTF-8 are replaced, never a reason to stop reading.
fn read_lines<R: Read + Send + 'static>(r: R, sink: Arc<Lines>) -> Option<JoinHandle<()>> {
    std::thread::Builder::new()
        .name("harness-stderr".into())
        .spawn(move || {
            let mut r = BufReader::new(r);
            let mut buf = Vec::new();
            while matches!(r.read_until(b'\n', &mut buf), Ok(n) if n > 0) {
                let line = String::from_utf8_lossy(&buf);
                let line = line.strip_suffix('\n').unwrap_or(&line).to_string();
                sink.get().push((Instant::now(), line));
                sink.arrived.notify_all();
                buf.clear();
            }
        })
        .ok()
}

impl Running {
    /// Spawns `cmd` with stdout and stderr captured (`capture`) or inherited.
    /// `group`: in a process group of its own (not reached by the
    /// terminal's Ctrl-C; signalled as a group).
    pub fn spawn(
        cmd: &mut Command,
        label: &str,
        capture: bool,
        group: bool,
    ) -> Result<Self, String> {
        cmd.stdin(Stdio::null());
        if capture {
            cmd.stdout(Stdio::piped()).stderr(Stdio::piped());
        }
        if group {
            cmd.process_group(0);
        }
        let mut child = cmd
            .spawn()
            .map_err(|e| format!("cannot start {label} ({:?}): {e}", cmd.get_program()))?;
        let stderr = Arc::new(Lines::default());
        let stdout = child.stdout.take().and_then(read_all);
        let stderr_reader = child
            .stderr
            .take()
            .and_then(|e| read_lines(e, stderr.clone()));
        Ok(Self {
            child: Some(child),
            group,
            stdout,
            stderr,
            stderr_reader,
            status: None,
            label: label.to_string(),
        })
    }

    /// Spawns `cmd` captured, in the caller's process group; panics if it
    /// cannot (a test's binaries are built).
    #[track_caller]
    pub fn start(cmd: &mut Command, label: &str) -> Self {
        Self::spawn(cmd, label, true, false).unwrap_or_else(|e| panic!("{e}"))
    }

    /// The child's pid (0 once it was reaped).
    pub fn pid(&self) -> u32 {
        self.child.as_ref().map_or(0, |c| c.id())
    }

    /// Sends `sig` to the child (or its group) without waiting; nothing
    /// once it was reaped (its pid may belong to another process by then).
    pub fn signal(&self, sig: Signal) {
        if self.status.is_none() {
            self.signal_group_or_child(sig);
        }
    }

    fn signal_group_or_child(&self, sig: Signal) {
        if let Some(c) = &self.child {
            let pid = c.id() as i32;
            let _ = nix::sys::signal::kill(Pid::from_raw(if self.group { -pid } else { pid }), sig);
        }
    }

    /// Still running?
    pub fn running(&mut self) -> bool {
        self.child
            .as_mut()
            .is_some_and(|c| matches!(c.try_wait(), Ok(None)))
    }

    /// Every stderr line so far, with the instant it was read.
    pub fn lines(&self) -> Vec<(Instant, String)> {
        self.stderr.get().clone()
    }

    /// Stderr so far, one string.
    pub fn stderr(&self) -> String {
        let lines = self.stderr.get();
        let mut s = String::new();
        for (_, l) in lines.iter() {
            s += l;
            s.push('\n');
        }
        s
    }

    /// Index of the first stderr line so far that contains `needle`.
    pub fn find(&self, needle: &str) -> Option<usize> {
        self.stderr
            .get()
            .iter()
            .position(|(_, l)| l.contains(needle))
    }

    /// Stderr lines so far that contain `needle`.
    pub fn count(&self, needle: &str) -> usize {
        self.stderr
            .get()
            .iter()
            .filter(|(_, l)| l.contains(needle))
            .count()
    }

    /// Waits up to `timeout` for a stderr line containing `needle`; returns
    /// it with the instant it was read.
    pub fn wait_line(&self, needle: &str, timeout: Duration) -> Option<(Instant, String)> {
        let until = Instant::now() + timeout;
        let mut lines = self.stderr.get();
        loop {
            if let Some(l) = lines.iter().find(|(_, l)| l.contains(needle)) {
                return Some(l.clone());
            }
            let left = until.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return None;
            }
            lines = self
                .stderr
                .arrived
                .wait_timeout(lines, left)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }

    /// Waits up to `timeout` for the child to exit, without ending it; once
    /// it exited, also for its stderr to reach its end (every process that
    /// shares the pipe gone). `None`: still running.
    pub fn wait_exit(&mut self, timeout: Duration) -> Option<ExitStatus> {
        let status = self.reap(timeout)?;
        self.drain_stderr();
        Some(status)
    }

    /// Reaps the child if it exits within `timeout` (stderr not waited for).
    fn reap(&mut self, timeout: Duration) -> Option<ExitStatus> {
        let until = Instant::now() + timeout;
        loop {
            if self.status.is_some() {
                return self.status;
            }
            match self.child.as_mut()?.try_wait() {
                Ok(Some(s)) => {
                    self.status = Some(s);
                    return Some(s);
                }
                Ok(None) => {}
                Err(_) => {
                    self.child = None;
                    return None;
                }
            }
            if Instant::now() >= until {
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    fn drain_stderr(&mut self) {
        if let Some(r) = self.stderr_reader.take() {
            let _ = r.join();
        }
    }

    /// Waits up to `timeout`; on timeout or a stop request ends the child
    /// (SIGTERM, `grace`, SIGKILL). Output is collected to the end.
    pub fn wait(mut self, timeout: Duration, grace: Duration) -> Ended {
        let until = Instant::now() + timeout;
        let (mut timed_out, mut interrupted) = (false, false);
        while self.wait_exit(Duration::from_millis(50)).is_none() && self.child.is_some() {
            if stop_requested() {
                interrupted = true;
            } else if Instant::now() > until {
                timed_out = true;
            } else {
                continue;
            }
            self.terminate(grace);
            break;
        }
        self.ended(timed_out, interrupted)
    }

    /// Waits for the child to end on its own, however long it takes.
    pub fn finish(mut self) -> Ended {
        while self.wait_exit(Duration::from_secs(3600)).is_none() && self.child.is_some() {}
        self.ended(false, false)
    }

    /// SIGTERM, then [`finish`](Self::finish).
    pub fn stop(self) -> Ended {
        self.signal(Signal::SIGTERM);
        self.finish()
    }

    /// SIGTERM, up to `grace` for it to end, then SIGKILL; reaps the child
    /// (without waiting for others that still hold its stderr).
    pub fn terminate(&mut self, grace: Duration) -> Option<ExitStatus> {
        if self.status.is_some() || self.child.is_none() {
            return self.status;
        }
        if let Some(s) = self.reap(Duration::ZERO) {
            return Some(s);
        }
        self.signal(Signal::SIGTERM);
        if let Some(s) = self.reap(grace) {
            if self.group {
                // stragglers of the group (e.g. stress-ng workers)
                self.signal_group_or_child(Signal::SIGKILL);
            }
            return Some(s);
        }
        self.kill()
    }

    /// SIGKILL (to the group, if it has one) and reap.
    pub fn kill(&mut self) -> Option<ExitStatus> {
        self.signal(Signal::SIGKILL);
        let s = self.child.as_mut()?.wait().ok();
        self.status = self.status.or(s);
        s
    }

    /// Everything it printed, to the end of its pipes.
    fn ended(mut self, timed_out: bool, interrupted: bool) -> Ended {
        self.drain_stderr();
        self.child = None;
        let stdout = self
            .stdout
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        Ended {
            status: self.status,
            stdout,
            stderr: self.stderr(),
            timed_out,
            interrupted,
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        if self.child.is_some() {
            let _ = self.terminate(Duration::from_secs(3));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sh(script: &str) -> Running {
        Running::start(Command::new("sh").args(["-c", script]), "sh")
    }

    #[test]
    fn output_lines_and_exit_code_are_collected() {
        let r = sh("echo out; echo one >&2; printf 'two\\377' >&2; exit 3");
        assert!(r.wait_line("one", Duration::from_secs(5)).is_some());
        let e = r.finish();
        assert_eq!((e.code(), e.stdout.as_str()), (Some(3), "out\n"));
        assert_eq!(e.stderr, "one\ntwo\u{fffd}\n");
        assert_eq!(e.describe(), "exit code 3");
    }

    #[test]
    fn a_child_past_its_time_is_ended_and_so_is_a_dropped_one() {
        let e = sh("exec sleep 30").wait(Duration::from_millis(100), Duration::from_secs(1));
        assert!(
            e.timed_out && e.status.and_then(|s| s.signal()) == Some(15),
            "{e:?}"
        );
        // deaf to SIGTERM, and its own child holds the pipes for 8 s
        let r = sh("trap '' TERM; echo deaf >&2; sleep 8; true");
        assert!(r.wait_line("deaf", Duration::from_secs(5)).is_some());
        let (pid, t0) = (Pid::from_raw(r.pid() as i32), Instant::now());
        drop(r);
        let took = t0.elapsed();
        assert!(
            took >= Duration::from_secs(3) && took < Duration::from_secs(6),
            "{took:?}"
        );
        // reaped: the pid is gone (or, at worst, reused by someone else)
        assert!(nix::sys::signal::kill(pid, None).is_err());
    }

    #[test]
    fn wait_exit_leaves_a_running_child_alone() {
        let mut r = sh("exec sleep 30");
        assert!(r.wait_exit(Duration::from_millis(50)).is_none());
        assert!(r.running());
        assert_eq!(r.kill().and_then(|s| s.signal()), Some(9));
    }
}
