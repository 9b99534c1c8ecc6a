//! Facts about the machine a real-time loop runs on, as words to print next
//! to measured latencies: the kernel, its preemption model, RT throttling,
//! the load, and real-time threads of other programs competing for the CPUs.
//! [`check_environment`](crate::check_environment) judges a configuration;
//! these only describe the host (the benchmarks record them with every run,
//! since they decide what the numbers mean).

use std::collections::{HashMap, HashSet};
use std::path::Path;

use crate::procfs::read_trimmed;

/// `uname -rv`.
pub fn kernel() -> String {
    let r = read_trimmed("/proc/sys/kernel/osrelease").unwrap_or_else(|| "?".into());
    let v = read_trimmed("/proc/sys/kernel/version").unwrap_or_default();
    format!("{r} {v}").trim().to_string()
}

/// The kernel's preemption model in words, and whether it is PREEMPT_RT.
///
/// Sources, best first: `/sys/kernel/realtime`, debugfs `sched/preempt`
/// (the current mode of a PREEMPT_DYNAMIC kernel, in parentheses), a
/// `preempt=` on the kernel command line, `/proc/config.gz`, `uname -v`.
pub fn preemption() -> (String, bool) {
    let version = read_trimmed("/proc/sys/kernel/version").unwrap_or_default();
    if read_trimmed("/sys/kernel/realtime").as_deref() == Some("1")
        || version.contains("PREEMPT_RT")
    {
        return ("PREEMPT_RT (full real-time preemption)".into(), true);
    }
    if let Some(p) = read_trimmed("/sys/kernel/debug/sched/preempt") {
        if let (Some(a), Some(b)) = (p.find('('), p.find(')')) {
            if a < b {
                let mode = &p[a + 1..b];
                return (
                    format!("PREEMPT_DYNAMIC, current mode {mode} (debugfs)"),
                    false,
                );
            }
        }
    }
    let cmdline = read_trimmed("/proc/cmdline").unwrap_or_default();
    let boot = cmdline
        .split_whitespace()
        .find_map(|w| w.strip_prefix("preempt="));
    let model = match (version.contains("PREEMPT_DYNAMIC"), boot, config_preempt()) {
        (true, Some(b), _) => format!("PREEMPT_DYNAMIC, booted preempt={b}"),
        (true, None, Some(d)) => {
            format!("PREEMPT_DYNAMIC, mode {d} (build default, no preempt= on the command line)")
        }
        (true, None, None) => "PREEMPT_DYNAMIC (mode unknown)".into(),
        (false, _, Some(d)) => format!("{d} (kernel config)"),
        (false, _, None) if version.contains("PREEMPT") => "PREEMPT (full)".into(),
        (false, _, None) => "unknown (probably none/voluntary)".into(),
    };
    (model, false)
}

/// `none`, `voluntary`, `full`, `lazy` or `PREEMPT_RT` from `/proc/config.gz`
/// (read with `zcat`: a gzip decoder for one optional line is not worth a
/// dependency).
fn config_preempt() -> Option<&'static str> {
    if !Path::new("/proc/config.gz").exists() {
        return None;
    }
    let out = std::process::Command::new("zcat")
        .arg("/proc/config.gz")
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    [
        ("CONFIG_PREEMPT_RT=y", "PREEMPT_RT"),
        ("CONFIG_PREEMPT_NONE=y", "none"),
        ("CONFIG_PREEMPT_VOLUNTARY=y", "voluntary"),
        ("CONFIG_PREEMPT=y", "full"),
        ("CONFIG_PREEMPT_LAZY=y", "lazy"),
    ]
    .into_iter()
    .find(|(key, _)| text.lines().any(|l| l == *key))
    .map(|(_, name)| name)
}

/// CPUs this process may use.
pub fn cpus() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// `sched_rt_runtime_us` of `sched_rt_period_us`, or `off`.
pub fn rt_throttling() -> String {
    match (
        read_trimmed("/proc/sys/kernel/sched_rt_runtime_us"),
        read_trimmed("/proc/sys/kernel/sched_rt_period_us"),
    ) {
        (Some(r), Some(p)) if r == "-1" => format!("off (period {p} µs)"),
        (Some(r), Some(p)) => format!("{r} of {p} µs"),
        _ => "unknown".into(),
    }
}

/// The 1-minute load average.
pub fn loadavg() -> String {
    read_trimmed("/proc/loadavg")
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into())
}

/// The host as a report shows it, read once (at the start of a run).
#[derive(Clone, Debug)]
pub struct Host {
    /// [`kernel`].
    pub kernel: String,
    /// [`preemption`]: the model in words ...
    pub preemption: String,
    /// ... and whether it is PREEMPT_RT.
    pub is_rt: bool,
    /// [`cpus`].
    pub cpus: usize,
    /// [`rt_throttling`].
    pub throttling: String,
    /// [`loadavg`] when it was read.
    pub load: String,
}

