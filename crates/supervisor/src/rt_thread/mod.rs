//! The real-time thread: pinned, SCHED_FIFO, its own allocation pool, one
//! absolute deadline per cycle.
//!
//! One cycle (`run` reads as this list):
//! 1. sleep to the absolute deadline (`clock_nanosleep`, TIMER_ABSTIME);
//! 2. take control requests (lock-free queue), answer them (lock-free
//!    queue): `control_queue`; then every setpoint frame programs
//!    published since the last cycle (a bounded drain of the setpoint
//!    subscriber, checked by the core's intake): `setpoints`;
//! 3. take the newest feedback frame of every I/O process — the answer to
//!    the previous cycle's command, which arrived while we slept:
//!    `IoPorts::receive`;
//! 4. step every axis's homing engine and the home sequences: `Core::step`
//!    (`IoPorts::step`), then answer the operations the engines judged in
//!    that step: `answers`;
//! 5. publish one command frame per I/O process and notify each:
//!    `IoPorts::publish`;
//! 6. record wake-up latency and compute time (and the I/O round trip, from
//!    the answer's own timestamp: command published → answer published);
//!    now and then hand a histogram set and a status snapshot over
//!    (`record.rs`: `Recorder`).
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

mod record;
mod setpoints;

use crate::core::{Core, CycleInfo};
use crate::shared::{Phase, Shared, MAX_IOS};
use motion_config::MachineConfig;
use motion_frames::FeedbackFrame;
use motion_ipc::{Domain, IpcError, SetpointSubscriber, SupervisorPorts};
use motion_rt::{enter_realtime, now_ns, rt_pool, PeriodicTimer, RtConfig, RtReport};
use record::Recorder;
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
type Node = iceoryx2::node::Node<iceoryx2::service::ipc::Service>;

