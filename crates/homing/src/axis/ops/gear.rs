//! MAG / MC_GearIn: the axis (the slave) follows its master's commanded
//! (or actual) position change times a ratio, from where both stand.
//!
//! The engine knows nothing of the master but what the cycle hands it each
//! step in `Request::master` ([`MasterFeed`]): the master's command and
//! actual position after the master stepped in the same cycle (no lag), the
//! hardest the master may change its speed, and whether it was stopped or
//! faulted.
//!
//! **Locked on**, the geared position is `slave_from + ratio × (master −
//! master_from)`: the slave's position at the lock plus the master's travel
//! since, times the ratio. Without a clutch it locks at once, where both
//! stand (no jump). **With a clutch** A, the slave's velocity ramps to the
//! geared velocity (ratio × the master's) at A, and locks once it gets
//! there; the distance lost while ramping is not made up — as Logix MAG's
//! clutch and PLCopen MC_GearIn (whose lost distance "is not compensated").
//!
//! **Bounds.** The command follows the geared position with the stream's
//! bounded follower: never faster than the slave's speed cap (`max_speed`;
//! `unhomed_speed` while not homed — an unhomed slave may gear, as in Logix,
//! at that cap and without soft limits), never changing its speed by more
//! than |ratio| × the master's acceleration bound plus the clutch's
//! acceleration per second, and never by more than the slave's own
//! `stream_acceleration` (the bound of its step-by-step motions). Where the
//! master asks for more than that, the slave lags and catches up at the
//! bounds; a lag beyond what it can catch up (a stop from the cap plus a
//! cycle, as the stream's) is an axis fault, ER 1025 / 2.
//!
//! **Its own limits.** Homed and linear with `travel_limits`, the slave
//! faults (ER 1025 / 1) in the step where its next command could no longer
//! stop inside them at `max_deceleration`: its stop, planned from the last
//! command at that deceleration, ends at or inside the limit — the command
//! never leaves them, so the cycle monitor never has to act. A limit switch
//! is the operations' rule (ER 12 / 43). The cycle stops the master too
//! when a geared slave faults.
//!
//! **Ends.** A stop or disable of the slave stops it normally (at
//! `max_deceleration`); a stop, disable or homing of the master
//! (`MasterFeed::stopped`) stops the slave normally; a fault of the master
//! stops the slave with ER 1025 / 3; a fault of the slave ends it as any
//! operation's motion. GearingStatus is set from the accepted gear until
//! its stop begins.

use super::follower::{self, Bounds};
use super::motion::{Gear, Motion, Run};
use super::rules::COLLISION;
use super::{within, Code};
use crate::axis::state::State;
use crate::axis::Axis;
use crate::codes::*;
use crate::operation::{GearSpec, MasterFeed, OpKind, StopCause};
use crate::profile::Profile;
use crate::time::ns_to_s;

impl Axis {
    /// The hardest this axis's motion may change its speed now, units/s²:
    /// the larger of `stream_acceleration`, `max_deceleration` and the
    /// running jog's, move's or stop's own — what a slave geared to it is
    /// given ([`MasterFeed::accel`]).
    pub fn acceleration_bound(&self) -> f64 {
        let running = match self.state {
            State::Motion(m) => match m.run {
                Run::Jog(j) => j.accel.max(j.decel),
                Run::Move(mv) => mv.accel.max(mv.decel),
                Run::Halt(h) => h.decel,
                Run::Stream(_) | Run::Gear(_) => 0.0,
            },
            _ => 0.0,
        };
        let l = &self.limits;
        l.stream_acceleration.max(l.max_deceleration).max(running)
    }

    /// The master this axis follows while geared (its index); `None` when
    /// not geared.
    pub fn gear_master(&self) -> Option<u16> {
        match self.state {
            State::Motion(Motion {
                run: Run::Gear(g), ..
            }) => Some(g.master),
            _ => None,
        }
    }

    /// The master's position this gear follows (raw).
    fn master_position(feed: &MasterFeed, actual: bool) -> Option<f64> {
        let p = if actual { feed.actual? } else { feed.commanded };
        p.is_finite().then_some(p)
    }

