//! The arm side of the drive's position latches (touch-probe handshake).
//!
//! Every arming gets a new non-zero id; the drive echoes it with its capture,
//! so a capture from an earlier arming can never be taken for a new one,
//! whatever the frame delay. Id 0 disarms.
//!
//! Each arming also remembers the positions the axis has been seen at since
//! (from the position at arming on): a capture can only lie on that travel,
//! so one outside it (beyond a margin of one step of travel at `max_speed`)
//! is a forged or corrupt frame, never an event.

use crate::io::Edge;

/// Raw positions seen since a latch was armed: `[lo, hi]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Travel {
    lo: f64,
    hi: f64,
}

impl Travel {
    fn at(p: f64) -> Self {
        Self { lo: p, hi: p }
    }

    /// Compared, not `f64::min`/`max` (which also sort out NaN): positions
    /// reach here validated, and this runs every step.
    fn extend(&mut self, p: f64) {
        if p < self.lo {
            self.lo = p;
        }
        if p > self.hi {
            self.hi = p;
        }
    }

    /// `x` lies on the travel, give or take `margin`.
    pub fn covers(&self, x: f64, margin: f64) -> bool {
        self.lo - margin <= x && x <= self.hi + margin
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Latches {
    /// Id of the current marker arming (0 = disarmed).
    pub marker_id: u8,
    /// Id of the current switch (registration) arming (0 = disarmed).
    pub switch_id: u8,
    /// Electrical edge the switch latch is armed for.
    pub switch_edge: Edge,
    /// Travel since the marker / switch latch was armed (None: armed before
    /// any position was known).
    pub marker_travel: Option<Travel>,
    pub switch_travel: Option<Travel>,
    last_id: u8,
}

impl Latches {
    /// Arms the marker latch with the axis last seen at `at`.
    pub fn arm_marker(&mut self, at: Option<f64>) {
        self.marker_id = self.next_id();
        self.marker_travel = at.map(Travel::at);
    }

    /// Arms the switch latch for a rising (`true`) or falling electrical
    /// edge, with the axis last seen at `at`.
    pub fn arm_switch(&mut self, rising: bool, at: Option<f64>) {
        self.switch_edge = if rising { Edge::Rising } else { Edge::Falling };
        self.switch_id = self.next_id();
        self.switch_travel = at.map(Travel::at);
    }

    /// A new sample at raw position `p`: the armed latches' travel grows.
    pub fn seen_at(&mut self, p: f64) {
        for t in [&mut self.marker_travel, &mut self.switch_travel] {
            match t {
                Some(t) => t.extend(p),
                None => *t = Some(Travel::at(p)),
            }
        }
    }

    pub fn disarm(&mut self) {
        self.marker_id = 0;
        self.switch_id = 0;
    }

    /// Ids run 1..=255 and wrap past 0, which means "disarmed".
    fn next_id(&mut self) -> u8 {
        self.last_id = if self.last_id == u8::MAX {
            1
        } else {
            self.last_id + 1
        };
        self.last_id
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn travel_since_arming() {
        let mut l = Latches::default();
        l.arm_marker(Some(1.0));
        l.seen_at(1.5);
        l.seen_at(0.5);
        let t = l.marker_travel.unwrap();
        assert!(t.covers(0.5, 0.0) && t.covers(1.5, 0.0) && !t.covers(1.6, 0.0));
        assert!(t.covers(1.6, 0.1 + 1e-12));
        // Re-arming forgets the earlier travel.
        l.arm_marker(Some(3.0));
        assert!(!l.marker_travel.unwrap().covers(1.0, 1.0));
        assert_eq!(l.marker_id, 2);
    }
}
