//! Per I/O process: attached or not, frames, and the gaps in its feedback.

use serde::{Deserialize, Serialize};

/// Gaps in an I/O process's feedback (cycles in a row without a fresh
/// answer), counted by length. A stall of a few milliseconds of one CPU is
/// normal on a busy machine; this shows how often and how long.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
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

/// One I/O process in `home`/`run`/`stats` reports.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IoReport {
    pub name: String,
    pub attached: bool,
    /// Cycles with a fresh, accepted feedback frame.
    pub frames_received: u64,
    /// Cycles without one.
    pub frames_missing: u64,
    /// Frames refused: bad layout, wrong axis count, wrong session key.
    pub frames_refused: u64,
    /// Frames that answered a command outside the accepted window.
    pub frames_too_old: u64,
    /// Times it attached (the first time included).
    pub attachments: u64,
    /// Longest gap in ms (`gaps.longest_cycles` × the cycle).
    pub longest_gap_ms: f64,
    pub gaps: GapCounts,
}
