//! The machine: kernel and preemption model, CPUs, other real-time tasks;
//! pinning, SCHED_FIFO and locked memory for the calling thread; the
//! monotonic clock and absolute sleeps.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// `CLOCK_MONOTONIC` now, ns (the clock the supervisor and cyclictest use).
pub use motion_rt::now_ns;

/// Sleeps until the absolute monotonic time `deadline_ns` (retries EINTR
/// with the same deadline).
pub fn sleep_until(deadline_ns: u64) {
    let ts = libc::timespec {
        tv_sec: (deadline_ns / 1_000_000_000) as libc::time_t,
        tv_nsec: (deadline_ns % 1_000_000_000) as libc::c_long,
    };
    loop {
        // SAFETY: a valid timespec; no remainder is asked for with TIMER_ABSTIME.
        let rc = unsafe {
            libc::clock_nanosleep(
                libc::CLOCK_MONOTONIC,
                libc::TIMER_ABSTIME,
                &ts,
                std::ptr::null_mut(),
            )
        };
        if rc != libc::EINTR {
            return;
        }
    }
}

fn read_trim(path: &str) -> Option<String> {
    std::fs::read_to_string(path)
        .ok()
        .map(|s| s.trim().to_string())
}

/// `uname -rv`.
pub fn kernel() -> String {
    let r = read_trim("/proc/sys/kernel/osrelease").unwrap_or_else(|| "?".into());
    let v = read_trim("/proc/sys/kernel/version").unwrap_or_default();
    format!("{r} {v}").trim().to_string()
}

/// The kernel's preemption model in words, and whether it is PREEMPT_RT.
///
/// Sources, best first: `/sys/kernel/realtime`, debugfs `sched/preempt`
/// (the current mode of a PREEMPT_DYNAMIC kernel, in parentheses), a
/// `preempt=` on the kernel command line, `/proc/config.gz`, `uname -v`.
pub fn preemption() -> (String, bool) {
    if read_trim("/sys/kernel/realtime").as_deref() == Some("1") {
        return ("PREEMPT_RT (full real-time preemption)".into(), true);
    }
    let version = read_trim("/proc/sys/kernel/version").unwrap_or_default();
    if version.contains("PREEMPT_RT") {
        return ("PREEMPT_RT (full real-time preemption)".into(), true);
    }
    if let Some(p) = read_trim("/sys/kernel/debug/sched/preempt") {
        if let (Some(a), Some(b)) = (p.find('('), p.find(')')) {
            if a < b {
                return (
                    format!("PREEMPT_DYNAMIC, current mode {} (debugfs)", &p[a + 1..b]),
                    false,
                );
            }
        }
    }
    let cmdline = read_trim("/proc/cmdline").unwrap_or_default();
    let boot = cmdline
        .split_whitespace()
        .find_map(|w| w.strip_prefix("preempt="))
        .map(str::to_string);
    let config_default = config_gz_preempt();
    let dynamic = version.contains("PREEMPT_DYNAMIC");
    match (dynamic, boot, config_default) {
        (true, Some(b), _) => (format!("PREEMPT_DYNAMIC, booted preempt={b}"), false),
        (true, None, Some(d)) => (
            format!("PREEMPT_DYNAMIC, mode {d} (build default, no preempt= on the command line)"),
            false,
        ),
        (true, None, None) => ("PREEMPT_DYNAMIC (mode unknown)".into(), false),
        (false, _, Some(d)) => (format!("{d} (kernel config)"), false),
        (false, _, None) if version.contains("PREEMPT") => ("PREEMPT (full)".into(), false),
        (false, _, None) => ("unknown (probably none/voluntary)".into(), false),
    }
}

/// `none`, `voluntary`, `full` or `lazy` from `/proc/config.gz`, via `zcat`.
fn config_gz_preempt() -> Option<String> {
    if !Path::new("/proc/config.gz").exists() {
        return None;
    }
    let out = std::process::Command::new("zcat")
        .arg("/proc/config.gz")
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    for (key, name) in [
        ("CONFIG_PREEMPT_RT=y", "PREEMPT_RT"),
        ("CONFIG_PREEMPT_NONE=y", "none"),
        ("CONFIG_PREEMPT_VOLUNTARY=y", "voluntary"),
        ("CONFIG_PREEMPT=y", "full"),
        ("CONFIG_PREEMPT_LAZY=y", "lazy"),
    ] {
        if text.lines().any(|l| l == key) {
            return Some(name.into());
        }
    }
    None
}

