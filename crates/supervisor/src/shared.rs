//! What crosses between the real-time thread and the rest of the process.
//!
//! Only `crossbeam::queue::ArrayQueue`s: bounded, preallocated, lock-free in
//! both directions. A crossbeam *channel* would be simpler, but a sender may
//! have to lock the channel's waker list to wake a blocked receiver, and that
//! lock could be held by a preempted normal-priority thread. Here nobody ever
//! blocks on a queue: the reporting side polls.
//!
//! Large objects (histogram sets, snapshots) travel as `Box`es that circulate
//! between a `full` and a `free` queue, so the real-time thread moves a pointer
//! and never allocates or frees.

use crate::stats::HistSet;
use crossbeam::queue::ArrayQueue;
use motion_frames::MAX_AXES;
use motion_homing::Status;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, Ordering};

/// Requests to the real-time thread.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// Rising edge of the Home instruction of axis `i`.
    Home(usize),
    /// Stop (MAS) axis `i`.
    Stop(usize),
    /// Stop every axis, disable the drives once at rest, then leave the loop.
    Exit,
}

/// One axis as the reporting thread sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisSnap {
    pub status: motion_homing::Status,
    /// Raw and axis position from the newest valid feedback.
    pub raw: Option<f64>,
    pub axis: Option<f64>,
    pub cmd_position: f64,
    pub cmd_velocity: f64,
    pub enable: bool,
    /// Home requests the engine has been given (rising edges applied).
    pub homes_started: u32,
}

impl AxisSnap {
    /// Homing finished (either way) and the axis is at rest.
    pub fn settled(&self) -> bool {
        let s: &Status = &self.status;
        !s.ip && !s.stopping && (s.dn || s.er) && self.cmd_velocity == 0.0
    }
}

#[derive(Clone, Debug)]
pub struct Snapshot {
    pub cycle: u64,
    pub now_ns: u64,
    pub axis_count: usize,
    pub axes: [AxisSnap; MAX_AXES],
    /// Feedback frames received / cycles without a fresh frame (total).
    pub frames_received: u64,
    pub frames_missing: u64,
    /// The last feedback frame arrived in this cycle (the I/O process answers).
    pub io_fresh: bool,
    /// Frames rejected: wrong layout or axis count.
    pub frames_rejected: u64,
    /// Frames that answered a command older than `stale_cycles` (not used).
    pub frames_late: u64,
    /// Every axis is at rest with nothing in process.
    pub all_at_rest: bool,
}

impl Default for Snapshot {
    fn default() -> Self {
        Self {
            cycle: 0,
            now_ns: 0,
            axis_count: 0,
            axes: [AxisSnap::default(); MAX_AXES],
            frames_received: 0,
            frames_missing: 0,
            io_fresh: false,
            frames_rejected: 0,
            frames_late: 0,
            all_at_rest: true,
        }
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
    pub stats_full: ArrayQueue<Box<HistSet>>,
    pub stats_free: ArrayQueue<Box<HistSet>>,
    pub snap_full: ArrayQueue<Box<Snapshot>>,
    pub snap_free: ArrayQueue<Box<Snapshot>>,
    phase: AtomicU8,
    /// Warm-up is over: the I/O process answers and the cycle is measured.
    pub measuring: AtomicBool,
    /// System-allocator calls made by the RT thread after warm-up.
    pub system_calls_in_cycle: AtomicU64,
    /// Allocations its pool served after warm-up (iceoryx2's per-sample Rc).
    pub pool_allocs_in_cycle: AtomicU64,
}

impl Shared {
    /// `spare_stats` / `spare_snaps`: boxes in circulation (allocated here).
    pub fn new(spare_stats: usize, spare_snaps: usize) -> Self {
        let s = Self {
            control: ArrayQueue::new(256),
            stats_full: ArrayQueue::new(spare_stats + 1),
            stats_free: ArrayQueue::new(spare_stats + 1),
            snap_full: ArrayQueue::new(spare_snaps + 1),
            snap_free: ArrayQueue::new(spare_snaps + 1),
            phase: AtomicU8::new(Phase::Starting as u8),
            measuring: AtomicBool::new(false),
            system_calls_in_cycle: AtomicU64::new(0),
            pool_allocs_in_cycle: AtomicU64::new(0),
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

    /// Reporting side: merges every full histogram set into `total`.
    pub fn collect_stats(&self, total: &mut HistSet) {
        self.collect_intervals(total, |_| {});
    }

    /// As [`Self::collect_stats`], showing each interval to `each` first
    /// (for interval logs).
    pub fn collect_intervals(&self, total: &mut HistSet, mut each: impl FnMut(&HistSet)) {
        while let Some(mut h) = self.stats_full.pop() {
            each(&h);
            total.merge(&h);
            h.reset();
            let _ = self.stats_free.push(h);
        }
    }
}
