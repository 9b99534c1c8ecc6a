//! An I/O process's status, declared once: the counters the cycle keeps
//! ([`IoCounters`], inside the snapshot's [`IoSnap`]) are the very struct
//! the status frame carries ([`IoStatusEntry::counters`]) and the JSON
//! reports flatten ([`IoStatus`] in `status --json`, [`IoReport`] in
//! `home`/`run`/`stats`). A new counter is one field of [`IoCounters`].

#[cfg(feature = "zero-copy")]
use iceoryx2_bb_derive_macros::{PlacementDefault, ZeroCopySend};
#[cfg(feature = "zero-copy")]
use iceoryx2_bb_elementary_traits::{
    placement_default::PlacementDefault, zero_copy_send::ZeroCopySend,
};
use serde::{Deserialize, Serialize};

use crate::text::{get_str, NAME_LEN};

/// Bytes of `IoStatusEntry::start_error`.
pub const START_ERROR_LEN: usize = 128;

/// Gaps in an I/O process's feedback (cycles in a row without a fresh
/// answer), counted by length. A stall of a few milliseconds of one CPU is
/// normal on a busy machine; this shows how often and how long.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct GapCounts {
    /// Gaps of exactly 1 cycle.
    pub one: u64,
    /// Gaps of 2–3 cycles.
    pub two_to_three: u64,
    /// Gaps of 4–10 cycles.
    pub four_to_ten: u64,
    /// Gaps of more than 10 cycles.
    pub over_ten: u64,
    /// The longest gap, cycles.
    pub longest_cycles: u64,
}

impl GapCounts {
    /// Counts a gap of `cycles` (> 0) cycles.
    pub fn add(&mut self, cycles: u64) {
        match cycles {
            0 => return,
            1 => self.one += 1,
            2..=3 => self.two_to_three += 1,
            4..=10 => self.four_to_ten += 1,
            _ => self.over_ten += 1,
        }
        self.longest_cycles = self.longest_cycles.max(cycles);
    }

    pub fn merge(&mut self, o: &GapCounts) {
        self.one += o.one;
        self.two_to_three += o.two_to_three;
        self.four_to_ten += o.four_to_ten;
        self.over_ten += o.over_ten;
        self.longest_cycles = self.longest_cycles.max(o.longest_cycles);
    }

    pub fn total(&self) -> u64 {
        self.one + self.two_to_three + self.four_to_ten + self.over_ten
    }
}

/// What the cycle counts of an I/O process (since the supervisor started).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct IoCounters {
    /// Cycles with a fresh, accepted feedback frame.
    pub frames_received: u64,
    /// Cycles without one.
    pub frames_missing: u64,
    /// Frames refused: bad layout, wrong axis count, wrong session key, an
    /// answer from the future.
    pub frames_refused: u64,
    /// Frames that answered a command outside the accepted window.
    pub frames_too_old: u64,
    /// Times it attached (the first time included).
    pub attachments: u64,
    /// Times a new incarnation of the process (a restart) was seen.
    pub incarnations: u64,
    pub gaps: GapCounts,
    /// Cycles without a fresh answer right now (the current gap).
    pub gap_cycles: u64,
}

/// One I/O process as the reporting side sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IoSnap {
    /// Fresh feedback arrives (within the feedback-loss rule).
    pub attached: bool,
    pub counters: IoCounters,
}

/// One I/O process of the status frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct IoStatusEntry {
    pub name: [u8; NAME_LEN],
    /// 1 = fresh feedback arrives (within the feedback-loss rule).
    pub attached: u8,
    pub reserved: [u8; 3],
    /// A spawned I/O process: times the supervisor started it again.
    pub spawn_restarts: u32,
    /// A spawned I/O process: seconds until its next start (0: running).
    pub spawn_retry_s: f32,
    pub reserved2: u32,
    pub counters: IoCounters,
    /// A spawned I/O process: the error it ended with at its last failed
    /// start (its first line), NUL-padded; empty when none.
    pub start_error: [u8; START_ERROR_LEN],
}

impl Default for IoStatusEntry {
    /// All zero.
    fn default() -> Self {
        Self {
            name: [0; NAME_LEN],
            attached: 0,
            reserved: [0; 3],
            spawn_restarts: 0,
            spawn_retry_s: 0.0,
            reserved2: 0,
            counters: IoCounters::default(),
            start_error: [0; START_ERROR_LEN],
        }
    }
}

/// One I/O process of `status --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IoStatus {
    pub name: String,
    pub attached: bool,
    #[serde(flatten)]
    pub counters: IoCounters,
    /// A spawned I/O process: times the supervisor started it again.
    #[serde(default)]
    pub restarts: u32,
    /// A spawned I/O process waiting to be started again: in this many
    /// seconds (1 s doubling to 30 s while it keeps failing at start-up).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub retry_in_s: Option<f64>,
    /// A spawned I/O process: the error of its last failed start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_error: Option<String>,
}

impl IoStatusEntry {
    /// The entry as `status --json` shows it.
    pub fn to_status(&self) -> IoStatus {
        IoStatus {
            name: get_str(&self.name),
            attached: self.attached != 0,
            counters: self.counters,
            restarts: self.spawn_restarts,
            retry_in_s: (self.spawn_retry_s > 0.0)
                .then(|| crate::schema::round(f64::from(self.spawn_retry_s), 1)),
            start_error: Some(get_str(&self.start_error)).filter(|e| !e.is_empty()),
        }
    }
}

/// One I/O process in `home`/`run`/`stats` reports.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IoReport {
    pub name: String,
    pub attached: bool,
    #[serde(flatten)]
    pub counters: IoCounters,
    /// Longest gap in ms (`gaps.longest_cycles` × the cycle).
    pub longest_gap_ms: f64,
}

impl IoReport {
    /// The report of I/O process `name` from its snapshot, with a cycle of
    /// `cycle_us`.
    pub fn new(name: &str, s: &IoSnap, cycle_us: u32) -> Self {
        let cycle_ms = f64::from(cycle_us) / 1000.0;
        Self {
            name: name.to_string(),
            attached: s.attached,
            counters: s.counters,
            longest_gap_ms: s.counters.gaps.longest_cycles as f64 * cycle_ms,
        }
    }
}

const _: () = {
    use core::mem::{offset_of, size_of};
    assert!(size_of::<GapCounts>() == 40);
    assert!(size_of::<IoCounters>() == 96);
    assert!(offset_of!(IoStatusEntry, counters) == 48);
    assert!(offset_of!(IoStatusEntry, start_error) == 144);
    assert!(size_of::<IoStatusEntry>() == 144 + START_ERROR_LEN);
};

/// A report row reads as its counters (`io.frames_received`): they are its
/// body, the name and the rest only label them.
impl core::ops::Deref for IoReport {
    type Target = IoCounters;

    fn deref(&self) -> &IoCounters {
        &self.counters
    }
}

/// As [`IoReport`]'s.
impl core::ops::Deref for IoStatus {
    type Target = IoCounters;

    fn deref(&self) -> &IoCounters {
        &self.counters
    }
}
