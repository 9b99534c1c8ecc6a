//! The trapezoid (no jerk limit): jog to a speed, stop, stop on a point,
//! a setpoint stream's segment, and the point-to-point move from any
//! starting velocity, plain and in a given time. At most four constant
//! acceleration segments; the acceleration steps between them.
//!
//! These are the profiles of homing's legs, of a fault's stop and of every
//! operation planned with `jerk = 0`: their numbers are the ones the engine
//! had before jerk-limited profiles existed, bit for bit. A trapezoid
//! re-planned from a moving state starts from its position and velocity;
//! the acceleration of the state it replaces does not carry over.
//!
//! Acceleration is used while speed magnitude grows, deceleration while it
//! shrinks, which is how Home Acceleration and Home Deceleration are defined.

use super::segments::{Builder, End, Profile};

impl Profile {
    /// Change velocity from `v0` to `v_target` (accelerating at `acc` while the
    /// speed grows, decelerating at `dec` while it shrinks, through zero if the
    /// sign changes), then cruise at `v_target` forever.
    pub fn jog(now_ns: u64, p0: f64, v0: f64, v_target: f64, acc: f64, dec: f64) -> Self {
        let mut b = Builder::new(p0, v0);
        if v0 != 0.0 && (v_target == 0.0 || v0.signum() != v_target.signum()) {
            // Slow down to zero first.
            b.push(-v0.signum() * dec, v0.abs() / dec);
            b.v = 0.0;
            b.push(v_target.signum() * acc, v_target.abs() / acc);
        } else if v_target.abs() >= v0.abs() {
            b.push(v_target.signum() * acc, (v_target.abs() - v0.abs()) / acc);
        } else {
            b.push(-v0.signum() * dec, (v0.abs() - v_target.abs()) / dec);
        }
        b.v = v_target;
        b.finish(now_ns, End::Cruise, v_target)
    }

    /// Decelerate at `dec` to a stop and hold there.
    pub fn stop(now_ns: u64, p0: f64, v0: f64, dec: f64) -> Self {
        let mut b = Builder::new(p0, v0);
        if v0 != 0.0 && dec > 0.0 {
            b.push(-v0.signum() * dec, v0.abs() / dec);
        }
        let p = b.p;
        b.v = 0.0;
        b.finish(now_ns, End::Hold(p), 0.0)
    }

    /// Decelerate uniformly from `(p0, v0)` to rest exactly at `target`
    /// (the deceleration is `v0² / 2|target − p0|`, whatever it takes) and
    /// hold there: a stop that must end on a given point — a travel limit —
    /// and never beyond it. `target` must lie ahead of the motion; a
    /// target behind it, or no motion, holds at `p0`.
    pub fn stop_at(now_ns: u64, p0: f64, v0: f64, target: f64) -> Self {
        let x = target - p0;
        if v0 == 0.0 || x * v0 <= 0.0 {
            return Self::hold(now_ns, p0);
        }
        let mut b = Builder::new(p0, v0);
        let dt = 2.0 * x / v0;
        b.push(-v0 / dt, dt);
        b.v = 0.0;
        b.finish(now_ns, End::Hold(target), 0.0)
    }

    /// From `p0` to `p1` at constant velocity in exactly `duration_ns`, then
    /// hold at `p1`: one interpolated segment of a setpoint stream. At
    /// `now_ns + duration_ns` the sample is `p1` bit for bit.
    pub fn segment(now_ns: u64, p0: f64, p1: f64, duration_ns: u64) -> Self {
        let t = crate::time::ns_to_s(duration_ns);
        if t <= 0.0 {
            return Self::hold(now_ns, p1);
        }
        let mut b = Builder::new(p0, (p1 - p0) / t);
        b.push(0.0, t);
        let mut p = b.finish(now_ns, End::Hold(p1), 0.0);
        // Ends at the requested time exactly, as the sample computes it.
        p.t_end = t;
        p
    }

