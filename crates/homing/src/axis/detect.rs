//! Finding a search leg's goal in the feedback.
//!
//! * **Events.** A marker (and, with `registration`, the switch) uses the
//!   drive-latched position. A switch only sampled once per cycle is placed at
//!   the midpoint of the last sample before and the first after the edge, so
//!   its error is at most half the distance travelled between those samples.
//! * **"First marker after the switch"** is decided by position, not by time:
//!   the marker latch is armed at the start of the leg, a marker latched before
//!   the switch edge (or on the wrong side of it) is rejected and the latch
//!   re-armed. This needs marker spacing above ~2 cycles of travel, which any
//!   sane return speed gives.
//! * Only a fresh, validated sample is ever looked at (see `intake`), and a
//!   latched position off the travel since arming is ignored (see
//!   `plausible`).

use super::intake::Sample;
use super::latches::Travel;
use super::Axis;
use crate::plan::Goal;

/// A search leg's progress.
#[derive(Clone, Copy, Debug)]
pub(super) struct Search {
    pub goal: Goal,
    /// Command position where the leg began: origin of the search limit.
    pub start: f64,
    /// The switch has been seen actuated in this leg (`SwitchClear*`).
    pub seen_active: bool,
    /// Raw position of the switch edge, once passed (`*ThenMarker`).
    pub edge: Option<f64>,
    /// Time the torque first reached the threshold in the current run.
    pub over_since: Option<u64>,
}

impl Axis {
    /// A new search from command (or, passive, actual) position `start`, with
    /// the latches it needs armed.
    pub(super) fn begin_search(&mut self, goal: Goal, start: f64) -> Search {
        if matches!(
            goal,
            Goal::Marker | Goal::SwitchClearThenMarker | Goal::SwitchDetectThenMarker
        ) {
            self.arm_marker();
        }
        if matches!(goal, Goal::SwitchDetect | Goal::SwitchDetectThenMarker) {
            self.arm_switch(true);
        }
        Search {
            goal,
            start,
            seen_active: false,
            edge: None,
            over_since: None,
        }
    }

    /// Looks for the search's goal in this sample; returns the raw position
    /// of what was found.
    pub(super) fn detect(&mut self, now: u64, s: &Sample, search: &mut Search) -> Option<f64> {
        let (was_active, prev_pos) = match self.prev {
            Some(p) => (p.switch_active, p.position),
            None => (s.switch_active, s.fb.position),
        };
        let detected = !was_active && s.switch_active;
        let cleared = was_active && !s.switch_active;
        match search.goal {
            Goal::SwitchDetect => detected.then(|| self.edge_position(prev_pos, s)),
            Goal::SwitchClear | Goal::SwitchClearThenMarker => {
                if !search.seen_active {
                    if s.switch_active {
                        search.seen_active = true;
                        self.arm_switch(false);
                    }
                } else if cleared && search.edge.is_none() {
                    let at = self.edge_position(prev_pos, s);
                    if search.goal == Goal::SwitchClear {
                        return Some(at);
                    }
                    search.edge = Some(at);
                    self.status.switch_edge_raw = Some(at);
                }
                self.marker_after_edge(prev_pos, s, search)
            }
            Goal::SwitchDetectThenMarker => {
                if detected && search.edge.is_none() {
                    let at = self.edge_position(prev_pos, s);
                    search.edge = Some(at);
                    self.status.switch_edge_raw = Some(at);
                }
                self.marker_after_edge(prev_pos, s, search)
            }
            Goal::Marker => self.marker_seen(prev_pos, s),
            Goal::Torque => {
                if s.fb.torque * self.dir >= self.cfg.home_torque_threshold {
                    let since = *search.over_since.get_or_insert(now);
                    if now - since >= self.torque_time_ns {
                        return Some(s.fb.position);
                    }
                } else {
                    search.over_since = None;
                }
                None
            }
        }
    }

    /// The latched marker if it lies beyond the switch edge in the direction
    /// the axis went; an earlier one is rejected and the latch re-armed.
    fn marker_after_edge(&mut self, prev_pos: f64, s: &Sample, search: &Search) -> Option<f64> {
        let m = self.marker_seen(prev_pos, s)?;
        match search.edge {
            Some(e) if (m - e) * (s.fb.position - e) >= 0.0 => Some(m),
            _ => {
                self.arm_marker();
                None
            }
        }
    }

    /// The marker, if one was passed: the latched position, or for a drive
    /// without a latch the midpoint of the samples around the index pulse.
    /// A latch off the travel since arming is implausible: counted, ignored,
    /// and the latch re-armed for the next marker.
    fn marker_seen(&mut self, prev_pos: f64, s: &Sample) -> Option<f64> {
        if !self.cfg.marker_latch {
            return s
                .fb
                .marker_pulse
                .then_some(0.5 * (prev_pos + s.fb.position));
        }
        let l = s.fb.marker_latch;
        let id = self.latches.marker_id;
        if !(id != 0 && l.id == id && l.latched) {
            return None;
        }
        let travel = self.latches.marker_travel;
        if !self.latch_plausible(travel, l.position, s) {
            let n = &mut self.status.implausible.marker_latches;
            *n = n.saturating_add(1);
            self.arm_marker();
            return None;
        }
        Some(l.position)
    }

    /// Switch edge position: the registration latch where the drive has one,
    /// else the midpoint of the samples around the edge. A latch off the
    /// travel since arming is implausible: counted and ignored (the sampled
    /// edge is used).
    fn edge_position(&mut self, prev_pos: f64, s: &Sample) -> f64 {
        let midpoint = 0.5 * (prev_pos + s.fb.position);
        let l = s.fb.switch_latch;
        let id = self.latches.switch_id;
        if !(self.cfg.registration && id != 0 && l.id == id && l.latched) {
            return midpoint;
        }
        if !self.latch_plausible(self.latches.switch_travel, l.position, s) {
            let n = &mut self.status.implausible.switch_latches;
            *n = n.saturating_add(1);
            return midpoint;
        }
        l.position
    }

    /// A latched position lies on the travel seen since arming, give or take
    /// one step of travel at `max_speed` (no check without a `max_speed`).
    pub(super) fn latch_plausible(&self, travel: Option<Travel>, at: f64, s: &Sample) -> bool {
        match (self.plausible.latch_margin(s.dt_ns), travel) {
            (Some(margin), Some(t)) => t.covers(at, margin),
            _ => true,
        }
    }

    fn arm_marker(&mut self) {
        let at = self.last.map(|s| s.fb.position);
        self.latches.arm_marker(at);
    }

    /// Arms the registration latch (if the drive has one) for the electrical
    /// edge of the switch being actuated (`true`) or released (`false`).
    /// A limit switch as the reference is latched as the drive reports it, a
    /// state (its probe input wired to the limit through the drive's input
    /// polarity, as 0x60FD is): rising = becoming active.
    pub(super) fn arm_switch(&mut self, actuated: bool) {
        if self.cfg.registration {
            let at = self.last.map(|s| s.fb.position);
            let inverted =
                self.cfg.home_switch_normally_closed && !self.cfg.home_sequence.uses_limit_switch();
            self.latches.arm_switch(actuated != inverted, at);
        }
    }
}
