//! Finding the programs the bench runs: motion-supervisor (and the
//! motion-io and motionctl next to it), cyclictest and stress-ng. Missing
//! ones are said plainly with how to get them: a missing supervisor ends the
//! bench, a missing cyclictest only skips its half.

use crate::cli::Opts;
use motion_bench::sys;
use std::path::{Path, PathBuf};

/// motion-supervisor (`--supervisor`, else next to this binary), checked to
/// have its motion-io (next to it, or `$MOTION_IO_BIN`) since it starts it.
pub fn supervisor(o: &Opts) -> Result<PathBuf, String> {
    let p = match &o.supervisor {
        Some(p) => p.clone(),
        None => sys::sibling_exe("motion-supervisor").ok_or_else(|| {
            let dir = std::env::current_exe()
                .ok()
                .and_then(|e| e.parent().map(Path::to_path_buf))
                .unwrap_or_default();
            format!(
                "motion-supervisor not found next to this binary (in {}); build it first: \
                 `cargo build --release --workspace --bins` (with the same CARGO_TARGET_DIR), \
                 or pass --supervisor PATH",
                dir.display()
            )
        })?,
    };
    if !sys::is_executable(&p) {
        return Err(format!("{} is not an executable file", p.display()));
    }
    let io = std::env::var_os("MOTION_IO_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| p.with_file_name("motion-io"));
    if !sys::is_executable(&io) {
        return Err(format!(
            "motion-io not found at {} (the supervisor starts it from there; build it with \
             `cargo build --release --workspace --bins` or set MOTION_IO_BIN)",
            io.display()
        ));
    }
    Ok(p)
}

/// cyclictest, or None (with a warning saying why) when its half is
/// skipped: `--no-cyclictest`, not installed, or no SCHED_FIFO for this
/// user (cyclictest refuses to run without it).
pub fn cyclictest(o: &Opts) -> Option<PathBuf> {
    let cyclictest = if o.no_cyclictest {
        eprintln!("jitter: --no-cyclictest: running the supervisor half only");
        None
    } else {
        match o
            .cyclictest
            .clone()
            .or_else(|| sys::find_in_path("cyclictest"))
        {
            Some(p) => Some(p),
            None => {
                eprintln!(
                    "jitter: WARNING: cyclictest not found (install rt-tests: \
                     `apt-get install -y rt-tests`); SKIPPING the cyclictest half, \
                     the supervisor is measured alone"
                );
                None
            }
        }
    };
    match (cyclictest, sys::can_use_fifo(o.priority)) {
        (Some(_), Err(e)) => {
            eprintln!(
                "jitter: WARNING: no real-time scheduling for this user ({e}); cyclictest \
                 cannot run like that: SKIPPING the cyclictest half (the supervisor warns \
                 and runs SCHED_OTHER)"
            );
            None
        }
        (c, _) => c,
    }
}

/// stress-ng with `--stress` (which needs a second CPU to load), else None.
pub fn stress_ng(o: &Opts) -> Result<Option<PathBuf>, String> {
    if o.stress {
        if sys::cpus() < 2 {
            return Err("--stress needs a second CPU".into());
        }
        Ok(Some(sys::find_in_path("stress-ng").ok_or(
            "--stress: stress-ng not found (apt-get install -y stress-ng)".to_string(),
        )?))
    } else {
        Ok(None)
    }
}

/// motionctl next to the supervisor: it homes the 64-axis machine.
pub fn motionctl(o: &Opts, supervisor: &Path) -> Result<PathBuf, String> {
    let motionctl = supervisor.with_file_name("motionctl");
    if o.axes64 && !sys::is_executable(&motionctl) {
        return Err(format!(
            "motionctl not found at {} (the 64-axis machine is homed with it; build it with \
             `cargo build --release --workspace --bins`, or pass --no-axes64)",
            motionctl.display()
        ));
    }
    Ok(motionctl)
}
