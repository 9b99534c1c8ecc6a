//! Turning the calling thread into a real-time thread.
//!
//! [`enter_realtime`] applies, in order: CPU affinity, `SCHED_FIFO` priority,
//! `mlockall(MCL_CURRENT | MCL_FUTURE)` and stack prefaulting. Each step the
//! OS refuses becomes a warning in [`RtReport::warnings`] that names the
//! setting, the requested value, the errno and the fix; nothing panics or
//! aborts, so a supervisor started on a developer laptop still runs (just
//! without real-time guarantees) and says exactly why.
//!
//! Why each step:
//! - **Affinity**: a thread that migrates between CPUs loses its caches and
//!   can land on a CPU busy with interrupts; pin it to an isolated CPU.
//! - **SCHED_FIFO**: a normal (CFS/EEVDF) thread shares the CPU fairly with
//!   everything else; a FIFO thread preempts every normal thread the moment
//!   its timer fires. Priority should be above the fieldbus NIC's IRQ thread
//!   (IRQ threads run at FIFO 50 on PREEMPT_RT kernels).
//! - **mlockall**: a page fault in the cycle (first touch of heap or stack, or
//!   a page reclaimed under memory pressure) costs microseconds to
//!   milliseconds. `MCL_CURRENT | MCL_FUTURE` keeps every present and future
//!   page of the process resident.
//! - **Stack prefault**: locking only applies to pages that exist; the stack
//!   grows on first touch, so touching the stack the cycle will use once, at
//!   start-up, moves those page faults out of the cycle.

use std::fmt;
use std::mem::MaybeUninit;

use nix::sched::{sched_setaffinity, CpuSet};
use nix::sys::mman::{mlockall, MlockAllFlags};
use nix::sys::resource::{getrlimit, Resource};
use nix::unistd::Pid;

use crate::procfs::{
    current_affinity, fmt_cpulist, fmt_rlimit, has_capability, online_cpus, page_size,
    read_status_kib, CAP_IPC_LOCK, CAP_SYS_NICE,
};

/// What [`enter_realtime`] should apply to the calling thread.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RtConfig {
    /// CPU to pin the thread to; `None` leaves the affinity alone.
    pub cpu: Option<usize>,
    /// `SCHED_FIFO` priority, 1..=99 on Linux.
    pub priority: i32,
    /// Call `mlockall(MCL_CURRENT | MCL_FUTURE)` (process-wide).
    pub lock_memory: bool,
    /// Bytes of stack to touch once so the cycle does not page-fault on it.
    pub prefault_stack: usize,
}

impl Default for RtConfig {
    /// No pinning, FIFO 80 (above IRQ threads at 50), memory locked, 256 KiB
    /// of stack prefaulted.
    fn default() -> Self {
        Self {
            cpu: None,
            priority: 80,
            lock_memory: true,
            prefault_stack: 256 * 1024,
        }
    }
}

/// A scheduling policy as read back from the kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SchedPolicy {
    /// `SCHED_OTHER`, the normal time-sharing policy.
    Other,
    /// `SCHED_FIFO`.
    Fifo,
    /// `SCHED_RR`.
    RoundRobin,
    /// `SCHED_BATCH`.
    Batch,
    /// `SCHED_IDLE`.
    Idle,
    /// Anything else (e.g. `SCHED_DEADLINE`, or the read-back failed: -1).
    Unknown(i32),
}

impl SchedPolicy {
    /// Maps a libc policy constant.
    pub fn from_raw(policy: i32) -> Self {
        match policy {
            libc::SCHED_OTHER => Self::Other,
            libc::SCHED_FIFO => Self::Fifo,
            libc::SCHED_RR => Self::RoundRobin,
            libc::SCHED_BATCH => Self::Batch,
            libc::SCHED_IDLE => Self::Idle,
            other => Self::Unknown(other),
        }
    }
}

impl fmt::Display for SchedPolicy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Other => f.write_str("SCHED_OTHER"),
            Self::Fifo => f.write_str("SCHED_FIFO"),
            Self::RoundRobin => f.write_str("SCHED_RR"),
            Self::Batch => f.write_str("SCHED_BATCH"),
            Self::Idle => f.write_str("SCHED_IDLE"),
            Self::Unknown(p) => write!(f, "policy {p}"),
        }
    }
}