    /// MAG: enabled, at rest, not faulted, not homing; a finite, non-zero
    /// ratio; a positive clutch if any; the master's position there.
    pub(super) fn gear_op(&mut self, now: u64, g: &GearSpec) -> Result<(), Code> {
        self.motion_gate()?;
        if !matches!(self.state, State::Idle) {
            return Err(COLLISION);
        }
        self.speed_bound()?;
        if self.speed_cap() <= 0.0 {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_SPEED));
        }
        if !(g.ratio.is_finite() && g.ratio != 0.0) {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_RATIO));
        }
        if g.clutch.is_some_and(|a| !(a.is_finite() && a > 0.0)) {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_ACCELERATION));
        }
        if self.limits.max_deceleration.is_nan() || self.limits.max_deceleration <= 0.0 {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_DECELERATION));
        }
        let unavailable = (ERR_GEARING, EX_GEAR_MASTER_UNAVAILABLE);
        let (Some(master), Some(feed)) = (g.master_index(), self.ops.master) else {
            return Err(unavailable);
        };
        if feed.faulted {
            return Err((ERR_GEARING, EX_GEAR_MASTER_FAULTED));
        }
        let m = Self::master_position(&feed, g.actual).ok_or(unavailable)?;
        let op = self.accept_op(OpKind::Gear);
        let (x, _) = self.profile.at(now);
        self.profile.set(Profile::hold(now, x));
        self.state = State::Motion(Motion {
            op,
            run: Run::Gear(Gear {
                master,
                ratio: g.ratio,
                actual: g.actual,
                clutch: g.clutch.unwrap_or(0.0),
                locked: g.clutch.is_none(),
                master_from: m,
                slave_from: x,
                master_prev: m,
                velocity: 0.0,
                since_ns: now,
            }),
        });
        Ok(())
    }

    /// One step of gearing: the master's news first (stopped, faulted),
    /// then the command one cycle further towards the geared position,
    /// within the bounds and the travel limits.
    pub(super) fn advance_gear(&mut self, now: u64, op: u32, g: Gear) {
        let Some(feed) = self.ops.master else {
            return self.gear_fault(now, EX_GEAR_MASTER_UNAVAILABLE);
        };
        if feed.faulted {
            return self.gear_fault(now, EX_GEAR_MASTER_FAULTED);
        }
        if feed.stopped {
            self.stop_motion(now, None, StopCause::Operator);
            return;
        }
        let Some(dt_ns) = self.ops.prev_step_ns.map(|t| now.saturating_sub(t)) else {
            return;
        };
        if dt_ns == 0 || now == g.since_ns {
            return;
        }
        // A master without a valid actual position this cycle stands still
        // for the slave (its feedback-loss rule stops it, which ends this).
        let m = Self::master_position(&feed, g.actual).unwrap_or(g.master_prev);
        match self.gear_step(now, &feed, g, m, ns_to_s(dt_ns)) {
            Ok(next) => {
                self.state = State::Motion(Motion {
                    op,
                    run: Run::Gear(next),
                });
            }
            Err(exerr) => self.gear_fault(now, exerr),
        }
    }

    /// This step's command (set in the profile) and the gear's state
    /// after it; the EXERR when the slave cannot go on (nothing of this
    /// step is then commanded).
    fn gear_step(
        &mut self,
        now: u64,
        feed: &MasterFeed,
        g: Gear,
        m: f64,
        dt: f64,
    ) -> Result<Gear, u16> {
        let u = g.ratio * (m - g.master_prev) / dt;
        let x = self.last_command.position;
        let own = self.limits.stream_acceleration;
        let cap = self.speed_cap();
        let (r, ref_v, accel, lock) = if g.locked {
            let a = (g.ratio.abs() * feed.accel + g.clutch).min(own);
            (g.slave_from + g.ratio * (m - g.master_from), u, a, true)
        } else {
            if !within(u, cap * (1.0 + 1e-9)) {
                return Err(EX_GEAR_CANNOT_FOLLOW);
            }
            let a = g.clutch.min(own);
            let w = g.velocity + (u - g.velocity).clamp(-a * dt, a * dt);
            (x + w * dt, w, a, within(u - g.velocity, a * dt))
        };
        let bounds = Bounds {
            cap,
            accel,
            limits: None,
        };
        let step = follower::step(x, g.velocity, r, ref_v, dt, &bounds);
        if g.locked {
            let cycle_s = ns_to_s(self.cycle_ns(now));
            if !within(r - step.position, follower::lag_bound(cap, accel, cycle_s)) {
                return Err(EX_GEAR_CANNOT_FOLLOW);
            }
        }
        if !self.stop_stays_inside(step.position, step.velocity) {
            return Err(EX_GEAR_SOFT_LIMIT);
        }
        self.profile.set(Profile::hold(now, step.position));
        let (master_from, slave_from) = if g.locked || !lock {
            (g.master_from, g.slave_from)
        } else {
            // Locks on here: the geared position counts from this step.
            (m, step.position)
        };
        Ok(Gear {
            locked: lock,
            master_from,
            slave_from,
            master_prev: m,
            velocity: step.velocity,
            ..g
        })
    }

    /// From `(p, v)` a stop at `max_deceleration` ends inside the travel
    /// limits (half a count's tolerance), or there are none.
    fn stop_stays_inside(&self, p: f64, v: f64) -> bool {
        let Some((lo, hi)) = self.soft_limits_raw() else {
            return true;
        };
        let end = p + v * v.abs() / (2.0 * self.limits.max_deceleration);
        let tol = self.half_count();
        end <= hi + tol && end >= lo - tol
    }

    /// The gearing ends as an axis fault ER 1025 / `exerr`: the slave stops
    /// from its last command at `max_deceleration`, inside its limits.
    fn gear_fault(&mut self, now: u64, exerr: u16) {
        self.op_fault(now, (ERR_GEARING, exerr), StopCause::Gearing, false);
    }
}
