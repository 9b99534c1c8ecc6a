//! The real-time thread: pinned, SCHED_FIFO, its own allocation pool, one
//! absolute deadline per cycle.
//!
//! One cycle:
//! 1. sleep to the absolute deadline (`clock_nanosleep`, TIMER_ABSTIME);
//! 2. take control requests (lock-free queue), answer them (lock-free queue);
//! 3. take the newest feedback frame of every I/O process — the answer to
//!    the previous cycle's command, which arrived while we slept;
//! 4. step every axis's homing engine and the home sequences;
//! 5. publish one command frame per I/O process and notify each;
//! 6. record wake-up latency and compute time (and the I/O round trip, from
//!    the answer's own timestamp: command published → answer published);
//!    now and then hand a histogram set and a status snapshot over.
//!
//! Nothing waits for an answer: a cycle does its bounded work and goes back
//! to sleep, so a slow I/O process can never push the next wake-up late (it
//! shows as a gap in its answers instead, which the feedback-loss rule
//! judges). This is how fieldbus masters run: outputs at the start of the
//! cycle, inputs collected at the start of the next.
//!
//! No formatting, no locks, no system-allocator calls in the loop: what
//! iceoryx2 allocates (one `Rc` per loaned sample) comes from this thread's
//! TLSF pool. The count of system-allocator calls after warm-up is published
//! for the no-allocation test.

use crate::core::Core;
use crate::shared::{Phase, Shared, MAX_IOS};
use crate::stats::HistSet;
use motion_config::MachineConfig;
use motion_frames::FeedbackFrame;
use motion_ipc::{Domain, IpcError, SupervisorPorts};
use motion_rt::{counting, enter_realtime, now_ns, rt_pool, PeriodicTimer, RtConfig, RtReport};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::thread::JoinHandle;

pub struct RtSettings {
    pub machine: MachineConfig,
    pub domain: Domain,
    pub rt: RtConfig,
    /// Bytes of the thread's allocation pool.
    pub pool_bytes: usize,
    /// Cycles with every I/O process attached after which measuring starts
    /// (connection set-up and first-time mappings are excluded from the
    /// histograms and the allocation counts).
    pub warmup_cycles: u64,
    /// Cycles after which measuring starts anyway (I/O processes missing).
    pub warmup_limit: u64,
    /// Cycles per histogram hand-off.
    pub stats_every: u64,
    /// Cycles per status snapshot.
    pub snapshot_every: u64,
}

impl RtSettings {
    pub fn new(machine: MachineConfig, domain: Domain) -> Self {
        let sup = &machine.supervisor;
        let period = sup.cycle_ns();
        let rt = RtConfig {
            cpu: Some(sup.cpu),
            priority: sup.priority,
            lock_memory: sup.lock_memory,
            ..RtConfig::default()
        };
        let per_s = (1_000_000_000 / period).max(1);
        Self {
            rt,
            domain,
            pool_bytes: 4 << 20,
            warmup_cycles: 100,
            warmup_limit: 2 * per_s,
            stats_every: per_s,
            snapshot_every: (10_000_000 / period).max(1),
            machine,
        }
    }
}

/// How the thread ended.
#[derive(Debug)]
pub struct RtOutcome {
    pub report: Option<RtReport>,
    pub error: Option<String>,
    pub cycles: u64,
    pub pool: Option<rt_pool::PoolStats>,
}

pub fn spawn(settings: RtSettings, shared: Arc<Shared>) -> std::io::Result<JoinHandle<RtOutcome>> {
    std::thread::Builder::new()
        .name("motion-rt".into())
        .stack_size(1 << 20)
        .spawn(move || {
            // A panic must not leave the phase at Running: the main thread
            // would wait for a cycle that no longer runs. (The drives are
            // then stopped by motion-io's watchdog: commands stop.)
            let out =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| body(settings, &shared)))
                    .unwrap_or_else(|_| RtOutcome {
                        report: None,
                        error: Some("the real-time thread panicked".into()),
                        cycles: 0,
                        pool: None,
                    });
            shared.set_phase(if out.error.is_some() {
                Phase::Failed
            } else {
                Phase::Exited
            });
            out
        })
}

/// SIGINT/SIGTERM are the main thread's business: keep them away from the
/// sleeping real-time thread.
fn block_signals() {
    use nix::sys::signal::{pthread_sigmask, SigSet, SigmaskHow, Signal};
    let mut set = SigSet::empty();
    set.add(Signal::SIGINT);
    set.add(Signal::SIGTERM);
    let _ = pthread_sigmask(SigmaskHow::SIG_BLOCK, Some(&set), None);
}

type FeedbackSample = iceoryx2::sample::Sample<iceoryx2::service::ipc::Service, FeedbackFrame, ()>;