impl Host {
    /// Reads every fact now.
    pub fn read() -> Self {
        let (preemption, is_rt) = preemption();
        Host {
            kernel: kernel(),
            preemption,
            is_rt,
            cpus: cpus(),
            throttling: rt_throttling(),
            load: loadavg(),
        }
    }

    /// `kernel K | preemption: P | N CPUs`: how a report's host line starts.
    pub fn head(&self) -> String {
        let (k, p, n) = (&self.kernel, &self.preemption, self.cpus);
        format!("kernel {k} | preemption: {p} | {n} CPUs")
    }
}

/// A real-time thread somewhere on the machine.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct RtTask {
    /// Its process.
    pub pid: u32,
    /// The thread.
    pub tid: u32,
    /// Its name (`comm`).
    pub comm: String,
    /// `SCHED_FIFO` or `SCHED_RR`.
    pub policy: &'static str,
    /// Its real-time priority.
    pub priority: u32,
}

impl std::fmt::Display for RtTask {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let RtTask {
            pid,
            tid,
            comm,
            policy,
            priority,
        } = self;
        write!(f, "{comm} (pid {pid}, tid {tid}) {policy} {priority}")
    }
}

/// (comm, fields after the comm) of a `/proc/.../stat` file.
fn stat(path: &str) -> Option<(String, Vec<String>)> {
    parse_stat(&std::fs::read_to_string(path).ok()?)
}

fn parse_stat(s: &str) -> Option<(String, Vec<String>)> {
    let (a, b) = (s.find('(')?, s.rfind(')')?);
    let rest = s.get(b + 1..)?.split_whitespace().map(str::to_string);
    Some((s.get(a + 1..b)?.to_string(), rest.collect()))
}

fn numbered(dir: &str) -> Vec<u32> {
    std::fs::read_dir(dir).map_or_else(
        |_| Vec::new(),
        |rd| {
            rd.flatten()
                .filter_map(|e| e.file_name().to_str()?.parse().ok())
                .collect()
        },
    )
}

/// SCHED_FIFO / SCHED_RR threads of user processes that are neither this
/// process nor one of its descendants (kernel threads are left out): other
/// work competing with this program's threads at real-time priority.
pub fn other_rt_tasks() -> Vec<RtTask> {
    let me = std::process::id();
    let all = numbered("/proc");
    let parent: HashMap<u32, u32> = all
        .iter()
        .filter_map(|&pid| {
            let (_, f) = stat(&format!("/proc/{pid}/stat"))?;
            Some((pid, f.get(1)?.parse().ok()?))
        })
        .collect();
    let ours = |mut pid: u32| {
        let mut seen = HashSet::new();
        while pid != me {
            match parent.get(&pid) {
                Some(&pp) if pid > 1 && seen.insert(pid) => pid = pp,
                _ => return false,
            }
        }
        true
    };
    let kernel = |pid: u32| pid == 2 || parent.get(&pid) == Some(&2);
    let mut out = Vec::new();
    for pid in all.into_iter().filter(|&p| !kernel(p) && !ours(p)) {
        for tid in numbered(&format!("/proc/{pid}/task")) {
            let Some((comm, f)) = stat(&format!("/proc/{pid}/task/{tid}/stat")) else {
                continue;
            };
            // field 40 rt_priority, 41 policy (1-based; `f` starts at field 3)
            let policy = match f.get(38).map(String::as_str) {
                Some("1") => "SCHED_FIFO",
                Some("2") => "SCHED_RR",
                _ => continue,
            };
            let priority = f.get(37).and_then(|x| x.parse().ok()).unwrap_or(0);
            out.push(RtTask {
                pid,
                tid,
                comm,
                policy,
                priority,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_lines_and_the_host() {
        let (comm, f) = parse_stat("42 (a (b) c) S 1 42 42 0 -1").unwrap();
        assert_eq!(comm, "a (b) c");
        assert_eq!((f[0].as_str(), f[1].as_str()), ("S", "1"));
        assert!(!kernel().is_empty() && cpus() >= 1 && !loadavg().is_empty());
        assert!(!preemption().0.is_empty() && !rt_throttling().is_empty());
        assert!(other_rt_tasks().iter().all(|t| t.pid != std::process::id()));
        let h = Host::read();
        assert_eq!(h.cpus, cpus());
        assert!(h
            .head()
            .starts_with(&format!("kernel {} | preemption: ", h.kernel)));
    }
}
