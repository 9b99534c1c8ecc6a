//! Read-only checks of the machine a real-time loop runs on.
//!
//! [`check_environment`] changes nothing; it reports the items a controls
//! engineer walks through before trusting a 1 kHz loop on a Linux PC: the
//! kernel flavour, RT throttling, CPU isolation, the rlimits/capabilities
//! that decide whether `SCHED_FIFO` and `mlockall` will be granted, whether
//! the CPU exists, SMT and the cpufreq governor.

use nix::sys::resource::{getrlimit, rlim_t, Resource, RLIM_INFINITY};

pub use crate::procfs::{fmt_cpulist, parse_cpulist};
// Used here, and still reachable at its former path `environment::read_trimmed`.
pub(crate) use crate::procfs::read_trimmed;
use crate::procfs::{
    current_affinity, fmt_rlimit, has_capability, online_cpus, read_cpulist, uname_version,
    CAP_IPC_LOCK, CAP_SYS_NICE,
};
use crate::thread::RtConfig;

/// One line per check, prefixed `ok:`, `warning:` or `info:`.
///
/// Lines say what was found and, for warnings, the fix. Nothing is changed.
pub fn check_environment(cfg: &RtConfig) -> Vec<String> {
    let mut out = Vec::new();
    check_kernel(&mut out);
    check_rt_throttling(&mut out);
    check_cpu(cfg, &mut out);
    check_rtprio(cfg, &mut out);
    check_memlock(cfg, &mut out);
    out
}

fn check_kernel(out: &mut Vec<String>) {
    let realtime_flag = read_trimmed("/sys/kernel/realtime").as_deref() == Some("1");
    let version = uname_version().unwrap_or_default();
    if realtime_flag || version.contains("PREEMPT_RT") {
        out.push(format!("ok: kernel is PREEMPT_RT ({version})"));
    } else {
        out.push(format!(
            "warning: kernel is not PREEMPT_RT (uname -v: {version}); worst-case wake-up \
             latency is milliseconds, not tens of microseconds; fix: boot a PREEMPT_RT kernel \
             (e.g. linux-image-rt-amd64)"
        ));
    }
}

fn check_rt_throttling(out: &mut Vec<String>) {
    match read_trimmed("/proc/sys/kernel/sched_rt_runtime_us") {
        Some(v) if v == "-1" => {
            out.push("info: sched_rt_runtime_us = -1 (RT throttling off: a runaway FIFO thread can starve the CPU)".to_string());
        }
        Some(v) => {
            let period = read_trimmed("/proc/sys/kernel/sched_rt_period_us")
                .unwrap_or_else(|| "1000000".to_string());
            out.push(format!(
                "info: sched_rt_runtime_us = {v} of sched_rt_period_us {period}: RT threads are \
                 throttled once they use that much CPU per period; a sleeping periodic loop is \
                 fine, a busy-polling FIFO thread will be stalled"
            ));
        }
        None => out.push("info: sched_rt_runtime_us unreadable".to_string()),
    }
}

fn check_cpu(cfg: &RtConfig, out: &mut Vec<String>) {
    let online = online_cpus();
    let isolated = read_cpulist("/sys/devices/system/cpu/isolated").unwrap_or_default();
    let nohz_full = read_cpulist("/sys/devices/system/cpu/nohz_full").unwrap_or_default();
    let Some(cpu) = cfg.cpu else {
        out.push(format!(
            "warning: no cpu configured: the RT thread may migrate (isolated cpus: {}); fix: \
             pin it to an isolated cpu",
            none_or_list(&isolated)
        ));
        return;
    };

    match &online {
        Some(list) if !list.contains(&cpu) => {
            out.push(format!(
                "warning: cpu {cpu} does not exist: machine has {} CPUs (online {})",
                list.len(),
                fmt_cpulist(list)
            ));
            return;
        }
        Some(_) => out.push(format!("ok: cpu {cpu} exists and is online")),
        None => out.push(format!(
            "info: cannot read online cpus; cpu {cpu} unchecked"
        )),
    }

    let allowed = current_affinity();
    if !allowed.is_empty() && !allowed.contains(&cpu) {
        out.push(format!(
            "warning: cpu {cpu} is not in this process's allowed set {}; fix: systemd \
             CPUAffinity= / taskset / cgroup cpuset.cpus",
            fmt_cpulist(&allowed)
        ));
    }

    if isolated.contains(&cpu) {
        out.push(format!("ok: cpu {cpu} is isolated (isolcpus)"));
    } else {
        out.push(format!(
            "warning: cpu {cpu} is not isolated (isolated: {}); fix: kernel command line \
             isolcpus={cpu} nohz_full={cpu} rcu_nocbs={cpu} irqaffinity=<other cpus>",
            none_or_list(&isolated)
        ));
    }
    if nohz_full.contains(&cpu) {
        out.push(format!("ok: cpu {cpu} is nohz_full"));
    }

    if let Some(smt) = read_trimmed("/sys/devices/system/cpu/smt/active") {
        if smt == "1" {
            out.push(
                "warning: SMT (hyper-threading) is active: the sibling thread shares the core; \
                 fix: nosmt on the kernel command line or disable in firmware"
                    .to_string(),
            );
        } else {
            out.push("ok: SMT is off".to_string());
        }
    }

    let gov_path = format!("/sys/devices/system/cpu/cpu{cpu}/cpufreq/scaling_governor");
    match read_trimmed(&gov_path) {
        Some(g) if g == "performance" => {
            out.push(format!("ok: cpu {cpu} cpufreq governor is performance"))
        }
        Some(g) => out.push(format!(
            "warning: cpu {cpu} cpufreq governor is {g}; fix: set performance \
             (cpupower frequency-set -g performance)"
        )),
        None => out.push(format!(
            "info: cpu {cpu} has no cpufreq (fixed frequency or a VM)"
        )),
    }
}

