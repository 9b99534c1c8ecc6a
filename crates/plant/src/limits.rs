//! The two overtravel limit switches (`[axis.sim] limit_switches = [lo, hi]`):
//! the negative one actuated at or below `lo`, the positive one at or above
//! `hi`, each a [`Switch`] over a half-line so its edges follow the same
//! crossing rules as the home switch's (reaching the boundary actuates,
//! leaving needs going strictly past it).
//!
//! **What the drive reports.** Like a CiA 402 drive's 0x60FD bits 0/1, the
//! feedback carries the limits as *states* (tripped or not): the drive
//! applies the wiring's polarity. The wiring still matters, because of what
//! a broken wire reads:
//!
//! * normally open (the default): a contact closes when actuated; a broken
//!   wire reads "not actuated" on both — the limit is silently gone (which
//!   is why machines use NC limit switches);
//! * normally closed (`limit_switches_normally_closed`): a contact opens when
//!   actuated; a broken common wire opens both, so both read actuated — which
//!   two switches at opposite ends of the travel never are. The drive takes
//!   that as a wire break and faults (power stage off) for as long as it
//!   lasts.
//!
//! **Registration.** Where the axis homes on a limit switch, the drive's
//! probe input (the registration latch) is wired to that limit
//! ([`RegistrationInput`](crate::config::RegistrationInput)), and latches its
//! edges as states: rising = becoming actuated.

use crate::sensors::Switch;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitSwitches {
    negative: Option<Switch>,
    positive: Option<Switch>,
    normally_closed: bool,
    /// The common wire of the two switches is cut (tests).
    wire_broken: bool,
}

impl LimitSwitches {
    /// From the (sanitized) interval: an infinite end means no switch on
    /// that side.
    pub fn new(limits: Option<(f64, f64)>, normally_closed: bool) -> Self {
        let (negative, positive) = match limits {
            Some((lo, hi)) => (
                lo.is_finite()
                    .then(|| Switch::new(f64::NEG_INFINITY, lo, false)),
                hi.is_finite()
                    .then(|| Switch::new(hi, f64::INFINITY, false)),
            ),
            None => (None, None),
        };
        Self {
            negative,
            positive,
            normally_closed,
            wire_broken: false,
        }
    }

    /// Electrical level of one input (true = contact closed).
    fn level(&self, switch: Option<Switch>, x: f64) -> bool {
        if self.wire_broken {
            return false;
        }
        switch.is_some_and(|s| s.active(x)) != self.normally_closed
    }

    /// The states the drive reports at `x`: (negative, positive) actuated.
    /// A missing switch never reads actuated, whatever the wiring.
    pub fn states(&self, x: f64) -> (bool, bool) {
        let state = |s: Option<Switch>| s.is_some() && self.level(s, x) != self.normally_closed;
        (state(self.negative), state(self.positive))
    }

    /// Both NC inputs read actuated: a wire break, which the drive faults on.
    pub fn wire_break(&self, x: f64) -> bool {
        let (n, p) = self.states(x);
        self.normally_closed && n && p
    }

    pub fn break_wire(&mut self) {
        self.wire_broken = true;
    }

    pub fn negative(&self) -> Option<Switch> {
        self.negative
    }

    pub fn positive(&self) -> Option<Switch> {
        self.positive
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_homing::Edge;

    #[test]
    fn actuated_at_or_beyond_the_ends() {
        let l = LimitSwitches::new(Some((-10.0, 10.0)), false);
        assert_eq!(l.states(-10.5), (true, false));
        assert_eq!(l.states(-10.0), (true, false), "at the end: actuated");
        assert_eq!(l.states(-9.999), (false, false));
        assert_eq!(l.states(10.0), (false, true));
        assert_eq!(l.states(1e300), (false, true));
        let one_sided = LimitSwitches::new(Some((f64::NEG_INFINITY, 10.0)), true);
        assert_eq!(one_sided.states(-1e300), (false, false));
        assert_eq!(LimitSwitches::new(None, true).states(0.0), (false, false));
    }

    #[test]
    fn a_broken_wire_reads_actuated_on_nc_and_nothing_on_no() {
        for nc in [false, true] {
            let mut l = LimitSwitches::new(Some((-10.0, 10.0)), nc);
            assert_eq!(l.states(0.0), (false, false), "NC {nc}: same states");
            assert_eq!(l.states(11.0), (false, true), "NC {nc}: same states");
            assert!(!l.wire_break(11.0));
            l.break_wire();
            assert_eq!(l.states(0.0), (nc, nc), "NC {nc}");
            assert_eq!(l.wire_break(0.0), nc);
        }
    }

    #[test]
    fn edges_as_states() {
        let l = LimitSwitches::new(Some((-10.0, 10.0)), true);
        let n = l.negative().unwrap();
        // Moving out of the negative limit: released when strictly past -10.
        assert_eq!(n.first_edge(-12.0, -10.0, Edge::Falling), None);
        assert_eq!(n.first_edge(-10.0, -9.0, Edge::Falling), Some(-10.0));
        let p = l.positive().unwrap();
        assert_eq!(p.first_edge(9.0, 10.0, Edge::Rising), Some(10.0));
    }
}
