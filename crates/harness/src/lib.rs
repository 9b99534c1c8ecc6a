//! `motion-harness`: the test harness of the workspace, for the end-to-end
//! tests (`tests/`), `motion-io`'s tests (`crates/io/tests`) and any other
//! test that runs the binaries. Dev-only: never a dependency of a product
//! crate. The benches (`bench/`) build on it — their children, readiness
//! and leftover checks are these — but what only they need is theirs
//! (`motion-bench`'s library); nothing here knows about a bench.
//!
//! * [`process`] — a child with captured output, stderr lines as they come,
//!   bounded waits, signals and a guaranteed end (also on drop).
//! * [`bins`] — where `motion-supervisor`, `motion-io` and `motionctl` are
//!   for a test; [`commands`] runs them as a test does.
//! * [`daemon`] — `motion-supervisor run`: ready when `status --json`, read
//!   as the typed report, shows its I/O attached; status; stop.
//! * [`machines`] — the fixture machines (`tests/machines/*.toml`) with
//!   stated overrides, written as a test's temporary config.
//! * [`leftovers`] — what a prefix left in `/dev/shm`, and the checks;
//!   [`temp`] — a test's scratch directory.
//! * [`check`] — rows by name, positions within a tolerance, homed axes.
//! * [`peer`] — the supervisor's side of a `motion-io`, played by a test.
//! * [`procs`] — processes found in `/proc`.
//! * [`ecat`] — the EtherCAT veth rig with emulated drives;
//!   [`placement`] — where its emulator's thread runs.
//!
//! Invariants: every process it starts ends (SIGTERM, then SIGKILL) when
//! its handle goes, also when a test panics; every test config has a
//! service prefix no other test or run uses, so tests run side by side and
//! each can check that it left nothing behind; readiness and results are
//! read through `motion-report`'s typed structs, the same definitions the
//! binaries write.

pub mod bins;
pub mod check;
pub mod commands;
pub mod daemon;
pub mod ecat;
pub mod leftovers;
pub mod machines;
pub mod peer;
pub mod placement;
pub mod process;
pub mod procs;
pub mod temp;

use std::sync::atomic::{AtomicU32, Ordering};

pub use check::{at_rest, home_all, homed, named, value, COUNT};
pub use commands::{ctl, motionctl, spawn_io, spawn_motionctl, spawn_supervisor, supervisor};
pub use daemon::{Attached, Daemon};
pub use leftovers::{assert_clean, shm_leftovers, DomainGuard};
pub use machines::{Machine, TempConfig};
pub use process::{Ended, Running};
pub use procs::{find_process, signal_pid};
pub use temp::TempDir;

/// A service prefix no other test (or run) uses: `<tag>_<pid>_<n>`.
pub fn unique_prefix(tag: &str) -> String {
    static N: AtomicU32 = AtomicU32::new(0);
    format!(
        "{tag}_{}_{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    )
}

/// Runs the process-spawning tests of one test binary one at a time.
///
/// Each test starts a SCHED_FIFO supervisor and an I/O process; several at
/// once on a 2-core CI machine (with a kernel that is not PREEMPT_RT, where
/// process start-up work in the kernel is not preemptible) can starve an I/O
/// process past `stale_cycles`, and the engines then — correctly — abort
/// homing with ERR 12/40. These tests are about behaviour, so they take turns.
pub fn serial() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// Waits until `f` is true or `timeout` passes (polls every 20 ms).
pub fn wait_for(timeout: std::time::Duration, mut f: impl FnMut() -> bool) -> bool {
    let until = std::time::Instant::now() + timeout;
    while std::time::Instant::now() < until {
        if f() {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    f()
}