fn check_rtprio(cfg: &RtConfig, out: &mut Vec<String>) {
    let cap = has_capability(CAP_SYS_NICE);
    match getrlimit(Resource::RLIMIT_RTPRIO) {
        Ok((soft, hard)) => {
            let enough = soft == RLIM_INFINITY || soft >= cfg.priority.max(0) as rlim_t;
            if enough {
                out.push(format!(
                    "ok: RLIMIT_RTPRIO soft {} hard {} allows FIFO {}",
                    fmt_rlimit(soft),
                    fmt_rlimit(hard),
                    cfg.priority
                ));
            } else if cap == Some(true) {
                out.push(format!(
                    "ok: RLIMIT_RTPRIO soft {} < FIFO {}, but the process has CAP_SYS_NICE \
                     (root); a non-root service needs LimitRTPRIO=99",
                    fmt_rlimit(soft),
                    cfg.priority
                ));
            } else {
                out.push(format!(
                    "warning: RLIMIT_RTPRIO soft {} hard {} < FIFO {} and no CAP_SYS_NICE: \
                     SCHED_FIFO will be refused; fix: systemd LimitRTPRIO=99 / ulimit -r 99",
                    fmt_rlimit(soft),
                    fmt_rlimit(hard),
                    cfg.priority
                ));
            }
        }
        Err(e) => out.push(format!("info: RLIMIT_RTPRIO unreadable: {e}")),
    }
}

fn check_memlock(cfg: &RtConfig, out: &mut Vec<String>) {
    let cap = has_capability(CAP_IPC_LOCK);
    match getrlimit(Resource::RLIMIT_MEMLOCK) {
        Ok((soft, hard)) => {
            if soft == RLIM_INFINITY {
                out.push(format!(
                    "ok: RLIMIT_MEMLOCK soft {} hard {}",
                    fmt_rlimit(soft),
                    fmt_rlimit(hard)
                ));
            } else if cap == Some(true) {
                out.push(format!(
                    "ok: RLIMIT_MEMLOCK soft {} but the process has CAP_IPC_LOCK (root); a \
                     non-root service needs LimitMEMLOCK=infinity",
                    fmt_rlimit(soft)
                ));
            } else if cfg.lock_memory {
                out.push(format!(
                    "warning: RLIMIT_MEMLOCK soft {} hard {} and no CAP_IPC_LOCK: mlockall \
                     fails or later mmaps fail once the limit is reached; fix: systemd \
                     LimitMEMLOCK=infinity / ulimit -l unlimited",
                    fmt_rlimit(soft),
                    fmt_rlimit(hard)
                ));
            } else {
                out.push(format!(
                    "info: RLIMIT_MEMLOCK soft {} (memory locking not requested)",
                    fmt_rlimit(soft)
                ));
            }
        }
        Err(e) => out.push(format!("info: RLIMIT_MEMLOCK unreadable: {e}")),
    }
}

fn none_or_list(list: &[usize]) -> String {
    if list.is_empty() {
        "none".to_string()
    } else {
        fmt_cpulist(list)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reports_every_item_and_changes_nothing() {
        let before = crate::thread::current_sched();
        let cfg = RtConfig {
            cpu: Some(0),
            ..RtConfig::default()
        };
        let lines = check_environment(&cfg);
        for l in &lines {
            assert!(
                l.starts_with("ok: ") || l.starts_with("warning: ") || l.starts_with("info: "),
                "{l}"
            );
        }
        let all = lines.join("\n");
        assert!(all.contains("PREEMPT_RT"), "{all}");
        assert!(all.contains("sched_rt_runtime_us"), "{all}");
        assert!(all.contains("isolated"), "{all}");
        assert!(all.contains("RLIMIT_RTPRIO"), "{all}");
        assert!(all.contains("RLIMIT_MEMLOCK"), "{all}");
        assert!(all.contains("cpufreq"), "{all}");
        assert_eq!(crate::thread::current_sched(), before);

        let missing = check_environment(&RtConfig {
            cpu: Some(4096),
            ..RtConfig::default()
        });
        assert!(missing
            .iter()
            .any(|l| l.contains("cpu 4096 does not exist")));
    }
}
