//! Processes the harness did not start itself: the `motion-io` a
//! supervisor spawned, found in `/proc`, signalled by pid.

use nix::sys::signal::Signal;
use nix::unistd::Pid;

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
pub fn pids() -> Vec<u32> {
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