    /// Time-optimal trapezoid from `(p0, v0)` to rest at `target`, never faster
    /// than `vmax`, accelerating at `acc` and decelerating at `dec`.
    ///
    /// Starting velocity may be anything: toward the target (the profile keeps
    /// going, slowing down first if `v0` exceeds `vmax`), away from it (it stops
    /// and comes back), or too fast to stop in time (it stops past the target
    /// and comes back). Callers that must never reverse check
    /// [`stopping_distance`] first.
    pub fn move_to(
        now_ns: u64,
        p0: f64,
        v0: f64,
        target: f64,
        vmax: f64,
        acc: f64,
        dec: f64,
    ) -> Self {
        let mut b = Builder::new(p0, v0);
        let s = if target >= p0 { 1.0 } else { -1.0 };
        let x = (target - p0) * s;
        let u = v0 * s; // velocity toward the target
        if u < 0.0 {
            // Moving away: stop, then come back from rest.
            b.push(s * dec, -u / dec);
            b.v = 0.0;
            rest_to_rest(&mut b, target, vmax, acc, dec);
        } else {
            let ds = u * u / (2.0 * dec);
            let tol = 1e-9 * (1.0 + x.abs());
            if ds > x + tol {
                // Cannot stop in time: stop past the target, then come back.
                b.push(-s * dec, u / dec);
                b.v = 0.0;
                rest_to_rest(&mut b, target, vmax, acc, dec);
            } else {
                toward(&mut b, s, x, u, vmax, acc, dec);
            }
        }
        b.finish(now_ns, End::Hold(target), 0.0)
    }

    /// From rest at `p0` to rest at `target` in exactly `duration_ns`: the
    /// trapezoid of [`Profile::move_to`] slowed down to a lower cruise speed
    /// (same acceleration and deceleration), so that axes whose moves differ
    /// in length (gantry sides with different offsets) start and end
    /// together. Never faster than its own minimum: a duration shorter than
    /// the time-optimal move gives the time-optimal move.
    ///
    /// With cruise speed `vc`, acceleration `a`, deceleration `d` and
    /// `k = (1/a + 1/d) / 2`, a trapezoid covers `x = vc T - k vc²` in `T`,
    /// so `vc = 2x / (T + sqrt(T² - 4kx))`; `T` above the minimum keeps the
    /// root real and `vc` at or below `vmax`. At `now_ns + duration_ns` the
    /// sample is `target` exactly, and not done before.
    pub fn move_to_in(
        now_ns: u64,
        p0: f64,
        target: f64,
        duration_ns: u64,
        vmax: f64,
        acc: f64,
        dec: f64,
    ) -> Self {
        let fastest = Self::move_to(now_ns, p0, 0.0, target, vmax, acc, dec);
        let t = duration_ns as f64 * 1e-9;
        if t <= fastest.t_end {
            return fastest;
        }
        let s = if target >= p0 { 1.0 } else { -1.0 };
        let x = (target - p0) * s;
        let k = 0.5 * (1.0 / acc + 1.0 / dec);
        let vc = (2.0 * x / (t + (t * t - 4.0 * k * x).max(0.0).sqrt())).min(vmax);
        let mut b = Builder::new(p0, 0.0);
        let (ta, td) = (vc / acc, vc / dec);
        b.push(s * acc, ta);
        b.push(0.0, t - ta - td);
        b.push(-s * dec, td);
        let mut p = b.finish(now_ns, End::Hold(target), 0.0);
        // Ends at the requested time exactly (the segment sum may differ in
        // the last bit).
        p.t_end = t;
        p
    }
}

/// Distance needed to stop from `v` at deceleration `dec`.
pub fn stopping_distance(v: f64, dec: f64) -> f64 {
    if dec > 0.0 {
        v * v / (2.0 * dec)
    } else {
        f64::INFINITY
    }
}

/// True if a move from `(p, v)` to rest at `target` needs no reversal: at
/// rest anything is reachable; moving, the velocity must point at the target
/// and the stopping distance must fit (with the same rounding tolerance that
/// [`Profile::move_to`] uses to decide it need not overshoot).
pub fn reaches_without_reversing(p: f64, v: f64, target: f64, dec: f64) -> bool {
    let x = target - p;
    if v == 0.0 {
        return true;
    }
    if x * v <= 0.0 {
        return false;
    }
    stopping_distance(v, dec) <= x.abs() + 1e-9 * (1.0 + x.abs())
}

