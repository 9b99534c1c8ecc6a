//! Processes the harness did not start itself: the `motion-io` a
//! supervisor spawned, found in `/proc`, signalled by pid; and stress-ng as
//! the benches' load.

use std::process::Command;
use std::time::Duration;

use nix::sys::signal::Signal;
use nix::unistd::Pid;

use crate::bins::find_in_path;
use crate::process::Running;

/// Pid of a running process whose executable name ends in `name` and one
/// of whose arguments is `needle` (e.g. the `motion-io` a supervisor of
/// prefix `needle` spawned).
pub fn find_process(name: &str, needle: &str) -> Option<i32> {
    for pid in pids() {
        let Ok(cmd) = std::fs::read(format!("/proc/{pid}/cmdline")) else {
            continue;
        };
        let args: Vec<String> = cmd
            .split(|b| *b == 0)
            .map(|a| String::from_utf8_lossy(a).into_owned())
            .collect();
        let is_name = args.first().is_some_and(|a| a.ends_with(name));
        if is_name && args.iter().any(|a| a == needle) {
            return Some(pid as i32);
        }
    }
    None
}

/// The pids in `/proc` now.
fn pids() -> Vec<u32> {
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    dir.flatten()
        .filter_map(|e| e.file_name().to_str()?.parse().ok())
        .collect()
}

/// Sends `sig` to `pid`.
pub fn signal_pid(pid: i32, sig: Signal) {
    let _ = nix::sys::signal::kill(Pid::from_raw(pid), sig);
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