/// CPUs this process may use.
pub fn cpus() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Pins the calling thread to `cpu` (if given), SCHED_FIFO at `priority` (if
/// given), memory locked — with the runtime the supervisor itself uses, so
/// the benchmark threads are set up exactly like the cycle. Returns the
/// settings the OS refused, as warnings.
pub fn enter_rt(cpu: Option<usize>, priority: Option<i32>) -> Vec<String> {
    match priority {
        Some(priority) => {
            motion_rt::enter_realtime(&motion_rt::RtConfig {
                cpu,
                priority,
                lock_memory: true,
                ..motion_rt::RtConfig::default()
            })
            .warnings
        }
        None => {
            let mut w = Vec::new();
            if let Some(c) = cpu {
                if !core_pin(c) {
                    w.push(format!("cannot pin to cpu {c}"));
                }
            }
            if let Err(e) = nix::sys::mman::mlockall(
                nix::sys::mman::MlockAllFlags::MCL_CURRENT
                    | nix::sys::mman::MlockAllFlags::MCL_FUTURE,
            ) {
                w.push(format!("mlockall: {e}"));
            }
            w
        }
    }
}

fn core_pin(cpu: usize) -> bool {
    use nix::sched::{sched_setaffinity, CpuSet};
    let mut set = CpuSet::new();
    set.set(cpu).is_ok() && sched_setaffinity(nix::unistd::Pid::from_raw(0), &set).is_ok()
}

/// Whether this process may run a thread SCHED_FIFO at `priority` (tried
/// on a throw-away thread).
pub fn can_use_fifo(priority: i32) -> Result<(), String> {
    std::thread::spawn(move || {
        let r = motion_rt::enter_realtime(&motion_rt::RtConfig {
            cpu: None,
            priority,
            lock_memory: false,
            prefault_stack: 0,
        });
        match r.policy {
            motion_rt::SchedPolicy::Fifo => Ok(()),
            _ => Err(r.warnings.join("; ")),
        }
    })
    .join()
    .unwrap_or_else(|_| Err("probe thread panicked".into()))
}

/// Holds `/dev/cpu_dma_latency` at `us` while the guard lives (as the
/// supervisor and cyclictest do: no deep idle states).
pub use motion_rt::hold_cpu_dma_latency;

/// A real-time thread somewhere on the machine.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct RtTask {
    pub pid: u32,
    pub tid: u32,
    pub comm: String,
    pub policy: &'static str,
    pub priority: u32,
}

impl std::fmt::Display for RtTask {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} (pid {}, tid {}) {} {}",
            self.comm, self.pid, self.tid, self.policy, self.priority
        )
    }
}

/// (comm, fields after the comm) of a `/proc/.../stat` line.
fn parse_stat(s: &str) -> Option<(String, Vec<String>)> {
    let a = s.find('(')?;
    let b = s.rfind(')')?;
    let comm = s.get(a + 1..b)?.to_string();
    let rest = s
        .get(b + 1..)?
        .split_whitespace()
        .map(str::to_string)
        .collect();
    Some((comm, rest))
}

fn pids() -> Vec<u32> {
    std::fs::read_dir("/proc")
        .map(|rd| {
            rd.flatten()
                .filter_map(|e| e.file_name().to_str()?.parse().ok())
                .collect()
        })
        .unwrap_or_default()
}

/// SCHED_FIFO / SCHED_RR threads of user processes that are neither this
/// process nor one of its descendants (kernel threads are left out): other
/// work competing with the benchmark for the CPUs at real-time priority.
pub fn other_rt_tasks() -> Vec<RtTask> {
    let me = std::process::id();
    let mut parent: HashMap<u32, u32> = HashMap::new();
    let all = pids();
    for &pid in &all {
        if let Some((_, f)) = std::fs::read_to_string(format!("/proc/{pid}/stat"))
            .ok()
            .as_deref()
            .and_then(parse_stat)
        {
            if let Some(pp) = f.get(1).and_then(|x| x.parse().ok()) {
                parent.insert(pid, pp);
            }
        }
    }
    let ours = |mut pid: u32| -> bool {
        let mut seen = HashSet::new();
        loop {
            if pid == me {
                return true;
            }
            if pid <= 1 || !seen.insert(pid) {
                return false;
            }
            match parent.get(&pid) {
                Some(&pp) => pid = pp,
                None => return false,
            }
        }
    };
    let kernel = |pid: u32| pid == 2 || parent.get(&pid) == Some(&2);
    let mut out = Vec::new();
    for &pid in &all {
        if kernel(pid) || ours(pid) {
            continue;
        }
        let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
            continue;
        };
        for t in tasks.flatten() {
            let Some(tid) = t.file_name().to_str().and_then(|s| s.parse::<u32>().ok()) else {
                continue;
            };
            let Some((comm, f)) = std::fs::read_to_string(t.path().join("stat"))
                .ok()
                .as_deref()
                .and_then(parse_stat)
            else {
                continue;
            };
            // field 40 rt_priority, 41 policy (1-based; `f` starts at field 3)
            let prio: u32 = f.get(37).and_then(|x| x.parse().ok()).unwrap_or(0);
            let policy = match f.get(38).map(String::as_str) {
                Some("1") => "SCHED_FIFO",
                Some("2") => "SCHED_RR",
                _ => continue,
            };
            out.push(RtTask {
                pid,
                tid,
                comm,
                policy,
                priority: prio,
            });
        }
    }
    out
}

/// `name` in `$PATH`.
pub fn find_in_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|p| is_executable(p))
}

pub fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

/// `name` in the directory of this executable (`target/release/`).
pub fn sibling_exe(name: &str) -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let p = exe.parent()?.join(name);
    is_executable(&p).then_some(p)
}

/// `/proc/sys/kernel/sched_rt_runtime_us` / `sched_rt_period_us`.
pub fn rt_throttling() -> String {
    match (
        read_trim("/proc/sys/kernel/sched_rt_runtime_us"),
        read_trim("/proc/sys/kernel/sched_rt_period_us"),
    ) {
        (Some(r), Some(p)) if r == "-1" => format!("off (period {p} µs)"),
        (Some(r), Some(p)) => format!("{r} of {p} µs"),
        _ => "unknown".into(),
    }
}

/// The 1-minute load average.
pub fn loadavg() -> String {
    read_trim("/proc/loadavg")
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_lines() {
        let (comm, f) = parse_stat("42 (a (b) c) S 1 42 42 0 -1").unwrap();
        assert_eq!(comm, "a (b) c");
        assert_eq!(f[0], "S");
        assert_eq!(f[1], "1");
        assert!(!kernel().is_empty());
        let _ = preemption();
        let _ = other_rt_tasks();
    }
}
