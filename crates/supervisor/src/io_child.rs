//! The `motion-io` processes the supervisor spawns (`spawn = "sim"` /
//! `"supervisor"`), one per such I/O process of the config, and how one
//! that ends is started again.
//!
//! * **Back-off.** One that fails at start-up (ran less than
//!   [`Backoff::STABLE`]) is started again after 1 s, then 2, 4, 8, 16 and
//!   30 s at most ([`Backoff`]); one that ran longer gets 1 s again.
//! * **Its output.** Its stderr goes through the supervisor (a reader thread
//!   per child): every line is shown once — a process that fails the same
//!   way again does not print the same lines again (the set is forgotten
//!   after a run that lasted) — and the error it ended with (`error: …` and
//!   what follows) is kept for the status ([`IoChild::start_error`]). It
//!   also inherits a copy of our stderr (`motion_rt::logging::FALLBACK_FD_ENV`)
//!   and writes there directly once it has joined us
//!   (`motion_rt::logging::direct_stderr`): when we are killed, its
//!   watchdog's "stopping every axis" still reaches the journal.
//! * **The status.** Per I/O process, the restarts, the time to the next
//!   start and the last start-up error ([`SpawnNote`]) go into the I/O rows
//!   of the status frame ([`note_spawns`]).

use std::collections::HashSet;
use std::io::{BufRead, BufReader};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use motion_control::{put_str, StatusFrame, MAX_IOS};

/// Lines a spawned I/O process wrote that were shown already (shared by its
/// successive runs).
pub type Seen = Arc<Mutex<HashSet<String>>>;

pub struct IoChild {
    /// The I/O process's name (`--io NAME`).
    pub name: String,
    child: Child,
    started: Instant,
    exit: Option<ExitStatus>,
    /// The error its output ended with, if any.
    error: Arc<Mutex<Option<String>>>,
    reader: Option<JoinHandle<()>>,
}

/// `$MOTION_IO_BIN`, else `motion-io` next to this executable, else on `PATH`.
pub fn io_binary() -> PathBuf {
    if let Some(p) = std::env::var_os("MOTION_IO_BIN") {
        return PathBuf::from(p);
    }
    if let Ok(exe) = std::env::current_exe() {
        let sibling = exe.with_file_name("motion-io");
        if sibling.exists() {
            return sibling;
        }
    }
    PathBuf::from("motion-io")
}

/// The delay before a spawned I/O process that ended is started again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Backoff {
    next: Duration,
}

impl Default for Backoff {
    fn default() -> Self {
        Backoff {
            next: Backoff::FIRST,
        }
    }
}

impl Backoff {
    pub const FIRST: Duration = Duration::from_secs(1);
    pub const MAX: Duration = Duration::from_secs(30);
    /// A process that ran this long did start: its next failure is a new
    /// story (1 s again).
    pub const STABLE: Duration = Duration::from_secs(10);

    /// The process ended after running `ran`: how long until it is started
    /// again.
    pub fn ended(&mut self, ran: Duration) -> Duration {
        if ran >= Backoff::STABLE {
            self.next = Backoff::FIRST;
        }
        let d = self.next;
        self.next = (self.next * 2).min(Backoff::MAX);
        d
    }
}

/// What the status shows of a spawned I/O process.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpawnNote {
    pub restarts: u32,
    /// When it is started again (`None`: it runs).
    pub retry_at: Option<Instant>,
    /// The error of its last failed start.
    pub start_error: Option<String>,
}

/// Writes the spawned I/O processes' notes (by I/O process index) into the
/// I/O rows of `f`.
pub fn note_spawns(notes: &[SpawnNote], f: &mut StatusFrame) {
    let now = Instant::now();
    for (n, e) in notes.iter().zip(f.ios.iter_mut()).take(MAX_IOS) {
        e.spawn_restarts = n.restarts;
        e.spawn_retry_s = n.retry_at.map_or(0.0, |t| {
            t.saturating_duration_since(now).as_secs_f32().max(0.05)
        });
        let first = n.start_error.as_deref().and_then(|e| e.lines().next());
        put_str(&mut e.start_error, first.unwrap_or(""));
    }
}

/// Reads a child's stderr until it ends: shows each line not seen before,
/// keeps the error it ends with (from its `error: ` line on).
fn read_output(from: impl std::io::Read, seen: Seen, error: Arc<Mutex<Option<String>>>) {
    let mut collecting = false;
    for line in BufReader::new(from).lines().map_while(Result::ok) {
        if seen
            .lock()
            .map(|mut s| s.insert(line.clone()))
            .unwrap_or(true)
        {
            eprintln!("{line}");
        }
        let mut e = error.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(at) = line.find("error: ") {
            *e = Some(line[at + "error: ".len()..].to_string());
            collecting = true;
        } else if collecting && !line.starts_with("motion-io") {
            // a message of several lines
            if let Some(t) = e.as_mut() {
                t.push('\n');
                t.push_str(line.trim_end());
            }
        } else {
            collecting = false;
        }
    }
}

