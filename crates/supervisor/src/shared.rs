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
use motion_homing::Status;
use motion_report::GapCounts;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, Ordering};

/// Most I/O processes (the config's limit).
pub const MAX_IOS: usize = 16;

/// Requests to the real-time thread. `mask` bit `i` = axis `i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// Home the axes of `mask`: in home order (config order one at a time
    /// when no axis has one), or all at once with `parallel`. `timeout_ns`
    /// (0 = none) stops what is still homing after that long.
    Home {
        id: u32,
        mask: u64,
        parallel: bool,
        timeout_ns: u64,
    },
    /// Stop (MAS) the axes of `mask`.
    Stop { id: u32, mask: u64 },
    /// Clear HomedStatus of the axes of `mask`.
    Unhome { id: u32, mask: u64 },
    /// Record every cycle of the next homing of axis `axis`.
    Trace { id: u32, axis: usize },
    /// Apply the stored raw → axis `offset` of absolute axis `axis` without
    /// motion ([`motion_homing::Axis::restore_reference`]).
    Restore { id: u32, axis: usize, offset: f64 },
    /// Stop every axis, disable the drives once at rest, then leave the loop.
    Exit,
    /// An operation for every axis of `mask` (a gantry: all its sides),
    /// delivered to their engines in the same cycle and answered after that
    /// cycle's step with each engine's answer. `f64` parameters that are
    /// NaN are the axis's default (a gantry side: its gantry's first
    /// side's): accel `home_acceleration`, decel `home_deceleration`, a
    /// move's speed `home_speed`. `token` names a jog (for its renewals).
    Op {
        id: u32,
        mask: u64,
        op: motion_homing::Operation,
        token: u64,
    },
    /// Renew (or with `end`, end) the jog `token` on the axes of `mask`
    /// (0: wherever it runs).
    JogRenew {
        id: u32,
        token: u64,
        mask: u64,
        end: bool,
    },
    /// `token` takes the axes of `mask` over for the setpoint stream (all
    /// of them or none).
    StreamAcquire { id: u32, mask: u64, token: u64 },
    /// The stream of `token` ends (released, or its owner is gone): its
    /// axes stop.
    StreamRelease { id: u32, token: u64 },
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
}

impl Ack {
    pub fn new(id: u32) -> Self {
        Self {
            id,
            cycle: 0,
            axes: [AxisAck::default(); MAX_AXES],
            op_ids: [0; MAX_AXES],
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

/// Why HomedStatus was lost after a homing had set it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LostCause {
    /// Another reason (invalid or implausible feedback, a shutdown), or
    /// none known.
    #[default]
    Other,
    /// The feedback-loss rule tripped (or the I/O process detached).
    Feedback,
    /// The I/O process reconnected (restarted or attached again).
    Reconnect,
}

/// One axis as the reporting side sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisSnap {
    pub status: motion_homing::Status,
    /// Raw and axis position from the newest valid feedback.
    pub raw: Option<f64>,
    pub axis: Option<f64>,
    /// From the newest valid feedback.
    pub velocity: f64,
    pub torque: f64,
    pub switch: bool,
    pub marker: bool,
    pub enabled: bool,
    pub fault: bool,
    pub drive_error_code: u16,
    /// Fresh feedback this cycle.
    pub fresh: bool,
    pub cmd_position: f64,
    pub cmd_velocity: f64,
    pub enable: bool,
    /// Home requests the engine has been given (rising edges applied).
    pub homes_started: u32,
    /// The home sequence this axis was part of was aborted because this
    /// axis (index) failed.
    pub aborted_by: Option<u8>,
    /// The sequence's `timeout_ns` ran out and the axis was stopped.
    pub timed_out: bool,
    /// A gantry side: the largest skew of its gantry's last homing, units.
    pub skew: Option<f64>,
    /// A sequence has started, or will start, this axis.
    pub in_sequence: bool,
    /// A trace of this axis's next homing is armed or recording.
    pub traced: bool,
    /// HomedStatus was lost after the last homing succeeded: when (ns), and
    /// why.
    pub lost_homed_ns: Option<u64>,
    pub lost_cause: LostCause,
    /// The raw → axis offset while homed.
    pub offset: Option<f64>,
    /// HomedStatus comes from a stored reference (absolute axis, restored
    /// without motion), not from a homing run since start-up.
    pub restored: bool,
    /// The owner token of the setpoint stream that owns the axis (0: none).
    pub owner: u64,
    /// This cycle's command position in axis coordinates.
    pub cmd_axis: Option<f64>,
    /// The cycle monitor's trip in force (until a reset), and its trips
    /// since start: the control thread logs each one with its values.
    pub monitor: Option<motion_monitor::Trip>,
    pub monitor_trips: u32,
}

impl AxisSnap {
    /// Homing finished (either way) and the axis is at rest.
    pub fn settled(&self) -> bool {
        let s: &Status = &self.status;
        !s.ip && !s.stopping && (s.dn || s.er) && self.cmd_velocity == 0.0
    }
}

/// One I/O process as the reporting side sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IoSnap {
    pub attached: bool,
    /// Cycles with a fresh, accepted frame / without one.
    pub frames_received: u64,
    pub frames_missing: u64,
    /// Refused: layout, axis count, key, answer from the future.
    pub frames_refused: u64,
    /// Answered a command outside the accepted window.
    pub frames_too_old: u64,
    pub attachments: u64,
    /// Times a new incarnation (restart) of the process was seen.
    pub restarts: u64,
    pub gaps: GapCounts,
    /// Current gap, cycles.
    pub gap_cycles: u64,
}

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
    /// The setpoint stream's intake: frames, setpoints, refusals; owners.
    pub stream: StreamCounts,
    pub owners: u32,
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
            owners: 0,
        }
    }
}

impl Snapshot {
    /// Every I/O process is attached.
    pub fn all_attached(&self) -> bool {
        self.ios[..self.io_count].iter().all(|i| i.attached)
    }
}

/// The setpoint stream's intake counters (since start), kept by the
/// cycle's intake (`core::stream`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamCounts {
    /// Frames that reached the checks.
    pub frames: u64,
    /// Setpoints handed to engines (a gantry's counts once).
    pub setpoints: u64,
    pub refused_layout: u64,
    pub refused_key: u64,
    pub refused_count: u64,
    pub refused_token: u64,
    pub refused_sequence: u64,
    pub refused_axis: u64,
    /// Streams granted since start.
    pub acquired: u32,
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