/// From rest at the builder's position to rest at `target`.
fn rest_to_rest(b: &mut Builder, target: f64, vmax: f64, acc: f64, dec: f64) {
    let s = if target >= b.p { 1.0 } else { -1.0 };
    let x = (target - b.p) * s;
    toward(b, s, x, 0.0, vmax, acc, dec);
}

/// Moving toward the target at `u >= 0` with room to stop (`u²/2dec <= x`):
/// slow to `vmax` if above it, else accelerate to the peak speed, cruise if the
/// peak reaches `vmax`, and decelerate to rest exactly `x` further on.
fn toward(b: &mut Builder, s: f64, x: f64, u: f64, vmax: f64, acc: f64, dec: f64) {
    if u > vmax {
        b.push(-s * dec, (u - vmax) / dec);
        let x1 = x - (u * u - vmax * vmax) / (2.0 * dec);
        let cruise = (x1 - vmax * vmax / (2.0 * dec)).max(0.0);
        b.push(0.0, cruise / vmax);
        b.push(-s * dec, vmax / dec);
        return;
    }
    let peak2 = (x + u * u / (2.0 * acc)) / (0.5 / acc + 0.5 / dec);
    let peak = peak2.max(0.0).sqrt().max(u);
    if peak > vmax {
        let d_acc = (vmax * vmax - u * u) / (2.0 * acc);
        let d_dec = vmax * vmax / (2.0 * dec);
        b.push(s * acc, (vmax - u) / acc);
        b.push(0.0, ((x - d_acc - d_dec).max(0.0)) / vmax);
        b.push(-s * dec, vmax / dec);
    } else {
        b.push(s * acc, (peak - u) / acc);
        b.push(-s * dec, peak / dec);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: u64 = 1_000_000; // 1 ms

    /// Samples a profile every `T` until it is done (or `max` cycles).
    fn run(p: &Profile, max: usize) -> Vec<(f64, f64)> {
        (0..max).map(|k| p.sample(k as u64 * T)).collect()
    }

    fn check_limits(xs: &[(f64, f64)], vmax: f64, acc: f64, dec: f64) {
        let dt = T as f64 * 1e-9;
        let v: Vec<f64> = xs.windows(2).map(|w| (w[1].0 - w[0].0) / dt).collect();
        for s in &v {
            assert!(s.abs() <= vmax * (1.0 + 1e-9) + 1e-9, "speed {s} > {vmax}");
        }
        for w in v.windows(2) {
            let dv = (w[1] - w[0]) / dt;
            let lim = if w[0].signum() == w[1].signum() && w[1].abs() > w[0].abs() {
                acc
            } else if w[0].signum() == w[1].signum() {
                dec
            } else {
                acc.max(dec)
            };
            assert!(dv.abs() <= lim * (1.0 + 1e-6) + 1e-6, "accel {dv} > {lim}");
        }
    }

    #[test]
    fn rest_to_rest_trapezoid_lands_exactly() {
        let p = Profile::move_to(0, 0.0, 0.0, 10.0, 20.0, 500.0, 250.0);
        let xs = run(&p, 2000);
        check_limits(&xs, 20.0, 500.0, 250.0);
        assert_eq!(p.sample(10_000 * T), (10.0, 0.0));
        // accel 0.04 s, decel 0.08 s, cruise (10 - 0.4 - 0.8)/20 = 0.44 s
        assert!((p.t_end - 0.56).abs() < 1e-12);
        assert!(p.is_done(560 * T + 1));
    }

    #[test]
    fn triangle_when_too_short_to_cruise() {
        let p = Profile::move_to(0, 0.0, 0.0, -0.1, 20.0, 500.0, 500.0);
        let xs = run(&p, 100);
        check_limits(&xs, 20.0, 500.0, 500.0);
        // peak = sqrt(0.1 * 500) = 7.07 < 20
        assert!((p.t_end - 2.0 * (50.0f64).sqrt() / 500.0).abs() < 1e-12);
        assert_eq!(xs.last().unwrap().0, -0.1);
    }

    #[test]
    fn moving_start_toward_target_continues_without_reversing() {
        // At 20 u/s, 4 units to go, stopping distance 0.4.
        let p = Profile::move_to(0, 0.0, 20.0, 4.0, 20.0, 500.0, 500.0);
        let xs = run(&p, 400);
        check_limits(&xs, 20.0, 500.0, 500.0);
        assert!(xs.windows(2).all(|w| w[1].0 >= w[0].0));
        assert_eq!(xs.last().unwrap().0, 4.0);
    }

    #[test]
    fn moving_start_faster_than_vmax_slows_first() {
        let p = Profile::move_to(0, 0.0, 30.0, 10.0, 20.0, 500.0, 500.0);
        let xs = run(&p, 1000);
        check_limits(&xs[21..], 20.0, 500.0, 500.0);
        assert_eq!(xs.last().unwrap().0, 10.0);
    }

    #[test]
    fn moving_away_stops_and_comes_back() {
        let p = Profile::move_to(0, 0.0, -20.0, 1.0, 5.0, 500.0, 400.0);
        let xs = run(&p, 2000);
        check_limits(&xs, 20.0, 500.0, 500.0);
        let min = xs.iter().map(|x| x.0).fold(f64::INFINITY, f64::min);
        assert!(
            (min - -0.5).abs() < 1e-3,
            "stops 20²/800 = 0.5 behind: {min}"
        );
        assert_eq!(xs.last().unwrap().0, 1.0);
    }

    #[test]
    fn overshoot_when_target_too_close() {
        let p = Profile::move_to(0, 0.0, 20.0, 0.1, 20.0, 500.0, 500.0);
        let xs = run(&p, 2000);
        let max = xs.iter().map(|x| x.0).fold(f64::NEG_INFINITY, f64::max);
        assert!((max - 0.4).abs() < 1e-3);
        assert_eq!(xs.last().unwrap().0, 0.1);
    }

    #[test]
    fn jog_reverses_through_zero() {
        let p = Profile::jog(0, 0.0, 10.0, -2.0, 100.0, 50.0);
        let xs = run(&p, 1000);
        check_limits(&xs, 10.0, 100.0, 50.0);
        // 0.2 s decel, 0.02 s accel, then cruise at -2.
        assert_eq!(p.sample(500 * T).1, -2.0);
        let (p1, _) = p.sample(300 * T);
        let (p2, _) = p.sample(400 * T);
        assert!(((p2 - p1) / 0.1 - -2.0).abs() < 1e-9);
    }

    #[test]
    fn stop_holds_where_it_stops() {
        let p = Profile::stop(0, 1.0, -10.0, 100.0);
        assert_eq!(p.sample(10 * T * 1000).0, p.end_position());
        assert!((p.end_position() - 0.5).abs() < 1e-12);
        assert!(!Profile::jog(0, 0.0, 0.0, 1.0, 1.0, 1.0).is_done(u64::MAX));
    }

    #[test]
    fn timed_move_takes_exactly_its_time_within_the_limits() {
        // 10 units, vmax 20, acc 500, dec 250: fastest 0.56 s (see above).
        // In 1 s: k = (1/500 + 1/250) / 2 = 0.003,
        // vc = 20 / (1 + sqrt(1 - 0.12)) = 10.3196 u/s (below 20).
        let p = Profile::move_to_in(0, 0.0, 10.0, 1_000 * T, 20.0, 500.0, 250.0);
        let vc = 20.0 / (1.0 + 0.88f64.sqrt());
        assert!((p.sample(500 * T).1 - vc).abs() < 1e-9);
        let xs = run(&p, 1200);
        check_limits(&xs, vc, 500.0, 250.0);
        assert_eq!(p.sample(1_000 * T), (10.0, 0.0));
        assert!(p.sample(999 * T).0 < 10.0);
        assert!(p.is_done(1_000 * T) && !p.is_done(1_000 * T - 1));
        assert_eq!(p.duration_ns(), 1_000 * T);
        assert!(xs.windows(2).all(|w| w[1].0 >= w[0].0), "never reverses");
    }

    #[test]
    fn timed_move_is_never_faster_than_its_minimum() {
        let fastest = Profile::move_to(0, 0.0, 0.0, 10.0, 20.0, 500.0, 250.0);
        let p = Profile::move_to_in(0, 0.0, 10.0, 300 * T, 20.0, 500.0, 250.0);
        assert_eq!(p, fastest);
        assert_eq!(p.duration_ns(), 560 * T);
    }

    #[test]
    fn timed_moves_of_any_length_and_time() {
        for (x, ms) in [
            (-0.1, 40),
            (-0.1, 1000),
            (3.0, 200),
            (250.0, 20_000),
            (1e-6, 7),
        ] {
            let min = Profile::move_to(0, 5.0, 0.0, 5.0 + x, 20.0, 500.0, 400.0);
            let p = Profile::move_to_in(0, 5.0, 5.0 + x, ms * T, 20.0, 500.0, 400.0);
            let end = (ms * T).max(min.duration_ns());
            let xs = run(&p, (end / T) as usize + 3);
            check_limits(&xs, 20.0, 500.0, 400.0);
            assert_eq!(p.sample(end), (5.0 + x, 0.0), "{x} in {ms} ms");
            assert!(p.is_done(end) && !p.is_done(end - 1), "{x} in {ms} ms");
        }
    }

    #[test]
    fn timed_zero_length_move_holds_until_its_time() {
        let p = Profile::move_to_in(0, 3.0, 3.0, 500 * T, 1.0, 1.0, 1.0);
        assert_eq!(p.sample(250 * T), (3.0, 0.0));
        assert!(!p.is_done(499 * T) && p.is_done(500 * T));
    }

    #[test]
    fn stop_at_ends_on_its_target_and_never_beyond() {
        // 20 u/s, 0.3 to go: a = 400 / 0.6 = 666.7 u/s², 0.03 s.
        let p = Profile::stop_at(0, 9.7, 20.0, 10.0);
        let xs = run(&p, 40);
        assert!(xs.iter().all(|x| x.0 <= 10.0), "{xs:?}");
        assert!(xs.windows(2).all(|w| w[1].0 >= w[0].0));
        // Done after 2 × 0.3 / 20 = 0.03 s (give or take the rounding of
        // that duration), exactly on the target.
        assert!((p.sample(30 * T).0 - 10.0).abs() < 1e-12);
        assert_eq!(p.sample(31 * T), (10.0, 0.0));
        assert!(!p.is_done(29 * T) && p.is_done(31 * T));
        check_limits(&xs, 20.0, 0.0, 400.0 / 0.6);
        // Backwards, and the degenerate cases: a hold where it stands.
        let p = Profile::stop_at(0, -9.7, -20.0, -10.0);
        assert_eq!(p.sample(31 * T), (-10.0, 0.0));
        assert_eq!(Profile::stop_at(0, 1.0, 5.0, 0.5).sample(T), (1.0, 0.0));
        assert_eq!(Profile::stop_at(0, 1.0, 0.0, 2.0).sample(T), (1.0, 0.0));
    }

    #[test]
    fn a_segment_runs_at_constant_velocity_and_lands_exactly() {
        let p = Profile::segment(5 * T, 1.0, 1.1, 10 * T);
        for k in 0..=10u64 {
            let (x, v) = p.sample(5 * T + k * T);
            if k < 10 {
                assert!((x - (1.0 + 0.01 * k as f64)).abs() < 1e-12, "{k}: {x}");
                assert!((v - 10.0).abs() < 1e-9, "{v}");
            } else {
                assert_eq!((x, v), (1.1, 0.0));
            }
        }
        assert_eq!(Profile::segment(0, 1.0, 2.0, T).sample(T), (2.0, 0.0));
        assert_eq!(Profile::segment(0, 1.0, 2.0, 0).sample(0), (2.0, 0.0));
    }

    #[test]
    fn zero_length_move_is_a_hold() {
        let p = Profile::move_to(0, 3.0, 0.0, 3.0, 1.0, 1.0, 1.0);
        assert_eq!(p.sample(0), (3.0, 0.0));
        assert!(p.is_done(0));
    }
}
