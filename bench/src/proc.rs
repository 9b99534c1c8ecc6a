//! A bench's processes: the harness's children ([`Running`], [`Ended`]:
//! captured output, bounded waits, a guaranteed end), the bench's own
//! SIGINT/SIGTERM (`motion-rt`'s termination handler: recorded, seen by
//! [`Running::wait`], which then ends the child), the `motion-io`
//! processes a supervisor spawned, and stress-ng as a load.

use std::process::Command;
use std::time::Duration;

pub use motion_harness::process::{stop_requested, tail, Ended, Running};
use motion_harness::procs::pids;

use crate::bins::find_in_path;

/// Installs the SIGINT/SIGTERM handler (a bench calls this first).
pub fn install_stop_handler() {
    if let Err(e) = motion_rt::termination::install() {
        eprintln!("warning: {e}");
    }
}

/// The signal that arrived (0: none).
pub fn stop_signal() -> i32 {
    motion_rt::termination::received().unwrap_or(0)
}

/// The `motion-io` processes whose parent is `parent`.
pub fn io_children(parent: u32) -> Vec<u32> {
    let mut v = Vec::new();
    for pid in pids() {
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
    let bin = find_in_path("stress-ng")
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
