//! Real-time building blocks for the motion supervisor's cycle.
//!
//! The supervisor runs a 1 kHz (or faster) control cycle on Linux, ideally a
//! PREEMPT_RT kernel. A cycle is only as good as its worst wake-up, and the
//! worst wake-ups come from a handful of well-known causes; each module here
//! removes one of them and reports honestly when it cannot.
//!
//! - [`thread`] — [`enter_realtime`]: pin the thread to a CPU, `SCHED_FIFO`,
//!   `mlockall(MCL_CURRENT|MCL_FUTURE)`, prefault the stack. A refused
//!   setting is a warning naming the setting, the value, the errno and the
//!   fix (`LimitRTPRIO=99`, `LimitMEMLOCK=infinity`, ...), never a panic:
//!   the same binary runs on a laptop and on the controller.
//! - [`environment`] — [`check_environment`]: the read-only checklist a
//!   controls engineer runs (PREEMPT_RT, RT throttling, isolated CPU,
//!   rlimits, governor, SMT).
//! - [`timer`] — [`PeriodicTimer`]: `clock_nanosleep(CLOCK_MONOTONIC,
//!   TIMER_ABSTIME)` to *absolute* deadlines, `deadline += period`, so
//!   wake-up latency and work time never accumulate into drift. `EINTR` is
//!   retried with the same absolute deadline (correct by construction,
//!   unlike a relative sleep). Overruns that swallow whole periods are
//!   counted as missed and skipped while keeping the phase — cyclictest
//!   skips them silently; a servo loop must know.
//! - [`host`] — the host in words for a report: kernel, preemption model,
//!   RT throttling, load, other programs' real-time threads.
//! - [`clock`] — [`now_ns`]: `CLOCK_MONOTONIC` in `u64` nanoseconds.
//! - [`rt_pool`] + [`RtAllocator`] + [`counting`] — no system-allocator
//!   calls in the cycle. glibc `malloc` can take a lock, `mmap`/`brk` and
//!   page-fault: unbounded latency. We use iceoryx2 0.10 for IPC, whose
//!   `loan_uninit` allocates one `Rc` per sample (measured), so "just don't
//!   allocate" is not an option. Instead the binary installs [`RtAllocator`]
//!   as `#[global_allocator]`; the RT thread calls [`rt_pool::enter`] at
//!   start-up and from then on its allocations come from its own
//!   pre-mapped, prefaulted, locked TLSF pool in constant time. A sample's
//!   `Rc` may be dropped on another thread: frees are routed by address, and
//!   a foreign thread hands the block back through a lock-free list instead
//!   of a lock (a lock held by a preempted normal thread would stall the RT
//!   thread — priority inversion). [`counting::system_calls_on_this_thread`]
//!   and [`rt_pool::stats`] make the rule testable: the count across the
//!   cycle must be 0.
//!
//! Typical start-up of the RT thread:
//!
//! ```no_run
//! use motion_rt::{enter_realtime, rt_pool, PeriodicTimer, RtConfig};
//!
//! let cfg = RtConfig { cpu: Some(1), priority: 80, ..RtConfig::default() };
//! let report = enter_realtime(&cfg);
//! for w in &report.warnings {
//!     eprintln!("rt: {w}");
//! }
//! rt_pool::enter(4 << 20).expect("RT pool");
//! let mut timer = PeriodicTimer::new(1_000_000);
//! loop {
//!     let wake = timer.wait();
//!     // ... cycle: no System allocations, no locks, no I/O ...
//! #   let _ = wake;
//! #   break;
//! }
//! ```

#![warn(missing_docs)]

mod allocator;
pub mod clock;
pub mod counting;
pub mod environment;
pub mod host;
pub mod logging;
pub mod pm_qos;
mod pool;
mod procfs;
mod remote_free;
pub mod termination;
pub mod thread;
pub mod timer;

pub use allocator::RtAllocator;
pub use clock::now_ns;
pub use environment::check_environment;
pub use pm_qos::{hold_cpu_dma_latency, DmaLatencyGuard};
pub use thread::{
    enter_realtime, fifo_allowed, keep_off_cpu, pin_to_cpu, RtConfig, RtReport, SchedPolicy,
};
pub use timer::{PeriodicTimer, Wakeup};

/// Per-thread real-time memory pools (see [`RtAllocator`]).
///
/// A thread calls [`enter`](rt_pool::enter) once, outside its cycle; its
/// allocations are then served from its own TLSF pool. Frees may happen on
/// any thread. [`stats`](rt_pool::stats) / [`thread_stats`](rt_pool::thread_stats)
/// expose the counters that prove the cycle never reached the system
/// allocator.
pub mod rt_pool {
    pub use crate::pool::{
        current_pool, drain_remote_frees, enter, leave, slot_stats, stats, thread_stats, PoolError,
        PoolInfo, PoolStats, MAX_POOLS, MIN_POOL_BYTES,
    };
}
