//! What crosses between the real-time thread and the rest of the process.
//!
//! Only `crossbeam::queue::ArrayQueue`s: bounded, preallocated, lock-free in
//! both directions. A crossbeam *channel* would be simpler, but a sender may
//! have to lock the channel's waker list to wake a blocked receiver, and that
//! lock could be held by a preempted normal-priority thread. Here nobody ever
//! blocks on a queue: the other side polls.
//!
//! Large objects (histogram sets, snapshots) travel as `Box`es that circulate
//! between a `full` and a `free` queue, so the real-time thread moves a pointer
//! and never allocates or frees. Small ones (requests, acknowledgements,
//! trace records) travel by value.

use crate::stats::HistSet;
use crossbeam::queue::ArrayQueue;
use motion_frames::MAX_AXES;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, Ordering};

/// Most I/O processes (the config's limit).
pub const MAX_IOS: usize = 16;

/// A request to the real-time thread: what is asked, the id its answer
/// carries, and the deadline after which it is never applied.
///
/// The control thread waits for the answer until the deadline and then
/// tells its client that nothing was applied — which must stay true, or a
/// client retrying `move --by` after "the cycle did not answer" would move
/// twice. So the cycle refuses a request past its deadline without any
/// effect ([`Ack::expired`], `Core::control`), and, because the cycle's
/// clock may lag (a wake-up late, a thread stopped between reading the
/// clock and acting), the one request the control thread waits for also
/// passes a [`Gate`]: whichever of the cycle (taking it) and the control
/// thread (giving up on it) comes first decides, atomically.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Control {
    /// Echoed in the answer ([`Ack::id`]); 0 for [`Ask::Exit`], which is
    /// not answered.
    pub id: u32,
    /// `CLOCK_MONOTONIC` ns after which the cycle refuses it without
    /// effect; [`NO_DEADLINE`] for what nobody waits for with a timeout
    /// (the keeper's restore, leaving).
    pub deadline_ns: u64,
    pub ask: Ask,
}

/// [`Control::deadline_ns`] of a request that never expires (never gated).
pub const NO_DEADLINE: u64 = u64::MAX;

impl Control {
    /// `ask` with no deadline (and not gated): for requests whose sender
    /// takes the answer whenever it comes.
    pub fn undated(id: u32, ask: Ask) -> Self {
        Control {
            id,
            deadline_ns: NO_DEADLINE,
            ask,
        }
    }

    /// Passes through the [`Gate`]: a request someone waits for until its
    /// deadline.
    pub fn gated(&self) -> bool {
        self.deadline_ns != NO_DEADLINE
    }
}

/// What a request asks of the cycle. `mask` bit `i` = axis `i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Ask {
    /// Home the axes of `mask`: in home order (config order one at a time
    /// when no axis has one), or all at once with `parallel`. `timeout_ns`
    /// (0 = none) stops what is still homing after that long.
    Home {
        mask: u64,
        parallel: bool,
        timeout_ns: u64,
    },
    /// Stop (MAS) the axes of `mask`.
    Stop { mask: u64 },
    /// Clear HomedStatus of the axes of `mask`.
    Unhome { mask: u64 },
    /// Record every cycle of the next homing of axis `axis`.
    Trace { axis: usize },
    /// Apply the stored raw → axis `offset` of absolute axis `axis`, with
    /// the `shift` redefine position had added to it, without motion
    /// ([`motion_homing::Axis::restore_reference`]).
    Restore {
        axis: usize,
        offset: f64,
        shift: f64,
    },
    /// Stop every axis, disable the drives once at rest, then leave the loop.
    Exit,
    /// An operation for every axis of `mask` (a gantry: all its sides),
    /// delivered to their engines in the same cycle and answered after that
    /// cycle's step with each engine's answer; carried as the client gave
    /// it (each engine fills what was left out from its configuration).
    /// `token` names a hold-to-run operation (a jog) for its renewals.
    Op {
        mask: u64,
        op: motion_homing::Operation,
        token: u64,
    },
    /// Renew (or with `end`, end) the jog `token` on the axes of `mask`
    /// (0: wherever it runs).
    JogRenew { token: u64, mask: u64, end: bool },
    /// `token` takes the axes of `mask` over for the setpoint stream (all
    /// of them or none).
    StreamAcquire { mask: u64, token: u64 },
    /// The stream of `token` ends (released, or its owner is gone): its
    /// axes stop.
    StreamRelease { token: u64 },
}

/// Who decided the fate of the request the control thread waits for: the
/// cycle taking it ([`Gate::take`]) or the control thread giving up on it
/// ([`Gate::abandon`]) — one atomic word (the id and its state), so the
/// two can never both win, whatever either thread's clock says or however
/// long either is stopped between its decision and its effect. The
/// control thread waits for one request at a time.
#[derive(Debug, Default)]
pub struct Gate(AtomicU64);

impl Gate {
    const PENDING: u64 = 1;
    const TAKEN: u64 = 2;
    const ABANDONED: u64 = 3;

    fn word(id: u32, state: u64) -> u64 {
        u64::from(id) << 8 | state
    }