fn body(s: RtSettings, shared: &Shared) -> RtOutcome {
    block_signals();
    let mut out = RtOutcome {
        report: Some(enter_realtime(&s.rt)),
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
    let mut io = match IoPorts::open(&node, &s) {
        Ok(io) => io,
        Err(e) => {
            out.error = Some(e);
            return out;
        }
    };
    let mut sp = match SetpointSubscriber::create(&node, &s.domain) {
        Ok(sp) => sp,
        Err(e) => {
            out.error = Some(format!("setpoint stream: {e}"));
            return out;
        }
    };
    let mut core = Core::new(&s.machine).with_session_key(s.domain.key);
    let mut rec = Recorder::new(&s, shared);
    if let Err(e) = rt_pool::enter(s.pool_bytes) {
        out.error = Some(format!("real-time allocation pool: {e:?}"));
        return out;
    }
    shared.set_phase(Phase::Running);
    out.cycles = run(&s, shared, &mut core, &mut io, &mut sp, &mut rec);
    out.pool = rt_pool::thread_stats();
    // Tear down outside the loop: releasing iceoryx2 resources allocates.
    drop(sp);
    drop(io);
    drop(node);
    out
}

/// The loop, one cycle per deadline, until leaving is complete; returns the
/// cycles run.
fn run(
    s: &RtSettings,
    shared: &Shared,
    core: &mut Core,
    io: &mut IoPorts,
    sp: &mut SetpointSubscriber,
    rec: &mut Recorder,
) -> u64 {
    let period = s.machine.supervisor.cycle_ns();
    let mut timer = PeriodicTimer::new(period);
    let mut cycle: u64 = 0;
    loop {
        let wake = timer.wait();
        cycle += 1;
        control_queue(shared, core, sp, wake.deadline_ns);
        setpoints::receive(sp, core);
        io.receive(core);
        // Woke more than a quarter cycle late (or missed a deadline): the CPU the
        // I/O process shares was taken away too, and this thread, of higher
        // priority, runs first when it comes back.
        let stalled = wake.missed > 0 || wake.latency_ns > period / 4;
        let info = io.step(core, wake.deadline_ns, stalled);
        io.publish(core);
        answers(shared, core);
        let t_published = now_ns();
        trace_record(shared, core);
        rec.cycle(
            shared,
            &wake,
            t_published,
            &info,
            core.all_attached(),
            cycle,
        );
        if cycle % s.snapshot_every == 0 || core.exiting() {
            rec.snapshot_handed_over();
            hand_over_snapshot(shared, core, wake.deadline_ns);
        }
        let done = core.exit_done();
        if cycle % s.stats_every == 0 || done {
            rec.hand_over(shared);
        }
        if done {
            return cycle;
        }
        rec.asleep(now_ns());
    }
}

/// Takes every request of the control queue and answers each one (an
/// operation only after the step its engines judge it in: `answers`); a
/// request the control thread has given up on is dropped unapplied (it
/// told its client so: `Shared::admit`). Bounded: the queue holds at most
/// 256 requests.
fn control_queue(shared: &Shared, core: &mut Core, sp: &mut SetpointSubscriber, now_ns: u64) {
    while let Some(c) = shared.control.pop() {
        if !shared.admit(&c) {
            continue;
        }
        setpoints::before(sp, &c);
        if let Some(ack) = core.control(c, now_ns) {
            // The answering side drains this queue every few ms; if it
            // is full the requester times out and says so.
            let _ = shared.acks.push(ack);
        }
    }
}

/// The answers of the operations the engines judged in this cycle's step.
fn answers(shared: &Shared, core: &mut Core) {
    core.answers(|ack| {
        let _ = shared.acks.push(ack);
    });
}

/// This cycle's trace record, if a trace is recording, to the control
/// thread (counted when the queue is full).
fn trace_record(shared: &Shared, core: &Core) {
    if let Some(r) = core.trace_record() {
        if shared.trace.push(r).is_err() {
            shared.trace_dropped.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// A status snapshot to the control thread, in a box from the free queue.
fn hand_over_snapshot(shared: &Shared, core: &Core, now_ns: u64) {
    if let Some(mut snap) = shared.snap_free.pop() {
        core.snapshot(now_ns, &mut snap);
        if let Err(snap) = shared.snap_full.push(snap) {
            recycle(&shared.snap_free, snap);
        }
    }
}

/// The frame ports of every I/O process, and the samples received in this
/// cycle (held until the step has read them, released before the next
/// receive).
struct IoPorts {
    ports: Vec<SupervisorPorts>,
    pending: Vec<Option<FeedbackSample>>,
}

impl IoPorts {
    fn open(node: &Node, s: &RtSettings) -> Result<Self, String> {
        let mut ports: Vec<SupervisorPorts> = Vec::with_capacity(s.machine.ios.len());
        for io in &s.machine.ios {
            let p = SupervisorPorts::create(node, &s.domain, &io.name)
                .map_err(|e| format!("I/O process {}: {e}", io.name))?;
            ports.push(p);
        }
        let n_io = ports.len().min(MAX_IOS);
        Ok(Self {
            ports,
            pending: (0..n_io).map(|_| None).collect(),
        })
    }

    /// The newest feedback frame of every I/O process: the answer to the
    /// previous command, which arrived while the thread slept.
    fn receive(&mut self, core: &mut Core) {
        for (k, (port, slot)) in self.ports.iter_mut().zip(&mut self.pending).enumerate() {
            *slot = match port.receive_latest() {
                Ok(sample) => sample,
                Err(IpcError::Forged { .. } | IpcError::Layout { .. }) => {
                    core.note_refused(k);
                    None
                }
                Err(_) => None,
            };
        }
    }

    /// The core's step on the frames received; the samples are released.
    fn step(&mut self, core: &mut Core, now_ns: u64, stalled: bool) -> CycleInfo {
        let mut frames: [Option<&FeedbackFrame>; MAX_IOS] = [None; MAX_IOS];
        for (f, p) in frames.iter_mut().zip(&self.pending) {
            *f = p.as_ref().map(|s| s.payload());
        }
        let n_io = self.pending.len();
        let info = core.step(now_ns, stalled, &frames[..n_io]);
        for p in self.pending.iter_mut() {
            *p = None;
        }
        info
    }

    /// Every I/O process's command frame, published and notified.
    fn publish(&mut self, core: &mut Core) {
        for (k, port) in self.ports.iter_mut().enumerate() {
            if let Ok(sent) = port.publish(|f| core.fill(k, f)) {
                core.sent(k, sent.sequence, now_ns());
            }
            let _ = port.notify();
        }
    }
}

/// Puts a box back into circulation; never frees it on this thread (a free
/// of memory from the system allocator would be a system call in the cycle).
fn recycle<T>(queue: &crossbeam::queue::ArrayQueue<Box<T>>, b: Box<T>) {
    if let Err(b) = queue.push(b) {
        // Cannot happen: every queue has room for all boxes in circulation.
        std::mem::forget(b);
    }
}
