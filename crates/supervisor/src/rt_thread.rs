//! The real-time thread: pinned, SCHED_FIFO, its own allocation pool, one
//! absolute deadline per cycle.
//!
//! One cycle:
//! 1. sleep to the absolute deadline (`clock_nanosleep`, TIMER_ABSTIME);
//! 2. take control requests (lock-free queue);
//! 3. take the newest feedback frame (zero-copy sample);
//! 4. step every axis's homing engine; publish the command frame and notify;
//! 5. wait — at most until half the period — for the I/O process's answer to
//!    *this* command: that is the I/O round trip, and the answer is the
//!    feedback of the next cycle;
//! 6. record wake-up latency, compute time and round trip; now and then hand
//!    a histogram set and a status snapshot to the reporting thread.
//!
//! No formatting, no locks, no system-allocator calls in the loop: what
//! iceoryx2 allocates (one `Rc` per loaned sample) comes from this thread's
//! TLSF pool. The count of system-allocator calls after warm-up is published
//! for the no-allocation test.

use crate::core::Core;
use crate::shared::{Phase, Shared};
use crate::stats::HistSet;
use motion_config::MachineConfig;
use motion_frames::{FeedbackFrame, IpcConfig, SupervisorPorts};
use motion_rt::{counting, enter_realtime, now_ns, rt_pool, PeriodicTimer, RtConfig, RtReport};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::thread::JoinHandle;

pub struct RtSettings {
    pub machine: MachineConfig,
    pub service_prefix: String,
    pub rt: RtConfig,
    /// Bytes of the thread's allocation pool.
    pub pool_bytes: usize,
    /// Answered cycles after which measuring starts (connection set-up,
    /// first-time mappings are excluded from histograms and allocation counts).
    pub warmup_frames: u64,
    /// Cycles per histogram hand-off.
    pub stats_every: u64,
    /// Cycles per status snapshot.
    pub snapshot_every: u64,
    /// How long after the deadline the cycle waits for the I/O answer.
    pub reply_budget_ns: u64,
}

impl RtSettings {
    pub fn new(machine: MachineConfig, service_prefix: String) -> Self {
        let sup = &machine.supervisor;
        let period = sup.cycle_ns();
        let rt = RtConfig {
            cpu: Some(sup.cpu),
            priority: sup.priority,
            lock_memory: sup.lock_memory,
            ..RtConfig::default()
        };
        Self {
            rt,
            service_prefix,
            pool_bytes: 4 << 20,
            warmup_frames: 100,
            stats_every: (1_000_000_000 / period).max(1),
            snapshot_every: (10_000_000 / period).max(1),
            reply_budget_ns: period / 2,
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
            let out = body(settings, &shared);
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

fn body(s: RtSettings, shared: &Shared) -> RtOutcome {
    block_signals();
    let report = enter_realtime(&s.rt);
    let mut out = RtOutcome {
        report: Some(report),
        error: None,
        cycles: 0,
        pool: None,
    };
    let ipc = IpcConfig::new(s.service_prefix.clone());
    let node = match ipc.create_node("motion-supervisor") {
        Ok(n) => n,
        Err(e) => {
            out.error = Some(e.to_string());
            return out;
        }
    };
    let mut ports = match SupervisorPorts::create(&node, &s.service_prefix) {
        Ok(p) => p,
        Err(e) => {
            out.error = Some(e.to_string());
            return out;
        }
    };
    let mut core = Core::new(&s.machine);
    let mut hist = shared
        .stats_free
        .pop()
        .unwrap_or_else(|| Box::new(HistSet::new()));
    if let Err(e) = rt_pool::enter(s.pool_bytes) {
        out.error = Some(format!("real-time allocation pool: {e:?}"));
        return out;
    }
    shared.set_phase(Phase::Running);

    let period = s.machine.supervisor.cycle_ns();
    let mut timer = PeriodicTimer::new(period);
    let mut pending: Option<
        iceoryx2::sample::Sample<iceoryx2::service::ipc::Service, FeedbackFrame, ()>,
    > = None;
    let mut pending_fresh = false;
    let mut answered: u64 = 0;
    let mut baseline: Option<(u64, u64)> = None;
    let mut cycle: u64 = 0;

    loop {
        let wake = timer.wait();
        cycle += 1;

        // Bounded: the queue holds at most 256 requests.
        while let Some(c) = shared.control.pop() {
            core.control(c);
        }

        match ports.receive_latest() {
            Ok(Some(sample)) => {
                pending = Some(sample);
                pending_fresh = true;
            }
            Ok(None) => {}
            Err(_) => core.note_rejected(),
        }
        let fresh = if pending_fresh {
            pending.as_ref().map(|p| p.payload())
        } else {
            None
        };
        core.step(wake.deadline_ns, fresh);
        pending_fresh = false;

        // Wake-ups left over from an answer that came after last cycle's
        // budget would end the wait below at once: clear them first.
        let _ = ports.try_wait();
        let t_send = now_ns();
        let sent = ports.publish(|f| core.fill(f));
        let _ = ports.notify();
        let t_published = now_ns();

        let mut roundtrip = None;
        if let Ok(sent) = sent {
            core.sent(sent.sequence);
            let budget_end = wake.deadline_ns + s.reply_budget_ns;
            // At most a few wake-ups per cycle (a stray one, then ours).
            for _ in 0..4 {
                match ports.wait_until(budget_end) {
                    Ok(true) | Err(_) => {
                        if let Ok(Some(sample)) = ports.receive_latest() {
                            let answers = sample.payload().answers_sequence;
                            pending = Some(sample);
                            pending_fresh = true;
                            if answers == sent.sequence {
                                roundtrip = Some(now_ns() - t_send);
                                break;
                            }
                        }
                    }
                    Ok(false) => break,
                }
            }
        }
        if roundtrip.is_some() {
            answered += 1;
        }

        let measuring = baseline.is_some();
        if measuring {
            hist.wakeup.saturating_record(wake.latency_ns.max(1));
            hist.compute
                .saturating_record((t_published - wake.woke_ns).max(1));
            match roundtrip {
                Some(rt) => hist.roundtrip.saturating_record(rt.max(1)),
                None => hist.late_replies += 1,
            }
            if wake.missed > 0 || t_published > wake.deadline_ns + period {
                hist.deadline_misses += 1;
            }
            if hist.start_ns == 0 {
                hist.start_ns = wake.deadline_ns;
            }
            hist.end_ns = wake.deadline_ns;
            hist.cycles += 1;
        } else if answered >= s.warmup_frames {
            baseline = Some((
                counting::system_calls_on_this_thread(),
                rt_pool::thread_stats().map_or(0, |p| p.pool_allocs),
            ));
            shared.measuring.store(true, Ordering::Release);
        }

        if cycle % s.snapshot_every == 0 || core.exiting() {
            if let Some(mut snap) = shared.snap_free.pop() {
                core.snapshot(wake.deadline_ns, &mut snap);
                if let Err(snap) = shared.snap_full.push(snap) {
                    recycle(&shared.snap_free, snap);
                }
            }
        }
        let done = core.exit_done();
        if cycle % s.stats_every == 0 || done {
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
