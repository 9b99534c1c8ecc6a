//! Sensors along the travel: the marker track and the switches (the home
//! switch; the limit switches are two of them, see `limits`), and the rules that decide what a cycle's straight
//! segment `old → new` has crossed.
//!
//! # Crossing rules
//!
//! Motion within a cycle is a straight segment, so every crossing is decided
//! by comparing the segment's ends with a fixed position; no loops over
//! markers, no sampling.
//!
//! * **Markers** are point events. A marker `m` is *passed* moving forward if
//!   `m ∈ (old, new]`, moving backward if `m ∈ [new, old)`: arriving on a
//!   marker counts, leaving it does not. So an axis that stops exactly on a
//!   marker and reverses passes it once (on arrival), and one that stops on it
//!   and continues also passes it once.
//! * **The switch** is a level over the inclusive interval `[lo, hi]`. An edge
//!   is counted in the cycle whose end-of-cycle level shows it. Entering the
//!   interval is therefore counted on *reaching* the boundary (forward
//!   `lo ∈ (old, new]`, backward `hi ∈ [new, old)`: the marker rule), leaving
//!   it only on going *strictly past* the boundary (forward `hi ∈ [old, new)`,
//!   backward `lo ∈ (new, old]`). Consequences: stopping exactly on a boundary
//!   shows the switch active and its entering edge latched; reversing from
//!   there gives the leaving edge at that same boundary in the next cycle; and
//!   the edges counted over any segment always agree with the levels at its
//!   ends (odd count ⇔ level changed).

use motion_homing::Edge;

/// Most rounding steps to correct the floor estimate of a marker index by.
/// One is always enough while the index is exactly representable; the bound
/// keeps huge (degenerate) indices from looping.
const INDEX_FIXUPS: usize = 4;

/// The marker track: markers at `at + k * every` for every integer `k`.
///
/// A marker's position is always computed as exactly `at + k * every` (one
/// rounding of the product, one of the sum), whichever way it is approached,
/// so the same physical marker latches the same bits forward and backward.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Markers {
    at: f64,
    every: f64,
}

impl Markers {
    /// The track of a (sanitized) config: `every <= 0` or non-finite values
    /// give an empty track.
    pub fn new(at: f64, every: f64) -> Self {
        if at.is_finite() && every.is_finite() && every > 0.0 {
            Self { at, every }
        } else {
            Self {
                at: 0.0,
                every: 0.0,
            }
        }
    }

    /// No markers at all.
    pub fn is_empty(&self) -> bool {
        self.every == 0.0
    }

    fn pos(&self, k: f64) -> f64 {
        self.at + k * self.every
    }

    /// Integer estimate of the index of the marker at or below `x`.
    fn floor_index(&self, x: f64) -> Option<f64> {
        let k = ((x - self.at) / self.every).floor();
        k.is_finite().then_some(k)
    }

    /// The smallest marker strictly above `x`.
    pub fn next_above(&self, x: f64) -> Option<f64> {
        if self.is_empty() || !x.is_finite() {
            return None;
        }
        let mut k = self.floor_index(x)? + 1.0;
        for _ in 0..INDEX_FIXUPS {
            if self.pos(k - 1.0) > x {
                k -= 1.0;
            } else {
                break;
            }
        }
        for _ in 0..INDEX_FIXUPS {
            if self.pos(k) <= x {
                k += 1.0;
            } else {
                break;
            }
        }
        let m = self.pos(k);
        (m.is_finite() && m > x).then_some(m)
    }

    /// The largest marker strictly below `x`.
    pub fn next_below(&self, x: f64) -> Option<f64> {
        if self.is_empty() || !x.is_finite() {
            return None;
        }
        let mut k = self.floor_index(x)?;
        for _ in 0..INDEX_FIXUPS {
            if self.pos(k) >= x {
                k -= 1.0;
            } else {
                break;
            }
        }
        for _ in 0..INDEX_FIXUPS {
            if self.pos(k + 1.0) < x {
                k += 1.0;
            } else {
                break;
            }
        }
        let m = self.pos(k);
        (m.is_finite() && m < x).then_some(m)
    }