fn body(s: RtSettings, shared: &Shared) -> RtOutcome {
    block_signals();
    let report = enter_realtime(&s.rt);
    let mut out = RtOutcome {
        report: Some(report),
        error: None,
        cycles: 0,
        pool: None,
    };
    let node = match s.domain.create_node("motion-supervisor") {
        Ok(n) => n,
        Err(e) => {
            out.error = Some(e.to_string());
            return out;
        }
    };
    let mut ports: Vec<SupervisorPorts> = Vec::with_capacity(s.machine.ios.len());
    for io in &s.machine.ios {
        match SupervisorPorts::create(&node, &s.domain, &io.name) {
            Ok(p) => ports.push(p),
            Err(e) => {
                out.error = Some(format!("I/O process {}: {e}", io.name));
                return out;
            }
        }
    }
    let n_io = ports.len().min(MAX_IOS);
    let mut core = Core::new(&s.machine);
    let mut hist = shared
        .stats_free
        .pop()
        .unwrap_or_else(|| Box::new(HistSet::new()));
    let mut pending: Vec<Option<FeedbackSample>> = (0..n_io).map(|_| None).collect();
    if let Err(e) = rt_pool::enter(s.pool_bytes) {
        out.error = Some(format!("real-time allocation pool: {e:?}"));
        return out;
    }
    shared.set_phase(Phase::Running);

    let period = s.machine.supervisor.cycle_ns();
    let mut timer = PeriodicTimer::new(period);
    let mut attached_cycles: u64 = 0;
    // What the previous cycle did, for the worst wake-ups.
    let mut prev = crate::stats::LateCycle::default();
    let mut prev_end_ns: u64 = 0;
    let mut baseline: Option<(u64, u64)> = None;
    let mut cycle: u64 = 0;

    loop {
        let wake = timer.wait();
        cycle += 1;

        // Bounded: the queue holds at most 256 requests.
        while let Some(c) = shared.control.pop() {
            if let Some(ack) = core.control(c, wake.deadline_ns) {
                // The answering side drains this queue every few ms; if it
                // is full the requester times out and says so.
                let _ = shared.acks.push(ack);
            }
        }

        let mut frames: [Option<&FeedbackFrame>; MAX_IOS] = [None; MAX_IOS];
        for k in 0..n_io {
            pending[k] = match ports[k].receive_latest() {
                Ok(sample) => sample,
                Err(IpcError::Forged { .. } | IpcError::Layout { .. }) => {
                    core.note_refused(k);
                    None
                }
                Err(_) => None,
            };
        }
        for (slot, p) in frames.iter_mut().zip(&pending) {
            *slot = p.as_ref().map(|s| s.payload());
        }
        // Woke more than a quarter cycle late (or missed a deadline): the CPU the
        // I/O process shares was taken away too, and this thread, of higher
        // priority, runs first when it comes back.
        let stalled = wake.missed > 0 || wake.latency_ns > period / 4;
        let info = core.step(wake.deadline_ns, stalled, &frames[..n_io]);
        // Release the shared-memory samples before the next receive.
        for p in pending.iter_mut() {
            *p = None;
        }

        for (k, port) in ports.iter_mut().enumerate() {
            if let Ok(sent) = port.publish(|f| core.fill(k, f)) {
                core.sent(k, sent.sequence, now_ns());
            }
            let _ = port.notify();
        }
        let t_published = now_ns();
        if let Some(r) = core.trace_record() {
            if shared.trace.push(r).is_err() {
                shared.trace_dropped.fetch_add(1, Ordering::Relaxed);
            }
        }

        if core.all_attached() {
            attached_cycles += 1;
        }
        if baseline.is_some() {
            hist.note_late(crate::stats::LateCycle {
                latency_ns: wake.latency_ns,
                deadline_ns: wake.deadline_ns,
                prev_slack_ns: wake.deadline_ns as i64 - prev_end_ns as i64,
                ..prev
            });
            prev.prev_compute_ns = t_published.saturating_sub(wake.woke_ns);
            prev.prev_snapshot = false;
            prev.prev_stats = false;
            hist.wakeup.saturating_record(wake.latency_ns.max(1));
            hist.compute
                .saturating_record(t_published.saturating_sub(wake.woke_ns).max(1));
            if let Some(rt) = info.roundtrip_ns {
                hist.roundtrip.saturating_record(rt.max(1));
            }
            hist.late_replies += u64::from(info.late_replies);
            if wake.missed > 0 || t_published > wake.deadline_ns + period {
                hist.deadline_misses += 1;
            }
            if hist.start_ns == 0 {
                hist.start_ns = wake.deadline_ns;
            }
            hist.end_ns = wake.deadline_ns;
            hist.cycles += 1;
        } else if attached_cycles >= s.warmup_cycles || cycle >= s.warmup_limit {
            baseline = Some((
                counting::system_calls_on_this_thread(),
                rt_pool::thread_stats().map_or(0, |p| p.pool_allocs),
            ));
            shared.measuring.store(true, Ordering::Release);
        }

        if cycle % s.snapshot_every == 0 || core.exiting() {
            prev.prev_snapshot = true;
            if let Some(mut snap) = shared.snap_free.pop() {
                core.snapshot(wake.deadline_ns, &mut snap);
                if let Err(snap) = shared.snap_full.push(snap) {
                    recycle(&shared.snap_free, snap);
                }
            }
        }
        let done = core.exit_done();
        if cycle % s.stats_every == 0 || done {
            prev.prev_stats = true;
            if let Some(fresh) = shared.stats_free.pop() {
                let full = std::mem::replace(&mut hist, fresh);
                if let Err(full) = shared.stats_full.push(full) {
                    recycle(&shared.stats_free, full);
                }
            }
            if let Some((sys0, pool0)) = baseline {
                let sys = counting::system_calls_on_this_thread() - sys0;
                let pool = rt_pool::thread_stats().map_or(0, |p| p.pool_allocs) - pool0;
                shared.system_calls_in_cycle.store(sys, Ordering::Release);
                shared.pool_allocs_in_cycle.store(pool, Ordering::Release);
            }
        }
        if done {
            break;
        }
        prev_end_ns = now_ns();
    }
    out.cycles = cycle;
    out.pool = rt_pool::thread_stats();
    // Tear down outside the loop: releasing iceoryx2 resources allocates.
    drop(pending);
    drop(ports);
    drop(node);
    out
}

/// Puts a box back into circulation; never frees it on this thread (a free
/// of memory from the system allocator would be a system call in the cycle).
fn recycle<T>(queue: &crossbeam::queue::ArrayQueue<Box<T>>, b: Box<T>) {
    if let Err(b) = queue.push(b) {
        // Cannot happen: every queue has room for all boxes in circulation.
        std::mem::forget(b);
    }
}
