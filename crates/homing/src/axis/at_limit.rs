//! What homing does at a limit switch: abort, carry on, or reverse.
//!
//! The limit inputs reach the engine as states (`Feedback::overtravel_*`,
//! CiA 402 0x60FD bits 0/1: the drive applies the wiring's polarity). A
//! limit tripped *in the direction of travel* aborts homing with 12 / 43
//! (hardware overtravel) — except in the legs that mean to be on it, and
//! only for the limit in Home Direction:
//!
//! * a limit-switch sequence (`limit_switch`, `limit_switch_then_marker`)
//!   seeks that limit and stops on it ([`Leg::StopAtLimit`]): the overtravel
//!   stop is suspended for those two legs and in force again from the
//!   return leg on, which leaves the limit (moving away from a tripped limit
//!   never aborts);
//! * with `home_reverse_at_limit`, the first seek of a bidirectional switch
//!   (then marker) sequence that meets that limit before the home switch
//!   reverses the search ([`after_reversal`]); the stop on the limit is the
//!   reversed plan's [`Leg::StopAtLimit`].
//!
//! The other limit is an overtravel in every leg, and so is the limit in
//! Home Direction in every other leg: the move home, the second seek after a
//! reversal (a reversal happens once), the run back past the home switch
//! (which meets the other limit when there is no home switch between the
//! two). With `limit_switches = false` the inputs are not looked at.
//!
//! For the limit-switch sequences the limit in Home Direction is also the
//! *reference switch*: what the `Switch*` goals of the plan look at
//! ([`Axis::reference_switch_active`]).

use super::intake::Sample;
use super::state::State;
use super::{Abort, Axis};
use crate::codes::{ERR_SERVO_MESSAGE, EX_OVERTRAVEL};
use crate::io::Feedback;
use crate::plan::{after_reversal, Leg};

/// What the current leg does about the limit switches in this sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum AtLimit {
    /// No limit tripped in the direction of travel, or one the leg means to
    /// be on: carry on.
    Go,
    /// The first seek met the limit in Home Direction before the home
    /// switch: reverse the search.
    Reverse,
    /// Hardware overtravel: abort with 12 / 43.
    Overtravel,
}

impl Axis {
    /// The sequence's reference switch is actuated in `fb`: the home switch
    /// through its NO / NC wiring; for the limit-switch sequences the limit
    /// switch in Home Direction (reported as a state by the drive).
    pub fn reference_switch_active(&self, fb: &Feedback) -> bool {
        if self.cfg.home_sequence.uses_limit_switch() {
            if self.dir > 0.0 {
                fb.overtravel_positive
            } else {
                fb.overtravel_negative
            }
        } else {
            fb.home_switch != self.cfg.home_switch_normally_closed
        }
    }

    /// The rule of the module docs for a leg that commands motion, at the
    /// command velocity of `now`.
    pub(super) fn at_limit(&mut self, now: u64, s: &Sample) -> AtLimit {
        if !self.cfg.limit_switches {
            return AtLimit::Go;
        }
        let v = self.profile.at(now).1;
        let towards =
            (v > 0.0 && s.fb.overtravel_positive) || (v < 0.0 && s.fb.overtravel_negative);
        if !towards {
            return AtLimit::Go;
        }
        let State::Homing(h) = &self.state else {
            return AtLimit::Overtravel;
        };
        if v * self.dir < 0.0 {
            // The limit behind the home direction: never the reference.
            return AtLimit::Overtravel;
        }
        match h.current() {
            Some(Leg::Seek(_)) if self.cfg.home_sequence.uses_limit_switch() => AtLimit::Go,
            Some(Leg::StopAtLimit) => AtLimit::Go,
            Some(Leg::Seek(_)) if self.cfg.home_reverse_at_limit && h.leg == 0 => AtLimit::Reverse,
            _ => AtLimit::Overtravel,
        }
    }

    /// The first seek met the limit in Home Direction: the plan becomes its
    /// reversed form and its next leg — stop at the limit — starts now.
    pub(super) fn reverse_search(&mut self, now: u64, s: &Sample) {
        let State::Homing(h) = &mut self.state else {
            return;
        };
        match after_reversal(h.plan) {
            Some(reversed) => {
                h.plan = reversed;
                self.status.reversed_at_limit = true;
                self.next_leg(now, s, true);
            }
            // Validation refuses `home_reverse_at_limit` for such a plan.
            None => self.fail(now, ERR_SERVO_MESSAGE, EX_OVERTRAVEL, Abort::Controlled),
        }
    }
}