    /// The first marker passed on the segment `old → new`, in the direction
    /// of motion (see the module docs for the half-open rule).
    pub fn first_passed(&self, old: f64, new: f64) -> Option<f64> {
        if new > old {
            self.next_above(old).filter(|&m| m <= new)
        } else if new < old {
            self.next_below(old).filter(|&m| m >= new)
        } else {
            None
        }
    }
}

/// One electrical edge of the home switch input crossed within a cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwitchEdge {
    /// The boundary crossed (`lo` or `hi`), exact.
    pub position: f64,
    /// The electrical sense of the change.
    pub edge: Edge,
}

/// The home switch: actuated over the inclusive interval `[lo, hi]`, wired
/// normally open or normally closed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Switch {
    lo: f64,
    hi: f64,
    normally_closed: bool,
}

impl Switch {
    /// A switch actuated over `[lo, hi]` (the ends are ordered here).
    pub fn new(lo: f64, hi: f64, normally_closed: bool) -> Self {
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        Self {
            lo,
            hi,
            normally_closed,
        }
    }

    /// The switch is mechanically actuated at `x` (boundaries included).
    pub fn active(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// Electrical level of the input at `x` (true = contact closed): NO closes
    /// when actuated, NC opens when actuated.
    pub fn level(&self, x: f64) -> bool {
        self.active(x) != self.normally_closed
    }

    /// Electrical edge produced by the switch becoming actuated (`true`) or
    /// released (`false`).
    fn edge(&self, actuated: bool) -> Edge {
        if actuated != self.normally_closed {
            Edge::Rising
        } else {
            Edge::Falling
        }
    }

    /// The electrical edges on the segment `old → new`, in order of motion
    /// (at most two: entering and leaving), by the rule in the module docs.
    pub fn edges(&self, old: f64, new: f64) -> [Option<SwitchEdge>; 2] {
        let at = |position: f64, actuated: bool| SwitchEdge {
            position,
            edge: self.edge(actuated),
        };
        // Thresholds of the closed interval: "x >= lo" and "x > hi". On a
        // monotone segment each changes at most once, exactly when its value
        // differs between the ends.
        let enters_lo = (old >= self.lo) != (new >= self.lo);
        let leaves_hi = (old > self.hi) != (new > self.hi);
        if new > old {
            [
                enters_lo.then(|| at(self.lo, true)),
                leaves_hi.then(|| at(self.hi, false)),
            ]
        } else if new < old {
            [
                leaves_hi.then(|| at(self.hi, true)),
                enters_lo.then(|| at(self.lo, false)),
            ]
        } else {
            [None, None]
        }
    }

    /// The first edge of sense `want` on `old → new`, if any.
    pub fn first_edge(&self, old: f64, new: f64, want: Edge) -> Option<f64> {
        self.edges(old, new)
            .into_iter()
            .flatten()
            .find(|e| e.edge == want)
            .map(|e| e.position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marker_neighbours_are_exact() {
        let m = Markers::new(2.5, 10.0);
        assert_eq!(m.next_above(0.0), Some(2.5));
        assert_eq!(m.next_above(2.5), Some(12.5));
        assert_eq!(m.next_below(2.5), Some(-7.5));
        assert_eq!(m.next_below(-7.0), Some(-7.5));
        assert_eq!(m.next_above(-1000.0), Some(-997.5));
        assert!(Markers::new(0.0, 0.0).next_above(1.0).is_none());
    }

    #[test]
    fn half_open_marker_rule() {
        let m = Markers::new(2.5, 10.0);
        // Arriving counts, leaving does not, in both directions.
        assert_eq!(m.first_passed(0.0, 2.5), Some(2.5));
        assert_eq!(m.first_passed(2.5, 5.0), None);
        assert_eq!(m.first_passed(2.5, 0.0), None);
        assert_eq!(m.first_passed(5.0, 2.5), Some(2.5));
        assert_eq!(m.first_passed(2.5, 2.5), None);
        // First in the direction of motion.
        assert_eq!(m.first_passed(0.0, 30.0), Some(2.5));
        assert_eq!(m.first_passed(30.0, 0.0), Some(22.5));
    }

    #[test]
    fn huge_positions_give_no_nan() {
        let m = Markers::new(2.5, 10.0);
        for &(a, b) in &[
            (f64::MAX, -f64::MAX),
            (-f64::MAX, f64::MAX),
            (1e300, 1e300 + 1e290),
            (-1e20, 1e20),
        ] {
            if let Some(p) = m.first_passed(a, b) {
                assert!(p.is_finite());
            }
        }
        let far = Markers::new(-f64::MAX, 1e-300);
        assert!(far.first_passed(f64::MAX, 0.0).is_none_or(f64::is_finite));
    }

    #[test]
    fn switch_levels_no_and_nc() {
        let no = Switch::new(0.0, 5.0, false);
        let nc = Switch::new(0.0, 5.0, true);
        for (x, act) in [
            (-0.1, false),
            (0.0, true),
            (2.0, true),
            (5.0, true),
            (5.1, false),
        ] {
            assert_eq!(no.active(x), act);
            assert_eq!(no.level(x), act, "NO closed when actuated at {x}");
            assert_eq!(nc.level(x), !act, "NC open when actuated at {x}");
        }
    }

    #[test]
    fn boundary_stops_agree_with_the_inclusive_interval() {
        let no = Switch::new(0.0, 5.0, false);
        let rising = |p| SwitchEdge {
            position: p,
            edge: Edge::Rising,
        };
        let falling = |p| SwitchEdge {
            position: p,
            edge: Edge::Falling,
        };
        // Reaching lo from below: entered (level closed at lo).
        assert_eq!(no.edges(-1.0, 0.0), [Some(rising(0.0)), None]);
        // Continuing from lo: nothing new.
        assert_eq!(no.edges(0.0, 1.0), [None, None]);
        // Reversing from lo: left at lo.
        assert_eq!(no.edges(0.0, -1.0), [None, Some(falling(0.0))]);
        // Reaching hi from inside: still actuated, no edge yet.
        assert_eq!(no.edges(4.0, 5.0), [None, None]);
        // Going on past hi: left at hi.
        assert_eq!(no.edges(5.0, 6.0), [None, Some(falling(5.0))]);
        // Reaching hi from above: entered.
        assert_eq!(no.edges(6.0, 5.0), [Some(rising(5.0)), None]);
        // Through the whole switch in one cycle, both ways.
        assert_eq!(no.edges(-1.0, 6.0), [Some(rising(0.0)), Some(falling(5.0))]);
        assert_eq!(no.edges(6.0, -1.0), [Some(rising(5.0)), Some(falling(0.0))]);
        // Point switch.
        let pt = Switch::new(3.0, 3.0, false);
        assert_eq!(pt.edges(2.0, 3.0), [Some(rising(3.0)), None]);
        assert_eq!(pt.edges(3.0, 4.0), [None, Some(falling(3.0))]);
        assert_eq!(pt.edges(2.0, 4.0), [Some(rising(3.0)), Some(falling(3.0))]);
    }

    #[test]
    fn nc_edges_are_inverted() {
        let nc = Switch::new(0.0, 5.0, true);
        assert_eq!(nc.first_edge(-1.0, 6.0, Edge::Falling), Some(0.0));
        assert_eq!(nc.first_edge(-1.0, 6.0, Edge::Rising), Some(5.0));
        assert_eq!(nc.first_edge(6.0, -1.0, Edge::Falling), Some(5.0));
        assert_eq!(nc.first_edge(6.0, -1.0, Edge::Rising), Some(0.0));
    }
}
