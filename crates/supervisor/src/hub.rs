//! What the normal-priority threads of the daemon share: the newest
//! snapshot, the latency statistics since start and since the last reset,
//! the serialized intervals of the last hour, the recorded trace.
//!
//! A `Mutex`: only normal threads (the control thread, which fills it, and
//! the main thread, which reads it for the final report) ever take it; the
//! real-time thread never sees it.

use crate::hlog::IntervalLines;
use crate::shared::{Snapshot, TraceRecord};
use crate::stats::HistSet;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Instant, SystemTime};

/// Intervals (seconds) of statistics kept for `stats --hlog`.
pub const INTERVALS_KEPT: usize = 3600;
/// Cycles a trace may record (an hour at 1 kHz would be 3.6 M: cap it).
pub const TRACE_MAX: usize = 600_000;

/// The trace of one homing (`motionctl trace`).
#[derive(Debug, Default)]
pub struct TraceBuf {
    /// Axis armed or recorded.
    pub axis: Option<usize>,
    pub records: Vec<TraceRecord>,
    /// The homing ended: the records are complete.
    pub complete: bool,
}

pub struct Hub {
    pub snapshot: Option<Box<Snapshot>>,
    pub since_start: HistSet,
    pub since_reset: HistSet,
    pub started: Instant,
    pub start_time: SystemTime,
    pub reset_at: Instant,
    /// First interval after the last reset.
    pub reset_interval: u64,
    pub lines: IntervalLines,
    pub trace: TraceBuf,
    /// Control requests refused (wrong key or layout) since start.
    pub requests_refused: u64,
    /// The control thread could not serve (its services failed).
    pub control_error: Option<String>,
    /// The spawned I/O processes' restarts and start-up errors, by I/O
    /// process index (the session writes them; empty: none spawned).
    pub spawns: Vec<crate::io_child::SpawnNote>,
}

impl Hub {
    pub fn new() -> Self {
        let now = Instant::now();
        Self {
            snapshot: None,
            since_start: HistSet::new(),
            since_reset: HistSet::new(),
            started: now,
            start_time: SystemTime::now(),
            reset_at: now,
            reset_interval: 0,
            lines: IntervalLines::new(INTERVALS_KEPT),
            trace: TraceBuf::default(),
            requests_refused: 0,
            control_error: None,
            spawns: Vec::new(),
        }
    }

    /// Starts "since reset" now.
    pub fn reset(&mut self) {
        self.since_reset.reset();
        self.reset_at = Instant::now();
        self.reset_interval = self.lines.next_number();
    }
}

impl Default for Hub {
    fn default() -> Self {
        Self::new()
    }
}

#[derive(Clone, Default)]
pub struct SharedHub(Arc<Mutex<Hub>>);

impl SharedHub {
    /// Never fails: a panic while holding the lock leaves data that is still
    /// fine to report.
    pub fn lock(&self) -> MutexGuard<'_, Hub> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}
