//! The `motion-io` processes the supervisor spawns (`spawn = "sim"`), one
//! per such I/O process of the config.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

pub struct IoChild {
    /// The I/O process's name (`--io NAME`).
    pub name: String,
    child: Child,
    started: Instant,
    exit: Option<ExitStatus>,
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

impl IoChild {
    /// Starts `motion-io --backend BACKEND --io NAME` on the same config, service
    /// prefix and runtime directory; it joins the supervisor's domain through
    /// the session file. Its stdout is discarded (ours may carry JSON); its
    /// stderr is shared.
    pub fn spawn(
        name: &str,
        backend: &str,
        config: Option<&Path>,
        service_prefix: &str,
        runtime_dir: &Path,
        extra: &[String],
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
            .stderr(Stdio::inherit());
        if let Some(c) = config {
            cmd.arg("--config").arg(c);
        }
        let child = cmd
            .spawn()
            .map_err(|e| format!("cannot start I/O process {name} ({}): {e}", bin.display()))?;
        Ok(Self {
            name: name.to_string(),
            child,
            started: Instant::now(),
            exit: None,
        })
    }

    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// The exit status once the process has ended.
    pub fn exited(&mut self) -> Option<ExitStatus> {
        if self.exit.is_none() {
            self.exit = self.child.try_wait().ok().flatten();
        }
        self.exit
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
    }
}
