//! The monitor's own stop: one constant deceleration from the last
//! command it passed to rest (EN 60204-1 category 1: stop, then the power
//! stage off). Written here on purpose and sharing nothing with the
//! engine's profiles, so that a fault in those cannot be the fault of the
//! stop that is meant to catch it.

use motion_homing::time::ns_to_s;

/// A constant-deceleration stop from `(p0, v0)` at `t0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Ramp {
    t0: u64,
    p0: f64,
    v0: f64,
    /// Deceleration, units/s², > 0 (infinite: at rest at once).
    decel: f64,
}

impl Ramp {
    /// A stop from `(p0, v0)` at `t0_ns` at `decel`, or — when that would
    /// carry it past `limit` (the soft limit ahead, raw) from inside — the
    /// harder deceleration that ends exactly on it; one already at or past
    /// that limit stops at once. `decel` must be positive.
    pub fn new(t0_ns: u64, p0: f64, v0: f64, decel: f64, limit: Option<f64>) -> Self {
        let mut r = Self {
            t0: t0_ns,
            p0,
            v0,
            decel,
        };
        if let Some(l) = limit.filter(|_| v0 != 0.0) {
            let room = (l - p0) * v0.signum();
            if room <= 0.0 {
                r.v0 = 0.0;
            } else if (r.end() - l) * v0.signum() > 0.0 {
                r.decel = v0 * v0 / (2.0 * room);
            }
        }
        r
    }

    /// Where it comes to rest.
    pub fn end(&self) -> f64 {
        self.p0 + self.v0 * self.v0.abs() / (2.0 * self.decel)
    }

    /// Position and velocity at `t_ns`, and whether it is at rest.
    pub fn at(&self, t_ns: u64) -> (f64, f64, bool) {
        let stop_s = self.v0.abs() / self.decel;
        let t = ns_to_s(t_ns.saturating_sub(self.t0));
        let moving = t < stop_s;
        if !moving {
            return (self.end_or_start(), 0.0, true);
        }
        let a = -self.decel * self.v0.signum();
        (
            self.p0 + self.v0 * t + 0.5 * a * t * t,
            self.v0 + a * t,
            false,
        )
    }

    /// The rest position (the start when there is no motion to stop).
    fn end_or_start(&self) -> f64 {
        if self.v0 == 0.0 {
            self.p0
        } else {
            self.end()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    #[test]
    fn it_stops_at_its_deceleration_and_stays() {
        let r = Ramp::new(10 * MS, 1.0, 20.0, 500.0, None);
        assert_eq!(r.end(), 1.4);
        let (p, v, done) = r.at(30 * MS);
        assert!((p - (1.0 + 0.4 - 0.1)).abs() < 1e-12 && (v - 10.0).abs() < 1e-12 && !done);
        assert_eq!(r.at(50 * MS), (1.4, 0.0, true));
        assert_eq!(r.at(5 * MS), (1.0, 20.0, false), "before its start");
        let back = Ramp::new(0, 0.0, -10.0, 1000.0, None);
        assert_eq!(back.at(MS * 100), (-0.05, 0.0, true));
    }

    #[test]
    fn it_ends_on_a_soft_limit_it_would_pass_and_never_moves_out() {
        let r = Ramp::new(0, 9.8, 20.0, 500.0, Some(10.0));
        assert!((r.end() - 10.0).abs() < 1e-12, "{}", r.end());
        assert_eq!(r.at(MS * 1000).0, r.end());
        let out = Ramp::new(0, 10.2, 20.0, 500.0, Some(10.0));
        assert_eq!(out.at(MS), (10.2, 0.0, true));
        let inside = Ramp::new(0, 5.0, 20.0, 500.0, Some(10.0));
        assert_eq!(inside.end(), 5.4);
        let infinite = Ramp::new(0, 5.0, 20.0, f64::INFINITY, None);
        assert_eq!(infinite.at(0), (5.0, 0.0, true));
    }
}