/// What [`enter_realtime`] actually achieved, read back from the kernel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RtReport {
    /// The CPU the thread is pinned to, if its affinity mask (read back) has
    /// exactly one CPU.
    pub cpu: Option<usize>,
    /// The thread's affinity mask, read back.
    pub allowed_cpus: Vec<usize>,
    /// Scheduling policy, read back with `pthread_getschedparam`.
    pub policy: SchedPolicy,
    /// Scheduling priority, read back with `pthread_getschedparam`.
    pub priority: i32,
    /// Process memory is locked (`mlockall` succeeded now or earlier:
    /// `VmLck` in /proc/self/status is non-zero).
    pub memory_locked: bool,
    /// `VmLck` of /proc/self/status in KiB, if readable.
    pub locked_kib: Option<u64>,
    /// Bytes of stack actually prefaulted.
    pub stack_prefaulted: usize,
    /// One line per setting the OS refused or that was adjusted.
    pub warnings: Vec<String>,
}

impl RtReport {
    /// True if everything requested was applied.
    pub fn fully_applied(&self) -> bool {
        self.warnings.is_empty()
    }
}

impl fmt::Display for RtReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.cpu {
            Some(cpu) => write!(f, "cpu {cpu}")?,
            None => write!(f, "cpus {}", fmt_cpulist(&self.allowed_cpus))?,
        }
        write!(
            f,
            ", {} {}, memory {}, stack prefaulted {} KiB",
            self.policy,
            self.priority,
            if self.memory_locked {
                "locked"
            } else {
                "NOT locked"
            },
            self.stack_prefaulted / 1024
        )?;
        for w in &self.warnings {
            write!(f, "\n  warning: {w}")?;
        }
        Ok(())
    }
}

/// Applies `cfg` to the calling thread and reports what was applied.
///
/// Never panics because the OS refused something: each refusal is a warning
/// in the report. Allocates (strings, the report): call it at start-up, not
/// in the cycle. `mlockall` is process-wide.
pub fn enter_realtime(cfg: &RtConfig) -> RtReport {
    let mut warnings = Vec::new();

    if let Some(cpu) = cfg.cpu {
        if let Err(w) = pin_to_cpu(cpu) {
            warnings.push(w);
        }
    }

    if let Err(w) = set_fifo(cfg.priority) {
        warnings.push(w);
    }

    let mut mlockall_ok = false;
    if cfg.lock_memory {
        match mlockall(MlockAllFlags::MCL_CURRENT | MlockAllFlags::MCL_FUTURE) {
            Ok(()) => mlockall_ok = true,
            Err(e) => warnings.push(mlock_warning(e)),
        }
    }

    let stack_prefaulted = prefault_stack(cfg.prefault_stack, &mut warnings);

    // Read back what the kernel actually has.
    let allowed_cpus = current_affinity();
    let cpu = match allowed_cpus.as_slice() {
        [only] => Some(*only),
        _ => None,
    };
    let (policy, priority) = current_sched();
    let locked_kib = read_status_kib("VmLck");
    let memory_locked = locked_kib.is_some_and(|k| k > 0);
    if mlockall_ok && !memory_locked && locked_kib.is_some() {
        warnings.push("memory locking: VmLck is 0 kB after mlockall".to_string());
    }

    RtReport {
        cpu,
        allowed_cpus,
        policy,
        priority,
        memory_locked,
        locked_kib,
        stack_prefaulted,
        warnings,
    }
}

/// Whether this process may run a thread `SCHED_FIFO` at `priority`: tried
/// on a throw-away thread (nothing pinned or locked); the error says why not.
pub fn fifo_allowed(priority: i32) -> Result<(), String> {
    let probe = move || {
        let cfg = RtConfig {
            priority,
            lock_memory: false,
            prefault_stack: 0,
            ..RtConfig::default()
        };
        let r = enter_realtime(&cfg);
        match r.policy {
            SchedPolicy::Fifo => Ok(()),
            _ => Err(r.warnings.join("; ")),
        }
    };
    let joined = std::thread::spawn(probe).join();
    joined.unwrap_or_else(|_| Err("the probe thread panicked".into()))
}

