//! MAM: a move (`Profile::move_from`: a trapezoid, or with `jerk` above 0
//! an S-curve) from the current command state (position, velocity,
//! acceleration) to rest at a target, PC when the command is there (the
//! profile returns the target bit for bit at its end).
//!
//! * The target is an axis position (`relative`: a distance from the
//!   current command position); on a cyclic axis an absolute target is
//!   reached the shortest way (at most half a revolution).
//! * Homed and linear: a target outside `travel_limits` is refused
//!   (13 / 4). Any target beyond ±`max_position` is refused too: feedback
//!   there would be refused as absurd.
//! * `supersede` replaces a jog or move in progress: planned from where
//!   it is, moving (a target behind it is reached after a stop at the
//!   move's deceleration, which must end inside the travel limits).
//! * Not homed: the speed is capped by `unhomed_speed`; cleared while
//!   moving, the move goes on to its target under the cap.

use super::motion::{Motion, MoveRun, Run};
use super::{within, Code};
use crate::axis::state::State;
use crate::axis::Axis;
use crate::codes::*;
use crate::config::TravelMode;
use crate::operation::{Dynamics, MoveSpec, OpKind};
use crate::position::nearest_cyclic;
use crate::profile::Profile;

impl MoveRun {
    /// How the move changes its speed.
    pub(super) fn ramp(&self) -> crate::profile::Ramp {
        crate::profile::Ramp {
            accel: self.accel,
            decel: self.decel,
            jerk: self.jerk,
        }
    }
}

impl Axis {
    /// MAM: the move as asked, and its dynamics (defaults resolved).
    pub(super) fn move_op(&mut self, now: u64, a: &MoveSpec, d: Dynamics) -> Result<(), Code> {
        self.motion_gate()?;
        self.move_collides(a.supersede)?;
        if !a.target.is_finite() {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_NOT_FINITE));
        }
        self.check_dynamics(d.speed, d.accel, d.decel)?;
        self.check_jerk(d.jerk)?;
        let (t, k) = self.motion_state(now);
        let target = self.move_target(a, k.p)?;
        self.switch_allows(target - k.p)?;
        self.stop_fits(k, d.decel, d.jerk)?;
        let mv = MoveRun {
            target,
            speed: d.speed,
            accel: d.accel,
            decel: d.decel,
            jerk: d.jerk,
            planned_speed: d.speed,
        };
        let op = self.accept_op(OpKind::Move);
        self.profile
            .set(Profile::move_from(t, k, target, d.speed, mv.ramp()));
        self.state = State::Motion(Motion {
            op,
            run: Run::Move(mv),
        });
        Ok(())
    }

    /// The raw target of a move from command position `p` (raw): refused
    /// 13 / 4 outside the travel limits (when enforced) or beyond
    /// ±`max_position`.
    fn move_target(&self, a: &MoveSpec, p: f64) -> Result<f64, Code> {
        let outside = Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET));
        let raw = match (a.relative, self.cfg.travel) {
            (true, _) => p + a.target,
            (false, TravelMode::Cyclic) if self.cfg.unwind > 0.0 => {
                nearest_cyclic(a.target - self.offset, p, self.cfg.unwind)
            }
            (false, _) => a.target - self.offset,
        };
        if !within(raw, self.cfg.max_position.min(f64::MAX)) {
            return outside;
        }
        if let Some((lo, hi)) = self.soft_limits_axis() {
            let axis = if a.relative {
                p + self.offset + a.target
            } else {
                a.target
            };
            if !(lo..=hi).contains(&axis) {
                return outside;
            }
        }
        Ok(raw)
    }

    /// One step of a move: done at its target; planned again under the
    /// unhomed cap when the axis lost its reference.
    pub(super) fn advance_move(&mut self, now: u64, op: u32, mv: MoveRun) {
        if self.profile.is_done(now) {
            self.state = State::Idle;
            self.op_done(op, true);
            return;
        }
        let speed = mv.speed.min(self.speed_cap());
        if speed == mv.planned_speed {
            return;
        }
        let (t, k) = self.motion_state(now);
        self.profile
            .set(Profile::move_from(t, k, mv.target, speed, mv.ramp()));
        self.state = State::Motion(Motion {
            op,
            run: Run::Move(MoveRun {
                planned_speed: speed,
                ..mv
            }),
        });
    }
}
