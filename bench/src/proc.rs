//! Child processes with captured output, bounded waits and a guaranteed end;
//! SIGINT/SIGTERM turned into a flag so that children are always cleaned up.

use std::io::Read;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// SIGINT and SIGTERM set a flag: `motion_rt::termination`'s handler, the
/// one every binary of the workspace installs (blocking calls resume; the
/// waits here poll the flag).
pub fn install_stop_handler() {
    if let Err(e) = motion_rt::termination::install() {
        eprintln!("warning: {e}");
    }
}

/// A SIGINT or SIGTERM arrived.
pub fn stop_requested() -> bool {
    motion_rt::termination::received().is_some()
}

/// The signal that set the flag (0: none).
pub fn stop_signal() -> i32 {
    motion_rt::termination::received().unwrap_or(0)
}

/// How a child ended.
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

/// A running child. Dropping it terminates it (SIGTERM, then SIGKILL) and
/// reaps it.
pub struct Running {
    child: Option<Child>,
    /// The child leads its own process group; signals go to the group.
    group: bool,
    out: Option<JoinHandle<String>>,
    err: Option<JoinHandle<String>>,
    pub label: String,
}

fn reader<R: Read + Send + 'static>(r: Option<R>) -> Option<JoinHandle<String>> {
    let mut r = r?;
    std::thread::Builder::new()
        .name("bench-pipe".into())
        .spawn(move || {
            let mut buf = Vec::new();
            let _ = r.read_to_end(&mut buf);
            String::from_utf8_lossy(&buf).into_owned()
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
        let out = reader(child.stdout.take());
        let err = reader(child.stderr.take());
        Ok(Self {
            child: Some(child),
            group,
            out,
            err,
            label: label.to_string(),
        })
    }

    pub fn pid(&self) -> u32 {
        self.child.as_ref().map_or(0, |c| c.id())
    }

    fn signal(&self, sig: i32) {
        if let Some(c) = &self.child {
            let pid = c.id() as i32;
            // SAFETY: plain kill(2) on our own child (or its group).
            unsafe {
                libc::kill(if self.group { -pid } else { pid }, sig);
            }
        }
    }

    /// Sends `sig` to the child (or its group) without waiting.
    pub fn send_signal(&self, sig: i32) {
        self.signal(sig);
    }

    /// Still running?
    pub fn running(&mut self) -> bool {
        self.child
            .as_mut()
            .is_some_and(|c| matches!(c.try_wait(), Ok(None)))
    }

    /// Waits up to `timeout`; on timeout or a stop request, terminates the
    /// child (SIGTERM, `grace`, SIGKILL). Output is collected to the end.
    pub fn wait(mut self, timeout: Duration, grace: Duration) -> Ended {
        let until = Instant::now() + timeout;
        let mut timed_out = false;
        let mut interrupted = false;
        let mut status = None;
        while let Some(c) = self.child.as_mut() {
            match c.try_wait() {
                Ok(Some(s)) => {
                    status = Some(s);
                    break;
                }
                Ok(None) => {}
                Err(_) => break,
            }
            if stop_requested() && !interrupted {
                interrupted = true;
                status = self.terminate(grace);
                break;
            }
            if Instant::now() > until {
                timed_out = true;
                status = self.terminate(grace);
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        self.child = None;
        let stdout = self
            .out
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        let stderr = self
            .err
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        Ended {
            status,
            stdout,
            stderr,
            timed_out,
            interrupted,
        }
    }

    /// SIGTERM, up to `grace` for it to end, then SIGKILL; reaps the child.
    pub fn terminate(&mut self, grace: Duration) -> Option<ExitStatus> {
        let c = self.child.as_mut()?;
        if let Ok(Some(s)) = c.try_wait() {
            return Some(s);
        }
        self.signal(libc::SIGTERM);
        let until = Instant::now() + grace;
        while Instant::now() < until {
            if let Ok(Some(s)) = self.child.as_mut()?.try_wait() {
                if self.group {
                    // stragglers of the group (e.g. stress-ng workers)
                    self.signal(libc::SIGKILL);
                }
                return Some(s);
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        self.signal(libc::SIGKILL);
        self.child.as_mut()?.wait().ok()
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        if self.child.is_some() {
            let _ = self.terminate(Duration::from_secs(3));
        }
    }
}