/// Pins the calling thread to `cpu` (no other setting changed); the error
/// names the CPUs there are or the allowed set, as a warning to print.
pub fn pin_to_cpu(cpu: usize) -> Result<(), String> {
    let online = online_cpus();
    let exists = match &online {
        Some(list) => list.contains(&cpu),
        None => cpu < num_cpus_configured(),
    };
    if !exists || cpu >= CpuSet::count() {
        let machine = match &online {
            Some(list) => format!(
                "machine has {} CPUs (online {})",
                list.len(),
                fmt_cpulist(list)
            ),
            None => format!("machine has {} CPUs", num_cpus_configured()),
        };
        return Err(format!(
            "cpu affinity: cpu {cpu} does not exist: {machine}; fix: choose one of those \
             (ideally one isolated with isolcpus=)"
        ));
    }
    // core_affinity does the pinning; it only says yes or no, so on a no the
    // same request is repeated through nix to name the errno in the warning.
    if core_affinity::set_for_current(core_affinity::CoreId { id: cpu }) {
        return Ok(());
    }
    let mut set = CpuSet::new();
    if let Err(e) = set.set(cpu) {
        return Err(format!("cpu affinity: cpu {cpu}: {e}"));
    }
    sched_setaffinity(Pid::from_raw(0), &set).map_err(|e| {
        format!(
            "cpu affinity: pinning to cpu {cpu} failed: {e}; fix: the cpu must be in the \
             process's allowed set {} (systemd CPUAffinity=, taskset, cgroup cpuset.cpus)",
            fmt_cpulist(&current_affinity())
        )
    })
}

fn set_fifo(priority: i32) -> Result<(), String> {
    // SAFETY: plain queries without pointers.
    let (min, max) = unsafe {
        (
            libc::sched_get_priority_min(libc::SCHED_FIFO),
            libc::sched_get_priority_max(libc::SCHED_FIFO),
        )
    };
    if priority < min || priority > max {
        return Err(format!(
            "SCHED_FIFO priority {priority}: out of range {min}..={max}; fix: choose a \
             priority in range (above 50, the IRQ threads of a PREEMPT_RT kernel)"
        ));
    }
    // SAFETY: sched_param is plain data; zeroed is a valid value (musl has
    // extra fields).
    let mut param: libc::sched_param = unsafe { std::mem::zeroed() };
    param.sched_priority = priority;
    // SAFETY: pthread_self() is the calling thread; `param` is valid.
    let rc = unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
    if rc == 0 {
        return Ok(());
    }
    let errno = nix::errno::Errno::from_raw(rc);
    let limit = match getrlimit(Resource::RLIMIT_RTPRIO) {
        Ok((soft, hard)) => format!(
            "RLIMIT_RTPRIO soft {} hard {}",
            fmt_rlimit(soft),
            fmt_rlimit(hard)
        ),
        Err(e) => format!("RLIMIT_RTPRIO unreadable ({e})"),
    };
    let cap = if has_capability(CAP_SYS_NICE) == Some(true) {
        "has CAP_SYS_NICE"
    } else {
        "no CAP_SYS_NICE"
    };
    Err(format!(
        "SCHED_FIFO priority {priority}: refused: {errno} ({limit}, {cap}); fix: systemd \
         LimitRTPRIO=99 / ulimit -r 99 / limits.conf rtprio 99, or CAP_SYS_NICE; with cgroup v1 \
         RT group scheduling also give the cgroup cpu.rt_runtime_us > 0"
    ))
}

fn mlock_warning(e: nix::errno::Errno) -> String {
    let limit = match getrlimit(Resource::RLIMIT_MEMLOCK) {
        Ok((soft, hard)) => format!(
            "RLIMIT_MEMLOCK soft {} hard {}",
            fmt_rlimit(soft),
            fmt_rlimit(hard)
        ),
        Err(e) => format!("RLIMIT_MEMLOCK unreadable ({e})"),
    };
    let cap = if has_capability(CAP_IPC_LOCK) == Some(true) {
        "has CAP_IPC_LOCK"
    } else {
        "no CAP_IPC_LOCK"
    };
    format!(
        "memory locking: mlockall(MCL_CURRENT|MCL_FUTURE) refused: {e} ({limit}, {cap}); fix: \
         systemd LimitMEMLOCK=infinity / ulimit -l unlimited / limits.conf memlock unlimited, \
         or CAP_IPC_LOCK"
    )
}