impl IoChild {
    /// Starts `motion-io --backend BACKEND --io NAME` on the same config, service
    /// prefix and runtime directory; it joins the supervisor's domain through
    /// the session file. Its stdout is discarded (ours may carry JSON); its
    /// stderr comes through ours, each line once (`seen`).
    pub fn spawn(
        name: &str,
        backend: &str,
        config: Option<&Path>,
        service_prefix: &str,
        runtime_dir: &Path,
        extra: &[String],
        seen: Seen,
    ) -> Result<Self, String> {
        let bin = io_binary();
        let mut cmd = Command::new(&bin);
        cmd.arg("--backend")
            .arg(backend)
            .arg("--io")
            .arg(name)
            .arg("--service-prefix")
            .arg(service_prefix)
            .arg("--runtime-dir")
            .arg(runtime_dir)
            .arg("--exit-with-supervisor")
            .arg("--quiet")
            .args(extra)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        if let Some(c) = config {
            cmd.arg("--config").arg(c);
        }
        // Our stderr, for its logger once the pipe has no reader (we died):
        // a copy above the standard descriptors, inherited by this child only.
        // SAFETY: F_DUPFD_CLOEXEC duplicates a descriptor we own.
        let keep = unsafe { libc::fcntl(2, libc::F_DUPFD_CLOEXEC, 10) };
        if keep >= 0 {
            cmd.env(motion_rt::logging::FALLBACK_FD_ENV, keep.to_string());
            // SAFETY: between fork and exec, only fcntl (async-signal-safe):
            // the copy loses close-on-exec in the child alone.
            unsafe {
                cmd.pre_exec(move || {
                    if libc::fcntl(keep, libc::F_SETFD, 0) < 0 {
                        return Err(std::io::Error::last_os_error());
                    }
                    Ok(())
                });
            }
        }
        let spawned = cmd.spawn();
        if keep >= 0 {
            // SAFETY: our copy, no longer needed once the child has its own.
            unsafe { libc::close(keep) };
        }
        let mut child = spawned
            .map_err(|e| format!("cannot start I/O process {name} ({}): {e}", bin.display()))?;
        let error = Arc::new(Mutex::new(None));
        let reader = child.stderr.take().and_then(|out| {
            let error = error.clone();
            std::thread::Builder::new()
                .name(format!("io-{name}-stderr"))
                .spawn(move || read_output(out, seen, error))
                .ok()
        });
        Ok(Self {
            name: name.to_string(),
            child,
            started: Instant::now(),
            exit: None,
            error,
            reader,
        })
    }

    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// How long it has run (until now, or until it was seen ended).
    pub fn ran(&self) -> Duration {
        self.started.elapsed()
    }

    /// The exit status once the process has ended.
    pub fn exited(&mut self) -> Option<ExitStatus> {
        if self.exit.is_none() {
            self.exit = self.child.try_wait().ok().flatten();
            if self.exit.is_some() {
                // its last lines are read before anyone asks for them
                if let Some(r) = self.reader.take() {
                    let _ = r.join();
                }
            }
        }
        self.exit
    }

    /// The error its output ended with (once it has ended).
    pub fn start_error(&self) -> Option<String> {
        self.error.lock().ok().and_then(|e| e.clone())
    }

    /// CPU time used so far, as a share of one CPU since start (0..1 per core).
    pub fn cpu_share(&mut self) -> Option<f64> {
        if self.exited().is_some() {
            return None;
        }
        let secs = crate::cpu::process_cpu_seconds(self.pid())?;
        Some(secs / self.started.elapsed().as_secs_f64())
    }

    /// SIGTERM, then SIGKILL after `grace`. Returns the exit status.
    pub fn terminate(&mut self, grace: Duration) -> Option<ExitStatus> {
        if let Some(s) = self.exited() {
            return Some(s);
        }
        let pid = nix::unistd::Pid::from_raw(self.child.id() as i32);
        let _ = nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGTERM);
        let until = Instant::now() + grace;
        while Instant::now() < until {
            if let Some(s) = self.exited() {
                return Some(s);
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = self.child.kill();
        self.exit = self.child.wait().ok();
        self.exit
    }
}

impl Drop for IoChild {
    fn drop(&mut self) {
        if self.exited().is_none() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failing_starts_back_off_from_1_s_doubling_to_30_s() {
        let mut b = Backoff::default();
        let quick = Duration::from_millis(200);
        let delays: Vec<u64> = (0..7).map(|_| b.ended(quick).as_secs()).collect();
        assert_eq!(delays, [1, 2, 4, 8, 16, 30, 30]);
        // a run that lasted: 1 s again
        assert_eq!(b.ended(Backoff::STABLE).as_secs(), 1);
        assert_eq!(b.ended(quick).as_secs(), 2);
    }

    #[test]
    fn output_is_shown_once_and_the_error_kept_whole() {
        let seen: Seen = Arc::default();
        let error = Arc::new(Mutex::new(None));
        let out = "motion-io: EtherCAT: starting the bus on veth0\n\
                   motion-io: error: EtherCAT start-up on veth0 failed: 1 of 1 drive(s) cannot \
                   run their axes\n  SubDevice 0 (EMU): 1 problem(s)\n    missing 0x60B8\n";
        read_output(out.as_bytes(), seen.clone(), error.clone());
        let e = error.lock().unwrap().clone().unwrap();
        assert_eq!(
            e,
            "EtherCAT start-up on veth0 failed: 1 of 1 drive(s) cannot run their axes\n  \
             SubDevice 0 (EMU): 1 problem(s)\n    missing 0x60B8"
        );
        assert_eq!(seen.lock().unwrap().len(), 4);
        // a second run with the same lines adds nothing
        read_output(out.as_bytes(), seen.clone(), error);
        assert_eq!(seen.lock().unwrap().len(), 4);
        // the status gets its first line
        let mut f = StatusFrame::zeroed();
        note_spawns(
            &[SpawnNote {
                restarts: 3,
                retry_at: Some(Instant::now() + Duration::from_secs(4)),
                start_error: Some(e),
            }],
            &mut f,
        );
        let r = f.ios[0];
        assert_eq!(r.spawn_restarts, 3);
        assert!(
            (3.5..=4.0).contains(&r.spawn_retry_s),
            "{}",
            r.spawn_retry_s
        );
        assert!(motion_control::get_str(&r.start_error).starts_with("EtherCAT start-up on veth0"));
    }
}