    /// Control thread, before sending request `id`: it is pending.
    pub fn offer(&self, id: u32) {
        self.0
            .store(Self::word(id, Self::PENDING), Ordering::Release);
    }

    /// Request `id`, still pending, is now `state`; false when it was not
    /// pending (the other side decided first, or it is not the one).
    fn decide(&self, id: u32, state: u64) -> bool {
        let (pending, decided) = (Self::word(id, Self::PENDING), Self::word(id, state));
        (self.0)
            .compare_exchange(pending, decided, Ordering::AcqRel, Ordering::Acquire)
            .is_ok()
    }

    /// Cycle: takes request `id` to apply it; false when the control thread
    /// gave up on it first (or has moved on to another): drop it unapplied.
    pub fn take(&self, id: u32) -> bool {
        self.decide(id, Self::TAKEN)
    }

    /// Control thread, at the deadline: gives up on request `id`; true when
    /// the cycle had not taken it (it never will), false when it had (its
    /// answer will come).
    pub fn abandon(&self, id: u32) -> bool {
        self.decide(id, Self::ABANDONED)
    }
}

/// Why the cycle refused a request for one axis: the domain's words. The
/// control thread turns them into the control service's reasons (the wire
/// has numbers for them; the cycle never sees those).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Refusal {
    /// Homing is in process on the axis (or its rising edge is pending).
    AlreadyHoming,
    /// Its I/O process is not attached.
    IoNotAttached,
    /// The Home instruction refuses, with its ERR / EXERR (an illegal
    /// homing configuration: ERR 41).
    Instruction { err: u16, exerr: u16 },
    /// The supervisor is shutting down.
    Exiting,
    /// A home sequence runs on the axis (or no sequence can start now).
    Busy,
    /// Nothing was started: another axis of the request was refused.
    NotStarted,
    /// The stored reference was not applied (`Restore`).
    Restore(motion_homing::RestoreRefusal),
    /// A program owns the axis (setpoint stream): ERR 3.
    Owned,
    /// No jog or stream of the request's token runs on the axis.
    Token,
    /// The engine refused the operation, with the instruction's ERR / EXERR.
    Operation { err: u16, exerr: u16 },
}

/// The answer for one axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AxisAck {
    /// The request did not name the axis.
    #[default]
    NotNamed,
    Accepted,
    Refused(Refusal),
}

impl AxisAck {
    pub fn accepted(&self) -> bool {
        *self == AxisAck::Accepted
    }
}

/// The real-time thread's answer to a request with an id.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ack {
    pub id: u32,
    /// The cycle that applied the request.
    pub cycle: u64,
    pub axes: [AxisAck; MAX_AXES],
    /// The engine's operation id of each accepted operation (0 otherwise).
    pub op_ids: [u32; MAX_AXES],
    /// It reached the cycle after its deadline and was not applied at all.
    pub expired: bool,
}

impl Ack {
    pub fn new(id: u32) -> Self {
        Self {
            id,
            cycle: 0,
            axes: [AxisAck::default(); MAX_AXES],
            op_ids: [0; MAX_AXES],
            expired: false,
        }
    }
}

/// One cycle of a traced homing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceRecord {
    /// Axis traced.
    pub axis: u8,
    /// Homing phase number (`motion_homing::Phase as u8`).
    pub phase: u8,
    /// Home switch actuated (logical) / a marker passed or latched this
    /// cycle / fresh feedback this cycle.
    pub switch: bool,
    pub marker: bool,
    pub fresh: bool,
    /// The home event was found in this cycle.
    pub event: bool,
    /// The homing ended in this cycle (the last record).
    pub end: bool,
    /// Time since the homing started, ns.
    pub t_ns: u64,
    /// Command and actual (raw) position, units; velocities units/s;
    /// torque % rated.
    pub cmd_position: f64,
    pub cmd_velocity: f64,
    pub position: f64,
    pub velocity: f64,
    pub torque: f64,
    /// Raw position of the event (valid with `event`).
    pub event_raw: f64,
    pub err: u16,
    pub exerr: u16,
}

// What the status shows of an axis and of an I/O process: the status
// table's source types (`motion-status`), next to the table they feed.
pub use motion_status::{AxisSnap, IoSnap, LostCause, StreamCounts};

#[derive(Clone, Debug)]
pub struct Snapshot {
    pub cycle: u64,
    pub now_ns: u64,
    pub axis_count: usize,
    pub axes: [AxisSnap; MAX_AXES],
    pub io_count: usize,
    pub ios: [IoSnap; MAX_IOS],
    /// Every axis is at rest with nothing in process.
    pub all_at_rest: bool,
    /// The supervisor is leaving (axes stopped, drives disabled).
    pub exiting: bool,
    /// The setpoint stream's intake: frames, setpoints, refusals, owners.
    pub stream: StreamCounts,
}

impl Default for Snapshot {
    fn default() -> Self {
        Self {
            cycle: 0,
            now_ns: 0,
            axis_count: 0,
            axes: [AxisSnap::default(); MAX_AXES],
            io_count: 0,
            ios: [IoSnap::default(); MAX_IOS],
            all_at_rest: true,
            exiting: false,
            stream: Default::default(),
        }
    }
}

