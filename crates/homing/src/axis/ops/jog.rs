//! MAJ, hold to run: a jog runs in the sign of its speed while its client
//! renews the lease (`Request::jog_renew`), and stops normally (with its
//! deceleration, `StopCause::LeaseExpired`) when the lease runs out — a
//! client that dies, hangs or loses its connection stops the axis within
//! its lease.
//!
//! Planned from the current command state (position, velocity and — for
//! an S-curve, `jerk` above 0 — acceleration), with the jog's ramp:
//!
//! * homed, linear, with travel limits: as a move to the limit in its
//!   direction at the jog's speed, acceleration, deceleration and jerk
//!   (`Profile::move_from`): it cruises like a jog and, when its stopping
//!   distance reaches the limit, decelerates to rest exactly on it, ending
//!   normally (`StopCause::SoftLimit`, PC). Planned at once, not cycle by
//!   cycle, so a late step cannot carry it past the limit. (Worked example:
//!   20 units/s, deceleration 500 units/s² → stopping distance
//!   20² / (2·500) = 0.4: the deceleration starts at limit − 0.4.)
//! * otherwise (not homed, cyclic, no limits): `Profile::jog_from` to ±speed,
//!   cruising until stopped. While not homed the speed is capped by
//!   `unhomed_speed` (a faster jog is refused: 13 / 1).
//!
//! When the reference changes under a running jog (`unhome`, a restored
//! reference) it is planned again from where it is: unhomed it runs on
//! under the cap (slowing down to it with its deceleration) and without
//! limits; homed again it heads for the limit.

use super::motion::{Jog, Motion, Run};
use super::Code;
use crate::axis::state::State;
use crate::axis::Axis;
use crate::codes::*;
use crate::operation::{Dynamics, OpKind, StopCause};
use crate::profile::{Kinematics, Profile, Ramp};

impl Axis {
    /// MAJ: the jog's dynamics (defaults resolved, the speed signed) and
    /// lease.
    pub(super) fn jog_op(&mut self, now: u64, d: Dynamics, lease_ns: u64) -> Result<(), Code> {
        let Dynamics {
            speed,
            accel,
            decel,
            jerk,
        } = d;
        self.motion_gate()?;
        self.jog_collides()?;
        self.check_dynamics(speed, accel, decel)?;
        self.check_jerk(jerk)?;
        self.check_lease(lease_ns)?;
        self.switch_allows(speed)?;
        let jog = Jog {
            speed,
            accel,
            decel,
            jerk,
            lease_ns,
            lease_until: now.saturating_add(lease_ns),
            limited: false,
            planned_speed: speed,
        };
        let (t, k) = self.motion_state(now);
        let (profile, jog) = self.plan_jog(t, k, jog)?;
        let op = self.accept_op(OpKind::Jog);
        self.profile.set(profile);
        self.state = State::Motion(Motion {
            op,
            run: Run::Jog(jog),
        });
        Ok(())
    }

    /// The jog's profile from command state `k` at `t` under the current
    /// reference: to the travel limit in its direction when limits are
    /// enforced (refused 13 / 4 when that limit is reached already, or when
    /// the axis could not stop inside from where it is), else a cruise at
    /// the speed the cap allows.
    pub(super) fn plan_jog(
        &self,
        t: u64,
        k: Kinematics,
        mut jog: Jog,
    ) -> Result<(Profile, Jog), Code> {
        let speed = jog.speed.abs().min(self.speed_cap());
        jog.planned_speed = speed;
        let ramp = Ramp {
            accel: jog.accel,
            decel: jog.decel,
            jerk: jog.jerk,
        };
        let Some((lo, hi)) = self.soft_limits_raw() else {
            jog.limited = false;
            let target = speed.copysign(jog.speed);
            return Ok((Profile::jog_from(t, k, target, ramp), jog));
        };
        let limit = if jog.speed > 0.0 { hi } else { lo };
        if (limit - k.p) * jog.speed.signum() <= self.half_count() {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET));
        }
        self.stop_fits(k, jog.decel, jog.jerk)?;
        jog.limited = true;
        let profile = Profile::move_from(t, k, limit, speed, ramp);
        Ok((profile, jog))
    }

    /// The jog's client renewed it: it runs until `now + lease` at least.
    pub(super) fn renew_jog(&mut self, now: u64) {
        if let State::Motion(Motion {
            run: Run::Jog(j), ..
        }) = &mut self.state
        {
            j.lease_until = j.lease_until.max(now.saturating_add(j.lease_ns));
        }
    }

    /// One step of a jog: the lease, the limit reached, a new reference.
    pub(super) fn advance_jog(&mut self, now: u64, op: u32, j: Jog) {
        if now > j.lease_until {
            self.halt(now, op, j.decel, j.jerk, StopCause::LeaseExpired, true);
            return;
        }
        if j.limited && self.profile.is_done(now) {
            // At rest on the limit: the jog ended normally.
            self.status.last_stop = StopCause::SoftLimit;
            self.state = State::Idle;
            self.op_done(op, true);
            return;
        }
        let limited = self.soft_limits_raw().is_some();
        let speed = j.speed.abs().min(self.speed_cap());
        if limited == j.limited && speed == j.planned_speed {
            return;
        }
        let (t, k) = self.motion_state(now);
        match self.plan_jog(t, k, j) {
            Ok((profile, jog)) => {
                self.profile.set(profile);
                self.state = State::Motion(Motion {
                    op,
                    run: Run::Jog(jog),
                });
            }
            // Homed again beyond (or too close to) the limit it heads for.
            Err(_) => self.halt(now, op, j.decel, j.jerk, StopCause::SoftLimit, true),
        }
    }
}