fn num_cpus_configured() -> usize {
    // SAFETY: plain query.
    let n = unsafe { libc::sysconf(libc::_SC_NPROCESSORS_CONF) };
    if n > 0 {
        n as usize
    } else {
        1
    }
}

/// Moves the calling thread off `cpu`: its affinity becomes the CPUs it may
/// use now, minus `cpu`. Returns the CPUs it keeps.
///
/// Why: the kernels this runs on are often not fully preemptible
/// (`PREEMPT_DYNAMIC` in mode none or voluntary, and every non-RT kernel):
/// a normal-priority thread inside a system call on the cycle's CPU delays
/// the real-time thread's wake-up until it reaches a scheduling point,
/// whatever the priorities say. Threads spawned afterwards inherit the
/// mask. Refused (mask unchanged) when `cpu` is the only CPU left.
pub fn keep_off_cpu(cpu: usize) -> Result<Vec<usize>, String> {
    let keep: Vec<usize> = current_affinity()
        .into_iter()
        .filter(|&c| c != cpu)
        .collect();
    if keep.is_empty() {
        return Err(format!(
            "cpu {cpu} is the only CPU this process may use: the non-real-time threads \
             share it with the cycle"
        ));
    }
    let mut set = CpuSet::new();
    for &c in &keep {
        set.set(c)
            .map_err(|e| format!("cpu affinity: cpu {c}: {e}"))?;
    }
    sched_setaffinity(Pid::from_raw(0), &set)
        .map_err(|e| format!("cpu affinity: keeping off cpu {cpu} failed: {e}"))?;
    Ok(keep)
}

/// The calling thread's policy and priority (`pthread_getschedparam`).
pub fn current_sched() -> (SchedPolicy, i32) {
    let mut policy: libc::c_int = -1;
    // SAFETY: zeroed sched_param is valid; pointers are to locals.
    let mut param: libc::sched_param = unsafe { std::mem::zeroed() };
    let rc = unsafe { libc::pthread_getschedparam(libc::pthread_self(), &mut policy, &mut param) };
    if rc == 0 {
        (SchedPolicy::from_raw(policy), param.sched_priority)
    } else {
        (SchedPolicy::Unknown(-1), 0)
    }
}

/// Bytes of stack left below the caller's frame, from the thread's stack
/// bounds (`pthread_getattr_np`).
fn stack_room() -> Option<usize> {
    let marker = 0u8;
    let sp = std::hint::black_box(&marker) as *const u8 as usize;
    // SAFETY: attr is initialised by pthread_getattr_np before use and
    // destroyed afterwards; out-pointers point to locals.
    unsafe {
        let mut attr = MaybeUninit::<libc::pthread_attr_t>::uninit();
        if libc::pthread_getattr_np(libc::pthread_self(), attr.as_mut_ptr()) != 0 {
            return None;
        }
        let mut addr: *mut libc::c_void = std::ptr::null_mut();
        let mut size: libc::size_t = 0;
        let rc = libc::pthread_attr_getstack(attr.as_ptr(), &mut addr, &mut size);
        let mut guard: libc::size_t = 0;
        let _ = libc::pthread_attr_getguardsize(attr.as_ptr(), &mut guard);
        libc::pthread_attr_destroy(attr.as_mut_ptr());
        if rc != 0 {
            return None;
        }
        let low = addr as usize + guard;
        sp.checked_sub(low)
    }
}

/// Headroom left untouched below the prefaulted area (signal frames, the
/// frames of the prefault recursion itself).
const STACK_HEADROOM: usize = 64 * 1024;
const PREFAULT_CHUNK: usize = 16 * 1024;

