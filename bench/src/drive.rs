//! A bench's daemon: `motion-supervisor run` of a machine the bench wrote,
//! started from the bench's [`Binaries`], ready when the harness's
//! [`wait_ready`] says so (every I/O process attached), stopped with
//! SIGTERM and its output collected; and what its prefix left in
//! `/dev/shm`, cleaned and reported.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

pub use motion_harness::daemon::status;
use motion_harness::daemon::{wait_ready, Attached};
use motion_harness::leftovers::leftovers;
use motion_harness::process::{tail, Ended, Running};
use motion_ipc::{cleanup_stale_domains, default_runtime_dir};
use nix::sys::signal::Signal;

use crate::bins::Binaries;

/// [`wait_ready`] with every I/O process attached.
pub fn wait_until_ready(
    motionctl: &Path,
    prefix: &str,
    sup: &mut Running,
    timeout: Duration,
) -> Result<(), String> {
    wait_ready(motionctl, prefix, sup, Attached::All, timeout).map(|_| ())
}

/// `motion-supervisor run --config CFG --json --service-prefix P`: a
/// bench's daemon, to which it adds what it measures (`--duration`,
/// `--hlog`, ...).
pub fn run_command(b: &Binaries, cfg: &Path, prefix: &str) -> Command {
    let mut cmd = Command::new(&b.supervisor);
    cmd.arg("run").arg("--config").arg(cfg);
    cmd.args(["--json", "--service-prefix", prefix]);
    cmd
}

/// [`run_command`] started and ready within `timeout` (every I/O process
/// attached); else stopped, and the error says how it ended with the end of
/// its stderr.
pub fn start_run(
    b: &Binaries,
    cfg: &Path,
    prefix: &str,
    timeout: Duration,
) -> Result<Running, String> {
    let mut run = Running::spawn(
        &mut run_command(b, cfg, prefix),
        "motion-supervisor run",
        true,
        false,
    )?;
    match wait_until_ready(&b.motionctl, prefix, &mut run, timeout) {
        Ok(()) => Ok(run),
        Err(e) => {
            let ended = stop_run(run, Duration::from_secs(20));
            let tail = tail(&ended.stderr, 5);
            Err(format!("{e} ({}; {tail})", ended.describe()))
        }
    }
}

/// The machine `toml` written as `dir/PREFIX.toml`; its path.
pub fn write_config(dir: &Path, prefix: &str, toml: &str) -> Result<PathBuf, String> {
    let cfg = dir.join(format!("{prefix}.toml"));
    std::fs::write(&cfg, toml).map_err(|e| format!("{}: {e}", cfg.display()))?;
    Ok(cfg)
}

/// The machine `toml` written to `dir` ([`write_config`]) and [`start_run`]
/// of it under `prefix` (ready within 20 s); an error names the prefix.
pub fn start_machine(
    b: &Binaries,
    dir: &Path,
    prefix: &str,
    toml: &str,
) -> Result<Running, String> {
    let cfg = write_config(dir, prefix, toml)?;
    start_run(b, &cfg, prefix, Duration::from_secs(20)).map_err(|e| format!("{prefix}: {e}"))
}

/// Asks a running supervisor to stop (SIGTERM) and collects its output.
pub fn stop_run(r: Running, timeout: Duration) -> Ended {
    r.signal(Signal::SIGTERM);
    r.wait(timeout, Duration::from_secs(5))
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
    cleanup_stale_domains(prefix, &default_runtime_dir());
    (found, leftovers(prefix))
}
