//! The stream's bounded follower: one cycle of the command towards the
//! setpoints' reference path, never faster or harder than the limits —
//! pure arithmetic, no state of its own (the stream keeps the command's
//! position and velocity).
//!
//! It is LinuxCNC's `simple_tp` (the velocity that still lets the command
//! stop on its target at the acceleration bound, `√(a²T² + 2a·d) − aT`)
//! in the frame moving with the reference: the distance `d` is what lies
//! between the command and the reference after this cycle if the command
//! moved at the reference's velocity. Where the reference is reachable
//! within the bounds (a stream at the cycle rate, an interpolated segment
//! whose corners need no more than `a × cycle`), the command lands on it
//! bit for bit; where it is not, the command closes in as fast as the
//! bounds allow, without overshooting the reference's motion.
//!
//! Then, in this order: inside the travel limits (never faster than a stop
//! at `a` ending on the limit allows), within `a × cycle` of the last
//! cycle's velocity, within the speed cap. A command already above the cap
//! (the cap fell: the reference was cleared) slows down at `a`.

/// What bounds one cycle of the follower.
#[derive(Clone, Copy, Debug)]
pub(super) struct Bounds {
    /// Speed cap, units/s.
    pub cap: f64,
    /// Acceleration bound, units/s² (also the braking at the limits).
    pub accel: f64,
    /// Travel limits (raw), while they are enforced.
    pub limits: Option<(f64, f64)>,
}

/// One cycle's command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Step {
    pub position: f64,
    /// Over this cycle, units/s.
    pub velocity: f64,
    /// Exactly on the reference.
    pub on_reference: bool,
    /// The speed cap held it back (else, if it is off the reference, the
    /// acceleration bound or a limit did).
    pub capped: bool,
}

/// The fastest a command at distance `room` from a limit may move towards
/// it and still stop on it at `accel` (0 at or beyond it).
fn braking(room: f64, accel: f64, at: f64) -> f64 {
    if room > 0.0 {
        (at * at + 2.0 * accel * room).sqrt() - at
    } else {
        0.0
    }
}

/// One cycle of `dt` s (> 0) from command `(x, v)` towards reference
/// position `r` (at the end of the cycle) moving at `u`.
pub(super) fn step(x: f64, v: f64, r: f64, u: f64, dt: f64, b: &Bounds) -> Step {
    let at = b.accel * dt;
    let d = r - x - u * dt;
    let catch_up = (at * at + 2.0 * b.accel * d.abs()).sqrt() - at;
    let mut w = u + catch_up.copysign(d);
    if let Some((lo, hi)) = b.limits {
        w = w
            .min(braking(hi - x, b.accel, at))
            .max(-braking(x - lo, b.accel, at));
    }
    // Held back by the cap: it asks for more than the cap, and the cap is
    // the nearer of the two bounds.
    let capped = (w > b.cap && b.cap <= v + at) || (w < -b.cap && -b.cap >= v - at);
    let (slowest, fastest) = ((v - at).max(-b.cap), (v + at).min(b.cap));
    w = if slowest <= fastest {
        w.clamp(slowest, fastest)
    } else if v > 0.0 {
        v - at
    } else {
        v + at
    };
    let mut position = x + w * dt;
    let on_reference = (position - r).abs() <= 1e-12 * (1.0 + r.abs());
    if on_reference {
        position = r;
        w = (r - x) / dt;
    }
    if let Some((lo, hi)) = b.limits {
        // Never further out (only a command already outside can get here:
        // homed again beyond a limit).
        let inside = position.clamp(lo.min(x), hi.max(x));
        if inside != position {
            position = inside;
            w = (inside - x) / dt;
        }
    }
    Step {
        position,
        velocity: w,
        on_reference,
        capped,
    }
}

