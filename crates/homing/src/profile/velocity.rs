//! The jerk-limited velocity change every S-curve is made of: from any
//! velocity and acceleration to a velocity at zero acceleration, as fast as
//! the acceleration bounds and the jerk allow.
//!
//! Three phases at most: the jerk takes the acceleration to a peak, the
//! peak is held, the jerk takes it back to zero. Let `v_r = v + a·|a|/2j`
//! be the velocity reached by bringing the acceleration to zero at once.
//! Below the goal `v1` the change goes up (above it, mirrored: down), with
//! the peak `a_p = √(j·(v1 − v) + a²/2)`: the up ramp from `a` to `a_p`
//! gains `(a_p² − a²)/2j`, the ramp back down `a_p²/2j`, which add up to
//! `v1 − v`. A peak beyond the bound is cut to the bound and held for as
//! long as the rest of the change takes. A start beyond the bound comes
//! back to it at the jerk first (the same ramp, downwards). This is the
//! time-optimal change (the velocity interface of Ruckig solves the same
//! problem): every phase runs at a bound.

/// Phases of a change: `(jerk, duration)`, run in order from the start's
/// acceleration (the middle one holds the peak at zero jerk).
pub(super) type Phases = [(f64, f64); 3];

/// The time-optimal change from velocity `v` and acceleration `a` to
/// velocity `v1` with zero acceleration, with accelerations in
/// `[-down, up]` and jerk in `[-j, j]`. Bounds and jerk must be positive
/// and finite (the planners check); durations may come out 0 (dropped by
/// the builder).
pub(super) fn change(v: f64, a: f64, v1: f64, up: f64, down: f64, j: f64) -> Phases {
    let v_r = v + a * a.abs() / (2.0 * j);
    // Work upwards: mirror a change that goes down.
    let (s, v, a, v1, bound) = if v_r <= v1 {
        (1.0, v, a, v1, up)
    } else {
        (-1.0, -v, -a, -v1, down)
    };
    let free = ((v1 - v) * j + 0.5 * a * a).max(0.0).sqrt();
    let peak = free.min(bound);
    let t1 = (peak - a).abs() / j;
    let j1 = if peak >= a { j } else { -j };
    let t3 = peak / j;
    let t2 = if free > bound {
        let dv1 = 0.5 * (a + peak) * t1;
        let dv3 = 0.5 * peak * t3;
        ((v1 - v - dv1 - dv3) / peak).max(0.0)
    } else {
        0.0
    };
    [(s * j1, t1), (0.0, t2), (-s * j, t3)]
}

/// Displacement and duration of `phases` run from velocity `v` and
/// acceleration `a` (the acceleration of a zero-jerk phase is the one the
/// phase before it ended with).
pub(super) fn travel(v: f64, a: f64, phases: &Phases) -> (f64, f64) {
    let (mut p, mut v, mut a, mut t) = (0.0, v, a, 0.0);
    for &(j, dt) in phases {
        if dt > 0.0 {
            (p, v, a) = super::segments::advance(p, v, a, j, dt);
            t += dt;
        }
    }
    (p, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the phases; returns the end velocity and acceleration, and the
    /// extreme accelerations on the way.
    fn run(v: f64, a: f64, ph: &Phases) -> (f64, f64, f64, f64) {
        let (mut v, mut a) = (v, a);
        let (mut lo, mut hi) = (a, a);
        for &(j, dt) in ph {
            v += a * dt + 0.5 * j * dt * dt;
            a += j * dt;
            lo = lo.min(a);
            hi = hi.max(a);
        }
        (v, a, lo, hi)
    }

    #[test]
    fn from_rest_reaching_the_bound_holds_it() {
        // 0 → 10 at a ≤ 100, j = 1000: ramps of 0.1 s gain 5 each...
        // 10 − 2·(100²/2000) = 0 left: exactly the two ramps.
        let ph = change(0.0, 0.0, 10.0, 100.0, 50.0, 1000.0);
        assert_eq!(ph[0], (1000.0, 0.1));
        assert_eq!(ph[1].1, 0.0);
        assert_eq!(ph[2], (-1000.0, 0.1));
        // 0 → 20: 10 more at 100 u/s²: a 0.1 s hold.
        let ph = change(0.0, 0.0, 20.0, 100.0, 50.0, 1000.0);
        assert!((ph[1].1 - 0.1).abs() < 1e-12, "{ph:?}");
        let (v, a, lo, hi) = run(0.0, 0.0, &ph);
        assert!((v - 20.0).abs() < 1e-12 && a.abs() < 1e-12 && lo >= 0.0 && hi <= 100.0);
    }

    #[test]
    fn below_the_bound_a_triangle() {
        // 0 → 1 at j = 1000: peak √1000 ≈ 31.6 < 100, 2 × 0.0316 s.
        let ph = change(0.0, 0.0, 1.0, 100.0, 100.0, 1000.0);
        let peak = 1000f64.sqrt();
        assert!((ph[0].1 - peak / 1000.0).abs() < 1e-15);
        assert_eq!(ph[1].1, 0.0);
        let (v, a, _, hi) = run(0.0, 0.0, &ph);
        assert!((v - 1.0).abs() < 1e-12 && a.abs() < 1e-12 && hi <= peak + 1e-12);
    }

    #[test]
    fn down_uses_the_lower_bound_and_any_start_acceleration() {
        // 20 → 0 with a = +40 at the start: up to 0 first (the speed
        // still grows), down to −50, back to 0.
        let ph = change(20.0, 40.0, 0.0, 100.0, 50.0, 1000.0);
        assert_eq!(ph[0].0, -1000.0);
        assert!((ph[0].1 - 0.09).abs() < 1e-12, "{ph:?}");
        let (v, a, lo, hi) = run(20.0, 40.0, &ph);
        assert!(v.abs() < 1e-12 && a.abs() < 1e-12, "{v} {a}");
        assert!(lo >= -50.0 - 1e-12 && hi <= 40.0);
        // A start beyond the bound comes back to it at the jerk.
        let ph = change(0.0, 300.0, 100.0, 100.0, 50.0, 1000.0);
        assert_eq!(ph[0].0, -1000.0);
        assert!((ph[0].1 - 0.2).abs() < 1e-12);
        let (v, a, _, _) = run(0.0, 300.0, &ph);
        assert!((v - 100.0).abs() < 1e-9 && a.abs() < 1e-12, "{v} {a}");
    }

    #[test]
    fn already_there_ramps_the_acceleration_out() {
        // v_r = 5 + 100²/2000 = 10: just the ramp down.
        let ph = change(5.0, 100.0, 10.0, 100.0, 100.0, 1000.0);
        assert_eq!(ph[0].1, 0.0);
        assert_eq!(ph[1].1, 0.0);
        assert!((ph[2].1 - 0.1).abs() < 1e-15);
        let (d, t) = travel(5.0, 100.0, &ph);
        // 5·0.1 + 100·0.01/2 − 1000·0.001/6
        assert!((d - (0.5 + 0.5 - 1.0 / 6.0)).abs() < 1e-12 && (t - 0.1).abs() < 1e-15);
    }
}
