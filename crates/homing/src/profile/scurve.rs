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
//! * **Jog** (MAJ): one change to the target velocity; against the current
//!   motion, a stop first (to rest, acceleration 0) and then the change.
//! * **Stop** (MAS and every normal stop): one change to zero at `dec`.
//! * **Move** (MAM): up to a peak speed `v_p`, cruise, down to rest exactly
//!   on the target. `v_p` is the largest speed ≤ the cap whose change up
//!   and change down fit the distance, found by [`solve`](super::solve)
//!   (`v_p = 0` is the plain stop, so every distance between the stop's
//!   and the cap's is covered). A start moving away, or too fast to stop
//!   before the target, stops first and comes back from rest.
//! * **Stop on a point** (a travel limit): the stop at the deceleration
//!   that ends exactly there, as hard as it must brake — if no
//!   deceleration at this jerk can (the point is closer than the shortest
//!   jerk-limited stop), the caller drops the jerk.
//! * **Timed move** (a gantry's final moves): the move from rest with its
//!   cruise speed lowered until it takes exactly the time asked.
//!
//! Against the time-optimal profile (Ruckig's, `tests/scurve_ruckig.rs`):
//! equal where the motion keeps one direction and has a velocity peak
//! (or cruise) at zero acceleration, which is every move from rest and
//! from a cruise. Slower where it passes through rest — a reversal, and
//! a start too fast to stop before the target — since the optimum turns
//! with the acceleration held (by at most the time the jerk takes to bring
//! the acceleration back, `a/j` per pass); and slightly slower for a start
//! braking already and just short of its target, which the profile first
//! brings to zero acceleration.

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
/// towards the target with room to stop before it (the rounding tolerance
/// of the trapezoid's same decision).
pub(super) fn reaches(from: Kinematics, target: f64, dec: f64, j: f64) -> bool {
    if from.at_rest() {
        return true;
    }
    let x = target - from.p;
    let dir = if from.v != 0.0 { from.v } else { from.a };
    if x * dir <= 0.0 {
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
        if from.v * s < 0.0 {
            push_stop(&mut b, dec, j);
        }
        let (up, down) = bounds(s, acc, dec);
        push_change(&mut b, velocity, up, down, j);
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
    if !reaches(from, target, l.dec, l.j) {
        push_stop(&mut b, l.dec, l.j);
    }
    toward(&mut b, target, l);
    b.finish(now_ns, End::Hold(target), 0.0)
}

/// From the builder's state, which [`reaches`] the target: up to the peak
/// speed, cruise, down to rest on the target.
fn toward(b: &mut Builder, target: f64, l: Limits) {
    let s = sign(target - b.p);
    let x = (target - b.p) * s;
    let vp = peak_speed(b.v, b.a, s, x, l);
    let (up, down) = bounds(s, l.acc, l.dec);
    push_change(b, s * vp, up, down, l.j);
    let down_dist = down_travel(vp, l).0;
    let cruise = (target - b.p) * s - down_dist;
    if vp > 0.0 && cruise > 0.0 {
        b.push_jerk(0.0, cruise / vp);
    }
    push_stop(b, l.dec, l.j);
}

/// Distance and time of the stop from speed `vp` at zero acceleration.
fn down_travel(vp: f64, l: Limits) -> (f64, f64) {
    let (d, t) = travel(vp, 0.0, &change(vp, 0.0, 0.0, l.dec, l.dec, l.j));
    (d, t)
}

/// Distance in direction `s` (and time) of the change from `(v, a)` to
/// speed `vp` and of the stop from there: the move without its cruise.
fn ramps(v: f64, a: f64, s: f64, vp: f64, l: Limits) -> (f64, f64) {
    let (up, down) = bounds(s, l.acc, l.dec);
    let (d1, t1) = travel(v, a, &change(v, a, s * vp, up, down, l.j));
    let (d2, t2) = down_travel(vp, l);
    (d1 * s + d2, t1 + t2)
}

/// The highest speed ≤ `vmax` whose ramps fit in `x` (0: the stop alone).
fn peak_speed(v: f64, a: f64, s: f64, x: f64, l: Limits) -> f64 {
    let excess = |vp: f64| ramps(v, a, s, vp, l).0 - x;
    let at_cap = excess(l.vmax);
    if at_cap <= 0.0 {
        return l.vmax;
    }
    let at_zero = excess(0.0);
    if at_zero >= 0.0 {
        return 0.0;
    }
    bracket(excess, 0.0, at_zero, l.vmax, at_cap).0
}

/// The stop that ends exactly on `target` (ahead of the motion: the caller
/// checks), at the smallest deceleration that gets there at jerk `j`;
/// `None` when even the shortest stop at this jerk ends beyond it.
pub(super) fn stop_at(now_ns: u64, from: Kinematics, target: f64, j: f64) -> Option<Profile> {
    let s = sign(from.v);
    let x = (target - from.p) * s;
    let (v, a) = (from.v, from.a);
    let beyond = |dec: f64| travel(v, a, &change(v, a, 0.0, dec, dec, j)).0 * s - x;
    // Beyond this peak the bound no longer binds: the shortest stop.
    let hardest = (j * v.abs() + 0.5 * a * a).sqrt() + a.abs();
    let at_hardest = beyond(hardest);
    if at_hardest.is_nan() || at_hardest > 0.0 {
        return None;
    }
    // A gentler bound that overshoots: the uniform deceleration onto the
    // point, or less (the stop's ramps only add distance from zero
    // acceleration; braking already, halve until it overshoots).
    let mut gentle = (v * v / (2.0 * x)).min(0.5 * hardest);
    let mut at_gentle = beyond(gentle);
    for _ in 0..super::solve::MAX_EVALUATIONS {
        if at_gentle > 0.0 {
            break;
        }
        gentle *= 0.5;
        at_gentle = beyond(gentle);
    }
    let dec = if at_gentle > 0.0 {
        bracket(beyond, hardest, at_hardest, gentle, at_gentle).0
    } else {
        gentle
    };
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
        // Time taken at cruise speed `vc`, as a time excess (decreasing).
        let late = |vc: f64| {
            let (d, tr) = ramps(0.0, 0.0, s, vc, l);
            tr + (x - d) / vc - t
        };
        let fast = peak_speed(0.0, 0.0, s, x, l);
        // The mean speed: its ramps make it late (their mean speed is half
        // their peak), and it is below the fastest move's peak.
        let slow = (x / t).min(fast);
        let vc = bracket(late, fast, late(fast), slow, late(slow)).0;
        let (up, down) = bounds(s, l.acc, l.dec);
        push_change(&mut b, s * vc, up, down, l.j);
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