impl Snapshot {
    /// Every I/O process is attached.
    pub fn all_attached(&self) -> bool {
        self.ios[..self.io_count].iter().all(|i| i.attached)
    }
}

/// Lifecycle of the real-time thread.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Phase {
    Starting = 0,
    Running = 1,
    Exited = 2,
    Failed = 3,
}

/// Everything the threads share.
pub struct Shared {
    pub control: ArrayQueue<Control>,
    /// The request the control thread waits for ([`Gate`]).
    pub gate: Gate,
    pub acks: ArrayQueue<Ack>,
    pub trace: ArrayQueue<TraceRecord>,
    pub stats_full: ArrayQueue<Box<HistSet>>,
    pub stats_free: ArrayQueue<Box<HistSet>>,
    pub snap_full: ArrayQueue<Box<Snapshot>>,
    pub snap_free: ArrayQueue<Box<Snapshot>>,
    phase: AtomicU8,
    /// Warm-up is over: every I/O process answers and the cycle is measured.
    pub measuring: AtomicBool,
    /// System-allocator calls made by the RT thread after warm-up.
    pub system_calls_in_cycle: AtomicU64,
    /// Allocations its pool served after warm-up (iceoryx2's per-sample Rc).
    pub pool_allocs_in_cycle: AtomicU64,
    /// Trace records dropped because the queue was full.
    pub trace_dropped: AtomicU64,
}

impl Shared {
    /// `spare_stats` / `spare_snaps`: boxes in circulation (allocated here).
    pub fn new(spare_stats: usize, spare_snaps: usize) -> Self {
        let s = Self {
            control: ArrayQueue::new(256),
            gate: Gate::default(),
            acks: ArrayQueue::new(64),
            trace: ArrayQueue::new(16_384),
            stats_full: ArrayQueue::new(spare_stats + 1),
            stats_free: ArrayQueue::new(spare_stats + 1),
            snap_full: ArrayQueue::new(spare_snaps + 1),
            snap_free: ArrayQueue::new(spare_snaps + 1),
            phase: AtomicU8::new(Phase::Starting as u8),
            measuring: AtomicBool::new(false),
            system_calls_in_cycle: AtomicU64::new(0),
            pool_allocs_in_cycle: AtomicU64::new(0),
            trace_dropped: AtomicU64::new(0),
        };
        for _ in 0..spare_stats {
            let _ = s.stats_free.push(Box::new(HistSet::new()));
        }
        for _ in 0..spare_snaps {
            let _ = s.snap_free.push(Box::default());
        }
        s
    }

    pub fn phase(&self) -> Phase {
        match self.phase.load(Ordering::Acquire) {
            0 => Phase::Starting,
            1 => Phase::Running,
            2 => Phase::Exited,
            _ => Phase::Failed,
        }
    }

    pub fn set_phase(&self, p: Phase) {
        self.phase.store(p as u8, Ordering::Release);
    }

    /// Reporting side: a request for the RT thread (false if the queue is full).
    pub fn send(&self, c: Control) -> bool {
        self.control.push(c).is_ok()
    }

    /// Real-time side: may request `c` be applied? An undated one always;
    /// one someone waits for only if the cycle takes it before they give
    /// up ([`Gate`]).
    pub fn admit(&self, c: &Control) -> bool {
        !c.gated() || self.gate.take(c.id)
    }

    /// Reporting side: the newest snapshot, recycling older ones.
    pub fn latest_snapshot(&self, keep: &mut Option<Box<Snapshot>>) {
        while let Some(s) = self.snap_full.pop() {
            if let Some(old) = keep.replace(s) {
                let _ = self.snap_free.push(old);
            }
        }
    }

    /// Reporting side: every full histogram set, shown to `each`, then
    /// recycled.
    pub fn collect_intervals(&self, mut each: impl FnMut(&HistSet)) {
        while let Some(mut h) = self.stats_full.pop() {
            each(&h);
            h.reset();
            let _ = self.stats_free.push(h);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whoever comes first decides: the cycle takes a pending request
    /// (then the control thread cannot give up on it), or the control
    /// thread gives up (then the cycle never takes it, nor any request
    /// before the one the control thread now waits for).
    #[test]
    fn the_gate_lets_exactly_one_side_decide() {
        let g = Gate::default();
        g.offer(7);
        assert!(g.take(7));
        assert!(!g.abandon(7), "taken: its answer will come");
        assert!(!g.take(7), "taken once");
        g.offer(8);
        assert!(g.abandon(8));
        assert!(!g.take(8), "given up on: never applied");
        g.offer(9);
        assert!(!g.take(8), "an old request the control thread gave up on");
        assert!(g.take(9));
        let s = Shared::new(0, 0);
        let undated = Control::undated(3, Ask::Exit);
        assert!(s.admit(&undated) && s.admit(&undated), "not gated");
        let dated = Control {
            id: 4,
            deadline_ns: 1,
            ask: Ask::Exit,
        };
        assert!(!s.admit(&dated), "not offered: not waited for");
        s.gate.offer(4);
        assert!(s.admit(&dated));
    }
}