/// How far the command may lag the reference before the stream is
/// refused: the distance it needs to stop from the cap at `accel`, plus
/// one cycle at the cap — what a pause of the program at full speed costs
/// (the command brakes past the last setpoint), and more than the corner
/// of any stream whose setpoints pass the checks on its own timeline
/// every cycle or so.
pub(super) fn lag_bound(cap: f64, accel: f64, cycle_s: f64) -> f64 {
    cap * cap / (2.0 * accel) + cap * cycle_s
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: f64 = 1e-3;
    const B: Bounds = Bounds {
        cap: 50.0,
        accel: 5000.0,
        limits: None,
    };

    /// Follows `reference(k) -> (r, u)` for `n` cycles from rest at 0.
    fn run(n: usize, b: &Bounds, reference: impl Fn(usize) -> (f64, f64)) -> Vec<Step> {
        let (mut x, mut v) = (0.0, 0.0);
        (0..n)
            .map(|k| {
                let (r, u) = reference(k);
                let s = step(x, v, r, u, T, b);
                (x, v) = (s.position, s.velocity);
                s
            })
            .collect()
    }

    fn bounded(steps: &[Step], b: &Bounds) {
        let mut v = 0.0;
        for (k, s) in steps.iter().enumerate() {
            assert!(s.velocity.abs() <= b.cap * (1.0 + 1e-12), "{k}: {s:?}");
            let dv = (s.velocity - v).abs();
            assert!(dv <= b.accel * T * (1.0 + 1e-9), "{k}: Δv {dv}");
            v = s.velocity;
        }
    }

    #[test]
    fn a_reachable_reference_is_followed_exactly() {
        // 1 kHz samples of a ramp to 10 u/s at 1000 u/s²: on it every cycle.
        let p = |k: usize| {
            let t = (k + 1) as f64 * T;
            let (tr, v) = (0.01, 10.0);
            if t < tr {
                500.0 * t * t
            } else {
                0.05 + v * (t - tr)
            }
        };
        let steps = run(100, &B, |k| {
            let prev = if k == 0 { 0.0 } else { p(k - 1) };
            (p(k), (p(k) - prev) / T)
        });
        for (k, s) in steps.iter().enumerate() {
            assert!(s.on_reference, "{k}: {s:?}");
            assert_eq!(s.position, p(k));
        }
    }

    #[test]
    fn a_jump_is_followed_at_the_bounds_without_overshoot() {
        // The reference jumps to 9 and rests: accelerate at 5000 to 50,
        // cruise, brake at 5000, land on it (no overshoot).
        let steps = run(400, &B, |_| (9.0, 0.0));
        bounded(&steps, &B);
        assert!(steps.iter().all(|s| s.position <= 9.0 + 1e-12));
        assert_eq!(steps.last().unwrap().position, 9.0);
        assert!(steps.iter().any(|s| s.capped));
    }

    #[test]
    fn a_reversal_of_the_reference_is_rounded_at_the_bounds() {
        // +50 u/s, then at 0.1 s −50 u/s: the command cannot turn in one
        // cycle; it brakes and turns at 5000 u/s² and catches up.
        let r = |k: usize| {
            let t = (k + 1) as f64 * T;
            if t <= 0.1 {
                (50.0 * t, 50.0)
            } else {
                (5.0 - 50.0 * (t - 0.1), -50.0)
            }
        };
        // From on the reference at full speed.
        let mut steps = Vec::new();
        let (mut x, mut v) = (0.0, 50.0);
        for k in 0..200 {
            let (p, u) = r(k);
            let s = step(x, v, p, u, T, &B);
            (x, v) = (s.position, s.velocity);
            steps.push(s);
        }
        let mut prev = 50.0;
        for s in &steps {
            assert!((s.velocity - prev).abs() <= 5.0 + 1e-9);
            prev = s.velocity;
        }
        let most = steps.iter().map(|s| s.position).fold(f64::MIN, f64::max);
        assert!(most < 5.0 + 50.0 * 50.0 / 10_000.0 + 0.05, "{most}");
    }

    #[test]
    fn limits_are_never_passed_and_a_fallen_cap_is_reached_at_the_bound() {
        let b = Bounds {
            limits: Some((-1.0, 1.0)),
            ..B
        };
        // A reference beyond the limit: the command stops on the limit.
        let steps = run(300, &b, |_| (5.0, 0.0));
        bounded(&steps, &b);
        assert!(steps.iter().all(|s| s.position <= 1.0));
        assert!((steps.last().unwrap().position - 1.0).abs() < 1e-9);
        // Moving at 40 when the cap falls to 10: down by 5 per cycle.
        let low = Bounds { cap: 10.0, ..B };
        let s = step(0.0, 40.0, 1.0, 40.0, T, &low);
        assert_eq!(s.velocity, 35.0);
        assert!(s.capped);
    }

    #[test]
    fn the_lag_bound_is_the_stop_from_the_cap_plus_a_cycle() {
        assert_eq!(lag_bound(50.0, 5000.0, 1e-3), 0.25 + 0.05);
    }
}
