//! A gantry's sides together: while every side's drive follows its
//! command and no side homes (homing moves the sides apart on purpose, and
//! its coordinator measures their skew), the distance between each side's
//! command and the first side's stays within `max_skew` of what it was
//! when they last stood together. Judged on the commands each side's
//! monitor passed, after every side's own verdict.

use crate::monitor::{POSITION_ROUNDING, TOLERANCE};

/// Most sides of a gantry (the cycle addresses axes by a 64-bit mask).
pub const MAX_SIDES: usize = 64;

/// One side in this cycle, as its monitor passed it.
#[derive(Clone, Copy, Debug, Default)]
pub struct Side {
    /// The command (raw), units.
    pub position: f64,
    /// Its drive follows the command.
    pub following: bool,
    /// It homes (or its homing's abort comes to rest).
    pub homing: bool,
    /// Its command moved since the cycle before.
    pub moved: bool,
}

/// The sides apart: which side, how far from where it stood, the bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Apart {
    pub side: usize,
    pub value: f64,
    pub bound: f64,
}

/// The sides of one gantry.
#[derive(Clone, Debug)]
pub struct Together {
    max_skew: f64,
    /// Per side, its distance from the first side when they last stood
    /// together (or the rule was last suspended).
    base: [f64; MAX_SIDES],
}

impl Together {
    pub fn new(max_skew: f64) -> Self {
        Self {
            max_skew: if max_skew.is_nan() { 0.0 } else { max_skew },
            base: [0.0; MAX_SIDES],
        }
    }

    /// This cycle's sides (the first one is the reference; beyond
    /// [`MAX_SIDES`] they are not looked at).
    pub fn judge<I>(&mut self, sides: I) -> Result<(), Apart>
    where
        I: Iterator<Item = Side> + Clone,
    {
        let Some(first) = sides.clone().next() else {
            return Ok(());
        };
        let suspended = sides.clone().any(|s| s.homing || !s.following);
        let resting = sides.clone().all(|s| !s.moved);
        let all = sides.take(MAX_SIDES).enumerate();
        if suspended || resting {
            for (i, s) in all {
                self.base[i] = s.position - first.position;
            }
            return Ok(());
        }
        for (i, s) in all {
            let change = (s.position - first.position - self.base[i]).abs();
            let eps = POSITION_ROUNDING * (1.0 + s.position.abs().max(first.position.abs()));
            let together = change <= self.max_skew * (1.0 + TOLERANCE) + eps;
            if !together {
                return Err(Apart {
                    side: i,
                    value: change,
                    bound: self.max_skew,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sides(p: &[f64], moved: bool) -> impl Iterator<Item = Side> + Clone + '_ {
        p.iter().map(move |&position| Side {
            position,
            following: true,
            homing: false,
            moved,
        })
    }

    #[test]
    fn sides_that_move_apart_beyond_max_skew_are_caught_from_where_they_stood() {
        let mut g = Together::new(0.5);
        // racked 2.0 at rest: that is where they stand
        assert!(g.judge(sides(&[0.0, 2.0], false)).is_ok());
        assert!(g.judge(sides(&[1.0, 3.4], true)).is_ok());
        let e = g.judge(sides(&[2.0, 4.6], true)).unwrap_err();
        assert_eq!(e.side, 1);
        assert!((e.value - 0.6).abs() < 1e-12 && e.bound == 0.5);
        // homing moves them apart on purpose: not judged, and from there on
        let homing = [0.0, 9.0].map(|position| Side {
            position,
            following: true,
            homing: true,
            moved: true,
        });
        assert!(g.judge(homing.iter().copied()).is_ok());
        assert!(g.judge(sides(&[0.3, 9.3], true)).is_ok());
    }
}
