//! The jerk-limited (S-curve) planners: jog, stop, move, stop on a point
//! and the timed move, from any position, velocity and acceleration.
//!
//! Every profile is a chain of the velocity changes of
//! [`velocity`](super::velocity) (each ends at zero acceleration) and
//! cruises, so the acceleration is continuous and the jerk is `±j` or 0
//! throughout. The bounds follow the direction of motion, as the
//! trapezoid's do: while moving in direction `s` the signed acceleration
//! stays in `[-dec, acc]·s`; a stop uses `dec` both ways.
//!
//! * **Jog** (MAJ): one change to the target velocity. Against the current
//!   motion, the faster of a stop to rest and a change from there, and one
//!   change that holds its acceleration through zero speed within both
//!   `acc` and `dec` (it brakes on one side of zero and speeds up on the
//!   other).
//! * **Stop** (MAS and every normal stop): one change to zero at `dec`.
//! * **Move** (MAM): up to a peak speed `v_p`, cruise, down to rest exactly
//!   on the target. `v_p` is the largest speed ≤ the cap whose change up
//!   and change down fit the distance, found by [`solve`](super::solve)
//!   from the speed the motion reaches by easing its acceleration to zero
//!   at once (one root above it). With less room than that (braking
//!   already), the acceleration eases off only part of the way before the
//!   stop. A start that must turn back (moving away, too fast to stop
//!   before the target, braking too hard to go on) takes the faster of the
//!   stop-and-move-from-rest and the single change through zero speed.
//! * **Stop on a point** (a travel limit): the stop at the deceleration
//!   that ends exactly there, as hard as it must brake — if no
//!   deceleration at this jerk can (the point is closer than the shortest
//!   jerk-limited stop), the caller drops the jerk.
//! * **Timed move** (a gantry's final moves): the move from rest with its
//!   cruise speed lowered until it takes exactly the time asked.
//!
//! Against the time-optimal profile (Ruckig's, `tests/scurve_ruckig.rs`,
//! 6000 random moves): the same duration (within 1e-6) wherever both are
//! bound alike — every move that keeps one direction, and every move that
//! turns back with `acc = dec`. A move that turns back with `acc ≠ dec`
//! has bounds that change with the direction of motion, which Ruckig
//! cannot express: there only a loose lower bound is compared.

use super::segments::{Builder, End, Kinematics, Profile};
use super::solve::bracket;
use super::velocity::{change, travel};

/// The signed acceleration bounds `(up, down)` of motion in direction `s`:
/// speed grows at `acc` at most and shrinks at `dec` at most.
fn bounds(s: f64, acc: f64, dec: f64) -> (f64, f64) {
    if s > 0.0 {
        (acc, dec)
    } else {
        (dec, acc)
    }
}