fn prefault_stack(requested: usize, warnings: &mut Vec<String>) -> usize {
    if requested == 0 {
        return 0;
    }
    let bytes = match stack_room() {
        Some(room) => {
            let usable = room.saturating_sub(STACK_HEADROOM);
            if requested > usable {
                warnings.push(format!(
                    "stack prefault: requested {requested} bytes but only {room} bytes of stack \
                     remain below the caller; prefaulted {usable}; fix: spawn the RT thread with \
                     a bigger stack (std::thread::Builder::stack_size) or request less"
                ));
                usable
            } else {
                requested
            }
        }
        None => {
            warnings.push(format!(
                "stack prefault: requested {requested} bytes but the stack bounds are unknown \
                 (pthread_getattr_np failed); prefaulted nothing"
            ));
            0
        }
    };
    if bytes > 0 {
        touch_stack(bytes, page_size());
    }
    bytes
}

/// Touches `remaining` bytes of stack below the caller, one page at a time,
/// in chunks of [`PREFAULT_CHUNK`] (recursion keeps each frame small).
#[inline(never)]
fn touch_stack(remaining: usize, page: usize) {
    let mut buf = MaybeUninit::<[u8; PREFAULT_CHUNK]>::uninit();
    let p = buf.as_mut_ptr().cast::<u8>();
    let mut off = PREFAULT_CHUNK;
    // Downwards, the direction the stack grows.
    while off > 0 {
        off = off.saturating_sub(page);
        // SAFETY: `off < PREFAULT_CHUNK`, inside `buf`.
        unsafe { std::ptr::write_volatile(p.add(off), 0) };
    }
    if remaining > PREFAULT_CHUNK {
        touch_stack(remaining - PREFAULT_CHUNK, page);
    }
    // Keep `buf` (and so the frame) alive across the recursive call.
    std::hint::black_box(&mut buf);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keep_off_cpu_leaves_the_cycle_cpu_to_the_cycle() {
        // On a thread of its own: the mask is per thread.
        std::thread::spawn(|| {
            let before = current_affinity();
            let cpu = before[0];
            match keep_off_cpu(cpu) {
                Ok(kept) => {
                    assert!(before.len() > 1);
                    assert!(!kept.contains(&cpu));
                    assert_eq!(current_affinity(), kept);
                    // Threads spawned afterwards inherit it.
                    let child = std::thread::spawn(current_affinity).join().unwrap();
                    assert_eq!(child, kept);
                }
                Err(e) => {
                    assert_eq!(before.len(), 1, "{e}");
                    assert_eq!(current_affinity(), before);
                }
            }
        })
        .join()
        .unwrap();
    }

    #[test]
    fn bad_cpu_is_a_warning() {
        let h = std::thread::spawn(|| {
            enter_realtime(&RtConfig {
                cpu: Some(4096),
                priority: 0,
                lock_memory: false,
                prefault_stack: 0,
            })
        });
        let r = h.join().unwrap();
        assert!(
            r.warnings
                .iter()
                .any(|w| w.contains("cpu 4096 does not exist")),
            "{r}"
        );
        assert!(
            r.warnings
                .iter()
                .any(|w| w.contains("priority 0: out of range")),
            "{r}"
        );
        assert_ne!(r.policy, SchedPolicy::Fifo);
    }

    #[test]
    fn prefault_is_clamped_to_the_stack() {
        let h = std::thread::Builder::new()
            .stack_size(256 * 1024)
            .spawn(|| {
                enter_realtime(&RtConfig {
                    cpu: None,
                    priority: 1,
                    lock_memory: false,
                    prefault_stack: 64 * 1024 * 1024,
                })
            })
            .unwrap();
        let r = h.join().unwrap();
        assert!(r.stack_prefaulted < 256 * 1024, "{r}");
        assert!(
            r.warnings.iter().any(|w| w.starts_with("stack prefault")),
            "{r}"
        );
    }

    #[test]
    fn fifo_is_probed_on_a_thread_of_its_own() {
        let err = fifo_allowed(0).unwrap_err();
        assert!(err.contains("priority 0: out of range"), "{err}");
        // as root or with RLIMIT_RTPRIO it is allowed; either way this
        // thread is left as it was
        let _ = fifo_allowed(1);
        assert_ne!(current_sched().0, SchedPolicy::Fifo);
    }

    #[test]
    fn policy_names() {
        assert_eq!(
            SchedPolicy::from_raw(libc::SCHED_FIFO).to_string(),
            "SCHED_FIFO"
        );
        assert_eq!(SchedPolicy::from_raw(libc::SCHED_OTHER), SchedPolicy::Other);
    }
}
