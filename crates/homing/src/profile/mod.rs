//! Motion profiles: jog to a speed, stop, stop on a point, move to a point
//! (plain or in a given time) and a setpoint stream's segment, as
//! trapezoids or jerk-limited S-curves.
//!
//! A profile is planned once, in the step that asks for it, as at most ten
//! constant-jerk segments followed by either a cruise (jog) or an exact
//! hold (stop, move). The engine samples it at each cycle's time: a
//! bounded scan and one polynomial, no heap, no panics. Planning is
//! bounded too: closed forms, and for an S-curve's unknown peak speed or
//! deceleration at most four root searches of at most 64 evaluations each
//! (the bench's `profile/*` measures both). Sampling a continuous profile (instead of integrating velocity
//! cycle by cycle) is what gives the guarantees the tests check
//! (`tests/properties.rs`, `tests/scurve_properties.rs`):
//!
//! * the speed between two samples is an average of the continuous speed, so
//!   it never exceeds the configured maximum;
//! * the second difference of the samples is a weighted average of the
//!   continuous acceleration, so it stays within `[-deceleration, +acceleration]`
//!   (in the direction of motion); for an S-curve the third difference is a
//!   weighted average of the jerk, so it stays within `±jerk`;
//! * every re-plan starts from the exact sampled state — position and
//!   velocity, and for an S-curve the acceleration too ([`Profile::state`]
//!   gives it) — so the bounds hold across it and nothing steps;
//! * a move returns its target bit-exactly once its duration has elapsed: no
//!   residual creep, no overshoot.
//!
//! Two families, one [`Profile`] type:
//!
//! * `trapezoid.rs`: `jerk = 0`. The homing legs, the stream, a fault's stop,
//!   and every operation whose jerk is 0 — bit for bit the numbers the engine
//!   had before S-curves ([`Profile::jog`], [`Profile::stop`],
//!   [`Profile::move_to`], ... keep their signatures).
//! * `scurve.rs` (of `velocity.rs`'s changes, `solve.rs`'s root finder):
//!   `jerk > 0`, through the entry points below, which take the
//!   full state ([`Kinematics`]) and a [`Ramp`]; with `jerk = 0` they are
//!   the trapezoid's functions, with the state's acceleration ignored.
//!
//! Which stops keep the jerk: a normal stop (MAS, a jog's lease, a
//! release, a disable, the end of a jog or move, a stop inside the travel
//! limits) is planned with the motion's jerk; a fault's stop
//! (`max_deceleration`: a limit switch, a refused setpoint, lost feedback)
//! is planned with `jerk = 0` — the shortest stop the deceleration allows,
//! the acceleration stepping once at its start. A stop that must end on a
//! travel limit keeps the jerk and brakes harder where it must; when no
//! jerk-limited stop ends there ([`Profile::stop_at_from`]), it drops the
//! jerk and decelerates uniformly onto the limit.
//!
//! Absurd inputs (a non-finite state or target, a zero, negative or NaN
//! speed, acceleration, deceleration or jerk) plan a hold where the state
//! is, never a panic or a NaN.

mod scurve;
mod segments;
mod solve;
mod trapezoid;
mod velocity;

pub use segments::{Kinematics, Profile};
pub use trapezoid::{reaches_without_reversing, stopping_distance};

/// How a jog, move or stop may change its speed: `accel` while the speed
/// grows, `decel` while it shrinks (units/s², positive), and `jerk`
/// (units/s³): positive for an S-curve, 0 for a trapezoid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ramp {
    pub accel: f64,
    pub decel: f64,
    pub jerk: f64,
}

impl Ramp {
    /// A trapezoid's ramp: no jerk limit.
    pub fn trapezoid(accel: f64, decel: f64) -> Self {
        Self {
            accel,
            decel,
            jerk: 0.0,
        }
    }

    fn usable(&self) -> bool {
        positive(self.accel) && positive(self.decel) && jerk_usable(self.jerk)
    }
}

/// Finite and above zero: a usable speed, acceleration or deceleration.
fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// 0 (a trapezoid) or a usable jerk.
fn jerk_usable(j: f64) -> bool {
    j == 0.0 || positive(j)
}

impl Profile {
    /// MAJ: change from `from` to `velocity` (the sign is the direction)
    /// and cruise there forever. Against the current motion it comes to
    /// rest first (an S-curve at zero acceleration, as the trapezoid does
    /// at zero velocity).
    pub fn jog_from(now_ns: u64, from: Kinematics, velocity: f64, r: Ramp) -> Self {
        if !(from.is_finite() && velocity.is_finite() && r.usable()) {
            return Self::hold(now_ns, from.p);
        }
        if r.jerk == 0.0 {
            let plan = Self::jog(now_ns, from.p, from.v, velocity, r.accel, r.decel);
            return checked(now_ns, from.p, plan);
        }
        checked(
            now_ns,
            from.p,
            scurve::jog(now_ns, from, velocity, r.accel, r.decel, r.jerk),
        )
    }

    /// A stop from `from` at `decel` (and `jerk`; 0: the trapezoid's,
    /// whose deceleration starts at once), holding where it ends.
    pub fn stop_from(now_ns: u64, from: Kinematics, decel: f64, jerk: f64) -> Self {
        if !(from.is_finite() && positive(decel) && jerk_usable(jerk)) {
            return Self::hold(now_ns, from.p);
        }
        if jerk == 0.0 {
            return checked(now_ns, from.p, Self::stop(now_ns, from.p, from.v, decel));
        }
        checked(now_ns, from.p, scurve::stop(now_ns, from, decel, jerk))
    }