/// +1 for a non-negative `x`, else -1 (`signum` without its `-0.0`).
fn sign(x: f64) -> f64 {
    if x >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Appends the change to velocity `v1` and lands on it exactly, at zero
/// acceleration (the phases' rounding does not carry over).
fn push_change(b: &mut Builder, v1: f64, up: f64, down: f64, j: f64) {
    for (jerk, dt) in change(b.v, b.a, v1, up, down, j) {
        b.push_jerk(jerk, dt);
    }
    b.v = v1;
    b.a = 0.0;
}

/// Appends a stop at `dec`, whichever way the builder's state moves.
fn push_stop(b: &mut Builder, dec: f64, j: f64) {
    push_change(b, 0.0, dec, dec, j);
}

/// Where a stop at `dec` from velocity `v` and acceleration `a` ends,
/// relative to where it starts.
pub(super) fn stop_displacement(v: f64, a: f64, dec: f64, j: f64) -> f64 {
    travel(v, a, &change(v, a, 0.0, dec, dec, j)).0
}

/// A move from `from` to `target` needs no reversal: at rest, or moving
/// towards the target, still moving that way once its acceleration is
/// brought to zero (a start braking harder than the jerk can ease turns
/// back whatever is planned), with room to stop before the target (the
/// rounding tolerance of the trapezoid's same decision).
pub(super) fn reaches(from: Kinematics, target: f64, dec: f64, j: f64) -> bool {
    if from.at_rest() {
        return true;
    }
    let x = target - from.p;
    let dir = if from.v != 0.0 { from.v } else { from.a };
    let v_r = from.v + from.a * from.a.abs() / (2.0 * j);
    if x * dir <= 0.0 || v_r * dir < 0.0 {
        return false;
    }
    let d = stop_displacement(from.v, from.a, dec, j) * sign(dir);
    d <= x.abs() + 1e-9 * (1.0 + x.abs())
}

/// Stop and hold where it ends.
pub(super) fn stop(now_ns: u64, from: Kinematics, dec: f64, j: f64) -> Profile {
    let mut b = Builder::from(from);
    if !from.at_rest() {
        push_stop(&mut b, dec, j);
    }
    let p = b.p;
    b.finish(now_ns, End::Hold(p), 0.0)
}

/// Change to `velocity` and cruise there.
pub(super) fn jog(
    now_ns: u64,
    from: Kinematics,
    velocity: f64,
    acc: f64,
    dec: f64,
    j: f64,
) -> Profile {
    let mut b = Builder::from(from);
    if velocity == 0.0 {
        push_stop(&mut b, dec, j);
    } else {
        let s = sign(velocity);
        let (up, down) = bounds(s, acc, dec);
        if from.v * s < 0.0 {
            // Against the motion: through rest, or turning with the
            // acceleration held (within both bounds): the faster.
            let mut turn = Builder::from(from);
            let m = acc.min(dec);
            push_change(&mut turn, velocity, m, m, j);
            push_stop(&mut b, dec, j);
            push_change(&mut b, velocity, up, down, j);
            if turn.t < b.t {
                b = turn;
            }
        } else {
            push_change(&mut b, velocity, up, down, j);
        }
    }
    b.finish(now_ns, End::Cruise, velocity)
}

/// The limits of a move.
#[derive(Clone, Copy, Debug)]
pub(super) struct Limits {
    pub vmax: f64,
    pub acc: f64,
    pub dec: f64,
    pub j: f64,
}

/// To rest exactly on `target`.
pub(super) fn move_to(now_ns: u64, from: Kinematics, target: f64, l: Limits) -> Profile {
    let mut b = Builder::from(from);
    if reaches(from, target, l.dec, l.j) {
        toward(&mut b, target, l);
    } else {
        // It turns back: moving away, too fast to stop before the target,
        // or braking too hard to go on. Through rest (a stop, then a move
        // from rest), or with the acceleration held through zero speed:
        // the faster.
        let turn = turn_toward(from, target, l);
        push_stop(&mut b, l.dec, l.j);
        toward(&mut b, target, l);
        if let Some(turn) = turn.filter(|t| t.t < b.t) {
            b = turn;
        }
    }
    b.finish(now_ns, End::Hold(target), 0.0)
}

/// From the builder's state, which [`reaches`] the target: up to the peak
/// speed, cruise, down to rest on the target — or, with less room than
/// even bringing the acceleration to zero first takes, a stop that brakes
/// later ([`brake_later`]).
fn toward(b: &mut Builder, target: f64, l: Limits) {
    let s = sign(target - b.p);
    let first = bounds(s, l.acc, l.dec);
    if !approach(b, s, target, first, l) {
        brake_later(b, s, (target - b.p) * s, l);
    }
}

/// From `from`, which does not reach the target without turning: one
/// change from the motion to the final approach's peak speed, towards the
/// target (moving away now) or back to it (overshooting), the
/// acceleration held through zero speed — within both the acceleration
/// and the deceleration, since it brakes on one side of zero and speeds
/// up on the other. `None` where no such plan lands on the target.
fn turn_toward(from: Kinematics, target: f64, l: Limits) -> Option<Builder> {
    let m = l.acc.min(l.dec);
    let s = sign(target - from.p);
    [s, -s].into_iter().find_map(|s| {
        let mut b = Builder::from(from);
        approach(&mut b, s, target, (m, m), l).then_some(b)
    })
}

/// Up to the peak speed in direction `s` (the first change within the
/// bounds `first`), cruise, and stop on `target`. False (nothing planned)
/// when even the lowest peak overshoots.
fn approach(b: &mut Builder, s: f64, target: f64, first: (f64, f64), l: Limits) -> bool {
    let x = (target - b.p) * s;
    let Some(vp) = peak_speed(b.v, b.a, s, x, first, l) else {
        return false;
    };
    push_change(b, s * vp, first.0, first.1, l.j);
    let cruise = (target - b.p) * s - down_travel(vp, l).0;
    if vp > 0.0 && cruise > 0.0 {
        b.push_jerk(0.0, cruise / vp);
    }
    push_stop(b, l.dec, l.j);
    true
}

/// Distance and time of the stop from speed `vp` at zero acceleration.
fn down_travel(vp: f64, l: Limits) -> (f64, f64) {
    travel(vp, 0.0, &change(vp, 0.0, 0.0, l.dec, l.dec, l.j))
}

/// Distance along `s` (and time) of the change from `(v, a)` to speed
/// `vp` in direction `s` (within the bounds `first`) and of the stop from
/// there: the move without its cruise.
fn ramps(v: f64, a: f64, s: f64, vp: f64, first: (f64, f64), l: Limits) -> (f64, f64) {
    let (d1, t1) = travel(v, a, &change(v, a, s * vp, first.0, first.1, l.j));
    let (d2, t2) = down_travel(vp, l);
    (d1 * s + d2, t1 + t2)
}

/// The highest speed ≤ `vmax` whose ramps fit in `x` (along `s`), at or
/// above the speed `v_r` the motion reaches by bringing its acceleration
/// to zero at once (from there up, the higher the peak, the longer the
/// ramps: one root). `None` when even that speed's ramps overshoot (a
/// start braking already, or above the cap).
fn peak_speed(v: f64, a: f64, s: f64, x: f64, first: (f64, f64), l: Limits) -> Option<f64> {
    let excess = |vp: f64| ramps(v, a, s, vp, first, l).0 - x;
    let at_cap = excess(l.vmax);
    if at_cap <= 0.0 {
        return Some(l.vmax);
    }
    let v_r = (s * (v + a * a.abs() / (2.0 * l.j))).clamp(0.0, l.vmax);
    let at_low = excess(v_r);
    if at_low.is_nan() || at_low > 0.0 {
        return None;
    }
    Some(bracket(excess, v_r, at_low, l.vmax, at_cap).0)
}

/// Braking already (`a` against the motion) with room for more than its
/// stop but not for bringing the acceleration to zero first: the
/// acceleration eases off at the jerk to `a1`, then the stop at `dec`
/// follows; `a1` (between the braking now and zero) is the one whose stop
/// ends on the target. Otherwise (a start above the cap) the stop at the
/// lower deceleration that ends there.
fn brake_later(b: &mut Builder, s: f64, x: f64, l: Limits) {
    let (v, a) = (b.v, b.a);
    let a_s = a * s;
    if a_s >= 0.0 {
        let dec = landing_decel(v, a, s, x, l.j, l.dec);
        push_stop(b, dec, l.j);
        return;
    }
    let beyond = |a1: f64| {
        let dt = (a1 - a_s) / l.j;
        let (p1, v1, a1) = super::segments::advance(0.0, v, a, s * l.j, dt);
        let (d, _) = travel(v1, a1, &change(v1, a1, 0.0, l.dec, l.dec, l.j));
        (p1 + d) * s - x
    };
    let (now, eased) = (beyond(a_s), beyond(0.0));
    let a1 = if now >= 0.0 || eased <= 0.0 {
        a_s
    } else {
        bracket(beyond, a_s, now, 0.0, eased).0
    };
    b.push_jerk(s * l.j, (a1 - a_s) / l.j);
    push_stop(b, l.dec, l.j);
}

/// The deceleration bound (at most `hi`, whose stop from `(v, a)` in
/// direction `s` ends at or before `x`: the caller checks) whose stop ends
/// on `x`, on the near side by rounding. The lower the bound, the longer
/// the stop.
fn landing_decel(v: f64, a: f64, s: f64, x: f64, j: f64, hi: f64) -> f64 {
    let beyond = |dec: f64| travel(v, a, &change(v, a, 0.0, dec, dec, j)).0 * s - x;
    let at_hi = beyond(hi);
    if at_hi >= 0.0 {
        return hi;
    }
    // A gentler bound that overshoots: the uniform deceleration onto the
    // point, or less (the stop's ramps only add distance from zero
    // acceleration; braking already, halve until it overshoots).
    let mut gentle = (v * v / (2.0 * x)).min(0.5 * hi);
    let mut at_gentle = beyond(gentle);
    for _ in 0..super::solve::MAX_EVALUATIONS {
        if at_gentle > 0.0 {
            break;
        }
        gentle *= 0.5;
        at_gentle = beyond(gentle);
    }
    if at_gentle > 0.0 {
        bracket(beyond, hi, at_hi, gentle, at_gentle).0
    } else {
        gentle
    }
}

/// The stop that ends exactly on `target` (ahead of the motion: the caller
/// checks), at the smallest deceleration that gets there at jerk `j`;
/// `None` when even the shortest stop at this jerk ends beyond it.
pub(super) fn stop_at(now_ns: u64, from: Kinematics, target: f64, j: f64) -> Option<Profile> {
    let s = sign(from.v);
    let x = (target - from.p) * s;
    let (v, a) = (from.v, from.a);
    // Beyond this peak the bound no longer binds: the shortest stop.
    let hardest = (j * v.abs() + 0.5 * a * a).sqrt() + a.abs();
    let shortest = travel(v, a, &change(v, a, 0.0, hardest, hardest, j)).0 * s;
    if shortest.is_nan() || shortest > x {
        return None;
    }
    let dec = landing_decel(v, a, s, x, j, hardest);
    let mut b = Builder::from(from);
    push_stop(&mut b, dec, j);
    Some(b.finish(now_ns, End::Hold(target), 0.0))
}

/// From rest at `p0` to rest at `target` in exactly `duration_ns` (or the
/// fastest move, when that is longer): the move with its cruise speed
/// lowered until its ramps and cruise take the time asked.
pub(super) fn move_in(now_ns: u64, p0: f64, target: f64, duration_ns: u64, l: Limits) -> Profile {
    let fastest = move_to(now_ns, Kinematics::rest(p0), target, l);
    let t = duration_ns as f64 * 1e-9;
    if t <= fastest.t_end {
        return fastest;
    }
    let s = sign(target - p0);
    let x = (target - p0) * s;
    let mut b = Builder::new(p0, 0.0);
    if x > 0.0 {
        let first = bounds(s, l.acc, l.dec);
        // Time taken at cruise speed `vc`, as a time excess (decreasing).
        let late = |vc: f64| {
            let (d, tr) = ramps(0.0, 0.0, s, vc, first, l);
            tr + (x - d) / vc - t
        };
        let fast = peak_speed(0.0, 0.0, s, x, first, l).unwrap_or(0.0);
        // The mean speed: its ramps make it late (their mean speed is half
        // their peak), and it is below the fastest move's peak.
        let slow = (x / t).min(fast);
        let vc = bracket(late, fast, late(fast), slow, late(slow)).0;
        push_change(&mut b, s * vc, first.0, first.1, l.j);
        let cruise = (target - b.p) * s - down_travel(vc, l).0;
        b.push_jerk(0.0, cruise / vc);
        push_stop(&mut b, l.dec, l.j);
    } else {
        b.push_jerk(0.0, t);
    }
    let mut p = b.finish(now_ns, End::Hold(target), 0.0);
    // Ends at the requested time exactly, as the sample computes it.
    p.t_end = t;
    p
}

#[cfg(test)]
mod tests {
    use crate::profile::{stop_displacement, Kinematics, Profile, Ramp};

    const MS: u64 = 1_000_000;

    fn ramp(a: f64, d: f64, j: f64) -> Ramp {
        Ramp {
            accel: a,
            decel: d,
            jerk: j,
        }
    }

    fn secs(p: &Profile) -> f64 {
        p.t_end
    }

    #[test]
    fn rest_to_rest_with_the_acceleration_reached() {
        // vmax 20, a 500, j 50 000: 500²/50 000 = 5 ≤ 20, so each ramp is
        // 20/500 + 500/50 000 = 0.05 s over 20·0.05/2 = 0.5; cruise
        // (10 − 1)/20 = 0.45 s: 0.55 s.
        let p = Profile::move_from(
            0,
            Kinematics::rest(0.0),
            10.0,
            20.0,
            ramp(500.0, 500.0, 5e4),
        );
        assert!((secs(&p) - 0.55).abs() < 1e-12, "{}", secs(&p));
        let k = p.state(25 * MS);
        assert!(
            (k.v - 10.0).abs() < 1e-9 && (k.a - 500.0).abs() < 1e-9,
            "{k:?}"
        );
        assert_eq!(p.sample(550 * MS), (10.0, 0.0));
    }

    #[test]
    fn a_jog_ramps_and_cruises_exactly() {
        // 0 → 10 at a 100, j 1000: 100²/1000 = 10, the peak is just
        // reached: 0.2 s.
        let p = Profile::jog_from(0, Kinematics::rest(1.0), 10.0, ramp(100.0, 100.0, 1000.0));
        assert!((secs(&p) - 0.2).abs() < 1e-15);
        assert!((p.state(100 * MS).a - 100.0).abs() < 1e-9);
        let (a, b) = (p.state(300 * MS), p.state(400 * MS));
        assert_eq!((a.v, a.a, b.v), (10.0, 0.0, 10.0));
        assert!((b.p - a.p - 1.0).abs() < 1e-12);
        // Reversed at the cruise: one change from +10 to −10 at 100
        // (0.2 + 0.1 s) beats a stop and a start (0.4 s).
        let back = Profile::jog_from(400 * MS, b, -10.0, ramp(100.0, 100.0, 1000.0));
        assert!((secs(&back) - 0.3).abs() < 1e-12, "{}", secs(&back));
        assert_eq!(back.state(400 * MS), b);
    }

    #[test]
    fn a_stop_and_its_distance() {
        let cruise = Kinematics::moving(0.0, 10.0);
        let p = Profile::stop_from(0, cruise, 100.0, 1000.0);
        assert!((secs(&p) - 0.2).abs() < 1e-15);
        assert!((p.end_position() - 1.0).abs() < 1e-12);
        assert_eq!(
            stop_displacement(10.0, 0.0, 100.0, 1000.0),
            p.end_position()
        );
        assert_eq!(stop_displacement(-10.0, 0.0, 100.0, 0.0), -0.5);
    }

    #[test]
    fn a_stop_on_a_point_brakes_as_hard_as_it_must() {
        // From 10 u/s at d 50, j 1000: the plain stop takes
        // 10/50 + 50/1000 = 0.25 s over 1.25. On 1.1: T = 0.22 s, so
        // 10/d + d/1000 = 0.22, d = (220 − √8400)/2 = 64.17.
        let cruise = Kinematics::moving(0.0, 10.0);
        let p = Profile::stop_at_from(0, cruise, 1.1, 1000.0);
        let d = (220.0 - 8400f64.sqrt()) / 2.0;
        assert!((secs(&p) - 0.22).abs() < 1e-9, "{}", secs(&p));
        assert!((p.state(110 * MS).a + d).abs() < 1e-6);
        assert_eq!(p.sample(220 * MS), (1.1, 0.0));
        // On 0.8: closer than the shortest stop at this jerk (a triangle
        // to √(1000·10) = 100: 0.2 s over 1.0). The jerk is dropped:
        // 10²/(2·0.8) = 62.5 u/s² from the first instant, 0.16 s.
        let p = Profile::stop_at_from(0, cruise, 0.8, 1000.0);
        assert!((secs(&p) - 0.16).abs() < 1e-12);
        assert_eq!(p.state(MS).a, -62.5);
        assert_eq!(p.sample(160 * MS), (0.8, 0.0));
    }

    #[test]
    fn a_timed_move_lowers_its_cruise() {
        // 10 in 1 s at a = d = 500, j = 50 000: T = 10/v + v/500 + 0.01,
        // so v²/500 − 0.99·v + 10 = 0: v = 10.3153 (≥ 5: the ramps reach
        // the acceleration).
        let r = ramp(500.0, 500.0, 5e4);
        let p = Profile::move_in(0, 0.0, 10.0, 1000 * MS, 20.0, r);
        let v = (0.99 - (0.99f64 * 0.99 - 0.08).sqrt()) * 250.0;
        assert!(
            (p.state(500 * MS).v - v).abs() < 1e-9,
            "{:?} {v}",
            p.state(500 * MS)
        );
        assert_eq!(p.sample(1000 * MS), (10.0, 0.0));
        assert!(p.is_done(1000 * MS) && !p.is_done(1000 * MS - 1));
    }

    #[test]
    fn a_move_that_must_turn_back_turns_with_its_acceleration() {
        // At +10 u/s, target 1 behind: a 100, j 1000. One change from +10
        // to the approach's peak through zero (0.3 s to −10), then the
        // cruise and stop: faster than a stop (0.2 s) and a move back.
        let r = ramp(100.0, 100.0, 1000.0);
        let from = Kinematics::moving(0.0, 10.0);
        let p = Profile::move_from(0, from, -1.0, 10.0, r);
        let through_rest = {
            let stop = Profile::stop_from(0, from, 100.0, 1000.0);
            let back = Profile::move_from(0, Kinematics::rest(stop.end_position()), -1.0, 10.0, r);
            secs(&stop) + secs(&back)
        };
        assert!(
            secs(&p) < through_rest - 0.05,
            "{} vs {through_rest}",
            secs(&p)
        );
        let zero = (0..400).find(|k| p.state(k * MS).v <= 0.0).unwrap();
        assert!(p.state(zero * MS).a < -99.0, "turns at full acceleration");
        assert_eq!(p.sample(p.duration_ns()), (-1.0, 0.0));
    }
}
