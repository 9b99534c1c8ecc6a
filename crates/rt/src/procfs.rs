//! What the kernel says about this machine and this process, read from
//! `/proc`, `/sys` and a few system calls, and the kernel's own formats
//! (cpu lists, rlimits). Both the real-time set-up ([`thread`](crate::thread))
//! and the environment checklist ([`environment`](crate::environment)) read
//! these; neither needs the other for them.

use std::fs;

use nix::sched::{sched_getaffinity, CpuSet};
use nix::sys::resource::{rlim_t, RLIM_INFINITY};
use nix::unistd::Pid;

/// `CAP_IPC_LOCK`: lock memory regardless of `RLIMIT_MEMLOCK`.
pub(crate) const CAP_IPC_LOCK: u32 = 14;
/// `CAP_SYS_NICE`: real-time scheduling regardless of `RLIMIT_RTPRIO`.
pub(crate) const CAP_SYS_NICE: u32 = 23;

pub(crate) fn read_trimmed(path: &str) -> Option<String> {
    fs::read_to_string(path).ok().map(|s| s.trim().to_string())
}

/// A cpu list file of `/sys` (`0-3,5`).
pub(crate) fn read_cpulist(path: &str) -> Option<Vec<usize>> {
    read_trimmed(path).and_then(|s| parse_cpulist(&s))
}

/// Online CPUs (`/sys/devices/system/cpu/online`).
pub(crate) fn online_cpus() -> Option<Vec<usize>> {
    read_cpulist("/sys/devices/system/cpu/online")
}

/// Parses a kernel cpu list such as `0-3,5,7-8`; empty input is an empty
/// list. `None` on malformed input.
pub fn parse_cpulist(s: &str) -> Option<Vec<usize>> {
    let mut cpus = Vec::new();
    for part in s.trim().split(',').filter(|p| !p.trim().is_empty()) {
        let part = part.trim();
        match part.split_once('-') {
            Some((a, b)) => {
                let a: usize = a.trim().parse().ok()?;
                let b: usize = b.trim().parse().ok()?;
                if b < a {
                    return None;
                }
                cpus.extend(a..=b);
            }
            None => cpus.push(part.parse().ok()?),
        }
    }
    cpus.sort_unstable();
    cpus.dedup();
    Some(cpus)
}

/// Formats CPUs as a kernel cpu list (`0-3,5`).
pub fn fmt_cpulist(cpus: &[usize]) -> String {
    let mut out = String::new();
    let mut i = 0;
    while i < cpus.len() {
        let start = cpus[i];
        let mut end = start;
        while i + 1 < cpus.len() && cpus[i + 1] == end + 1 {
            end += 1;
            i += 1;
        }
        if !out.is_empty() {
            out.push(',');
        }
        if start == end {
            out.push_str(&start.to_string());
        } else {
            out.push_str(&format!("{start}-{end}"));
        }
        i += 1;
    }
    out
}

pub(crate) fn fmt_rlimit(v: rlim_t) -> String {
    if v == RLIM_INFINITY {
        "unlimited".to_string()
    } else {
        v.to_string()
    }
}

/// A `Field:   123 kB` line of /proc/self/status, in KiB.
pub(crate) fn read_status_kib(field: &str) -> Option<u64> {
    let status = fs::read_to_string("/proc/self/status").ok()?;
    status_field(&status, field)?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

fn status_field<'a>(status: &'a str, field: &str) -> Option<&'a str> {
    status.lines().find_map(|l| {
        let (k, v) = l.split_once(':')?;
        (k == field).then_some(v.trim())
    })
}

/// Whether the effective capability set (`CapEff`) has capability `cap`.
pub(crate) fn has_capability(cap: u32) -> Option<bool> {
    let status = fs::read_to_string("/proc/self/status").ok()?;
    let mask = u64::from_str_radix(status_field(&status, "CapEff")?, 16).ok()?;
    Some(mask & (1u64 << cap) != 0)
}

pub(crate) fn uname_version() -> Option<String> {
    // SAFETY: utsname is plain data; uname fills it.
    let mut u: libc::utsname = unsafe { std::mem::zeroed() };
    if unsafe { libc::uname(&mut u) } != 0 {
        return None;
    }
    // SAFETY: the kernel NUL-terminates the fields.
    let v = unsafe { std::ffi::CStr::from_ptr(u.version.as_ptr()) };
    Some(v.to_string_lossy().into_owned())
}

/// The calling thread's affinity mask.
pub(crate) fn current_affinity() -> Vec<usize> {
    match sched_getaffinity(Pid::from_raw(0)) {
        Ok(set) => (0..CpuSet::count())
            .filter(|&c| set.is_set(c).unwrap_or(false))
            .collect(),
        Err(_) => Vec::new(),
    }
}

/// The page size (`sysconf(_SC_PAGESIZE)`, 4096 if it cannot be read).
pub(crate) fn page_size() -> usize {
    // SAFETY: plain query.
    let p = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    if p > 0 {
        p as usize
    } else {
        4096
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpulists() {
        assert_eq!(parse_cpulist("").unwrap(), Vec::<usize>::new());
        assert_eq!(
            parse_cpulist("0-3,5,7-8\n").unwrap(),
            vec![0, 1, 2, 3, 5, 7, 8]
        );
        assert_eq!(parse_cpulist("1").unwrap(), vec![1]);
        assert!(parse_cpulist("3-1").is_none());
        assert!(parse_cpulist("x").is_none());
        assert_eq!(fmt_cpulist(&[0, 1, 2, 3, 5, 7, 8]), "0-3,5,7-8");
        assert_eq!(fmt_cpulist(&[]), "");
    }

    #[test]
    fn status_fields() {
        let s = "Name:\tx\nVmLck:\t    1234 kB\nCapEff:\t000001ffffffffff\n";
        assert_eq!(status_field(s, "VmLck"), Some("1234 kB"));
        assert_eq!(status_field(s, "CapEff"), Some("000001ffffffffff"));
        assert_eq!(status_field(s, "Nope"), None);
    }
}