    /// MAM: from `from` to rest exactly on `target`, never faster than
    /// `speed` (a start above it slows down first). A start moving away,
    /// or too fast to stop before the target, stops and comes back:
    /// callers that must never reverse check [`reaches`] first.
    pub fn move_from(now_ns: u64, from: Kinematics, target: f64, speed: f64, r: Ramp) -> Self {
        if !(from.is_finite() && target.is_finite() && positive(speed) && r.usable()) {
            return Self::hold(now_ns, from.p);
        }
        if r.jerk == 0.0 {
            let plan = Self::move_to(now_ns, from.p, from.v, target, speed, r.accel, r.decel);
            return checked(now_ns, from.p, plan);
        }
        let l = scurve::Limits {
            vmax: speed,
            acc: r.accel,
            dec: r.decel,
            j: r.jerk,
        };
        checked(now_ns, from.p, scurve::move_to(now_ns, from, target, l))
    }

    /// A stop that ends exactly on `target` and never beyond it (a travel
    /// limit), which must lie ahead of the motion; a target behind it, or
    /// no velocity, holds where it is. With jerk: the jerk-limited stop at
    /// the smallest deceleration that ends there (harder than any
    /// configured one if it must); when the target is closer than the
    /// shortest stop this jerk allows, the jerk is dropped: uniform
    /// deceleration onto the target, `v²/2d` (the trapezoid's
    /// [`Profile::stop_at`]), the lowest deceleration that gets there.
    pub fn stop_at_from(now_ns: u64, from: Kinematics, target: f64, jerk: f64) -> Self {
        if !(from.is_finite() && target.is_finite() && jerk_usable(jerk)) {
            return Self::hold(now_ns, from.p);
        }
        let ahead = from.v != 0.0 && (target - from.p) * from.v > 0.0;
        let plan = if jerk == 0.0 || !ahead {
            None
        } else {
            scurve::stop_at(now_ns, from, target, jerk)
        };
        let plan = plan.unwrap_or_else(|| Self::stop_at(now_ns, from.p, from.v, target));
        checked(now_ns, from.p, plan)
    }

    /// From rest at `p0` to rest at `target` in exactly `duration_ns` (a
    /// gantry's sides start and end together): the move of
    /// [`Profile::move_from`] with a lower cruise speed. Never faster than
    /// the fastest move: a shorter duration gives the fastest move. At
    /// `now_ns + duration_ns` the sample is `target` exactly, and not done
    /// before.
    pub fn move_in(
        now_ns: u64,
        p0: f64,
        target: f64,
        duration_ns: u64,
        speed: f64,
        r: Ramp,
    ) -> Self {
        if !(p0.is_finite() && target.is_finite() && positive(speed) && r.usable()) {
            return Self::hold(now_ns, p0);
        }
        if r.jerk == 0.0 {
            let plan = Self::move_to_in(now_ns, p0, target, duration_ns, speed, r.accel, r.decel);
            return checked(now_ns, p0, plan);
        }
        let l = scurve::Limits {
            vmax: speed,
            acc: r.accel,
            dec: r.decel,
            j: r.jerk,
        };
        checked(
            now_ns,
            p0,
            scurve::move_in(now_ns, p0, target, duration_ns, l),
        )
    }
}

/// `plan`, or a hold at `p` if a number of it overflowed (extreme but
/// finite inputs: 1e300 units/s stopped within 1e-300 units). Usable
/// inputs of a machine never get here; a hold is what any other unusable
/// input plans too.
fn checked(now_ns: u64, p: f64, plan: Profile) -> Profile {
    if plan.is_finite() {
        plan
    } else {
        Profile::hold(now_ns, p)
    }
}

/// Where a stop at `decel` (and `jerk`) from velocity `v` and acceleration
/// `a` ends, relative to where it starts: `v·|v|/2·decel` without jerk
/// (the acceleration ignored, as the trapezoid's stop does); infinite in
/// the direction of motion for an unusable deceleration or jerk (or one
/// so extreme that the distance overflows).
pub fn stop_displacement(v: f64, a: f64, decel: f64, jerk: f64) -> f64 {
    if v == 0.0 && (a == 0.0 || jerk == 0.0) {
        return 0.0;
    }
    let endless = f64::INFINITY.copysign(if v != 0.0 { v } else { a });
    if !(positive(decel) && jerk_usable(jerk) && v.is_finite() && a.is_finite()) {
        return endless;
    }
    if jerk == 0.0 {
        return v * v.abs() / (2.0 * decel);
    }
    let d = scurve::stop_displacement(v, a, decel, jerk);
    if d.is_finite() {
        d
    } else {
        endless
    }
}

/// True if a move from `from` to rest at `target` needs no reversal: at
/// rest anything is reachable; moving, the motion must point at the
/// target and its stop at `decel` (and `jerk`) must fit before it (with
/// the rounding tolerance [`Profile::move_from`] uses to decide it need
/// not overshoot). With `jerk = 0`: [`reaches_without_reversing`].
pub fn reaches(from: Kinematics, target: f64, decel: f64, jerk: f64) -> bool {
    if jerk == 0.0 {
        return reaches_without_reversing(from.p, from.v, target, decel);
    }
    if !(from.is_finite() && target.is_finite() && positive(decel) && positive(jerk)) {
        return from.at_rest();
    }
    scurve::reaches(from, target, decel, jerk)
}
