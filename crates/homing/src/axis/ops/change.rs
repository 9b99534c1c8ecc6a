//! MCD: new dynamics (speed, acceleration, deceleration, jerk) for the jog
//! or move that runs now. Each number left out keeps the running motion's
//! (its speed as planned: under the unhomed cap, the capped one).
//!
//! The motion is planned again from its exact command state — position,
//! velocity and acceleration (`Profile::state`) — with the new ramp, as a
//! supersede would be: nothing steps, a move still ends bit for bit on its
//! target, a jog on a homed linear axis still comes to rest on its travel
//! limit. It keeps its operation (the same `Status::op.id`, so its client
//! follows it on) and the change is answered in place
//! ([`OpKind::in_place`](crate::operation::OpKind::in_place)).
//!
//! Refused, with nothing changed:
//!
//! | when | ERR / EXERR |
//! |---|---|
//! | homing in process, faulted, shutdown, not a servo axis, no feedback, servo off | as any motion (16, 20, 12/12, 5/1, 12/40, 5) |
//! | a stream runs | 3 (the stream's program owns the dynamics) |
//! | no jog or move runs (at rest, stopping) | 3 / 1 |
//! | a speed not above 0, above the cap; an acceleration not above 0; a deceleration not above 0 or above `max_deceleration`; a jerk below 0 or above `MAX_JERK` | 13 / 1, 2, 3, 8 |
//! | the new deceleration and jerk could no longer stop the motion inside the travel limits it is inside of (homed, linear) | 13 / 4 |

use super::motion::{Jog, Motion, MoveRun, Run};
use super::Code;
use crate::axis::state::State;
use crate::axis::Axis;
use crate::codes::*;
use crate::operation::{ChangeSpec, Dynamics};
use crate::profile::Profile;

impl Axis {
    /// MCD: the running jog or move re-planned with the dynamics of `c`.
    pub(super) fn change_op(&mut self, now: u64, c: &ChangeSpec) -> Result<(), Code> {
        self.motion_gate()?;
        let State::Motion(m) = self.state else {
            return Err((ERR_EXECUTION_COLLISION, EX_NOTHING_TO_CHANGE));
        };
        if c.speed.is_some_and(|s| s.is_nan() || s <= 0.0) {
            // A magnitude: a jog keeps its direction.
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_SPEED));
        }
        let (t, k) = self.motion_state(now);
        let (profile, run) = match m.run {
            Run::Jog(j) => {
                let d = self.changed(c, j.planned_speed, j.accel, j.decel, j.jerk)?;
                let jog = Jog {
                    speed: d.speed.copysign(j.speed),
                    accel: d.accel,
                    decel: d.decel,
                    jerk: d.jerk,
                    ..j
                };
                let (profile, jog) = self.plan_jog(t, k, jog)?;
                (profile, Run::Jog(jog))
            }
            Run::Move(mv) => {
                let d = self.changed(c, mv.planned_speed, mv.accel, mv.decel, mv.jerk)?;
                self.stop_fits(k, d.decel, d.jerk)?;
                let speed = d.speed.min(self.speed_cap());
                let mv = MoveRun {
                    speed: d.speed,
                    accel: d.accel,
                    decel: d.decel,
                    jerk: d.jerk,
                    planned_speed: speed,
                    ..mv
                };
                let profile = Profile::move_from(t, k, mv.target, speed, mv.ramp());
                (profile, Run::Move(mv))
            }
            // A stream or a gear: their dynamics are the follower's, not a plan.
            Run::Stream(_) | Run::Gear(_) => return Err(super::rules::COLLISION),
            Run::Halt(_) => return Err((ERR_EXECUTION_COLLISION, EX_NOTHING_TO_CHANGE)),
        };
        self.profile.set(profile);
        self.state = State::Motion(Motion { op: m.op, run });
        Ok(())
    }

    /// The running motion's dynamics with what `c` gives, checked as a new
    /// jog or move's would be.
    fn changed(
        &self,
        c: &ChangeSpec,
        speed: f64,
        accel: f64,
        decel: f64,
        jerk: f64,
    ) -> Result<Dynamics, Code> {
        let d = c.applied_to(Dynamics {
            speed,
            accel,
            decel,
            jerk,
        });
        self.check_dynamics(d.speed, d.accel, d.decel)?;
        self.check_jerk(d.jerk)?;
        Ok(d)
    }
}
