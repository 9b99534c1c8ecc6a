//! What an operation needs before it may start, checked in the order a
//! Logix instruction reports it, and the checks of its operands. A failed
//! check is the operation's refusal: nothing changes.
//!
//! | asked | refused with |
//! |---|---|
//! | enable, jog, move, stream start | 16 homing in process · 20 faulted · 12/12 shutdown · 5/1 not a servo axis · 12/40 no valid feedback |
//! | jog, move, stream start | also 5 servo off (not enabled, or a disable in progress) |
//! | jog | 3 on a moving or streaming axis (a jog on a jogging axis replaces it) · 13/1..3, 13/6 operands · 9 towards a tripped limit switch · 13/4 towards a travel limit already reached, or a stop that would end outside |
//! | move | 3 on a jogging or moving axis without `supersede`, on a streaming axis · 13/5 target not finite · 13/1..3 operands · 13/4 target outside the travel limits (or ±`max_position`), or a stop that would end outside · 9 towards a tripped limit switch |
//! | stream start | 3 on an axis in motion (stopping too) · 1019/7 not homed (unless `stream_unhomed`) · 13/1 no speed bound · 13/3 no `max_deceleration` |
//! | reset | 16 homing in process |
//! | disable, stop, stream end | never |
//!
//! Home (the rung's rising edge) is refused with 20 when faulted and 3 while
//! a jog, move or stream runs (a stop in progress is taken over), by the
//! Home instruction's ER as before.

use super::motion::{Motion, Run};
use super::Code;
use crate::axis::state::State;
use crate::axis::Axis;
use crate::codes::*;
use crate::config::AxisConfiguration;
use crate::op_limits::JOG_LEASE_NS;

/// Execution collision.
pub(super) const COLLISION: Code = (ERR_EXECUTION_COLLISION, 0);

impl Axis {
    /// What every operation that powers or moves the axis needs.
    pub(super) fn power_gate(&self) -> Result<(), Code> {
        if self.status.ip {
            return Err((ERR_HOME_IN_PROCESS, 0));
        }
        if self.status.faulted {
            return Err((ERR_AXIS_FAULTED, 0));
        }
        if self.request.shutdown {
            return Err((ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN));
        }
        if self.cfg.configuration == AxisConfiguration::FeedbackOnly {
            return Err((ERR_SERVO_OFF, EX_NOT_SERVO));
        }
        if self.last.is_none() {
            return Err((ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST));
        }
        Ok(())
    }

    /// What every operation that moves the axis needs: the power gate, and
    /// the drive enabled with no disable under way.
    pub(super) fn motion_gate(&self) -> Result<(), Code> {
        self.power_gate()?;
        let disabling = matches!(self.ops.await_rest, Some((_, true)));
        if !self.servo_action() || disabling {
            return Err((ERR_SERVO_OFF, 0));
        }
        Ok(())
    }

    /// A jog may start: idle, stopping normally, or jogging (it is
    /// replaced); not while a move or a stream runs, nor while homing's
    /// abort comes to rest.
    pub(super) fn jog_collides(&self) -> Result<(), Code> {
        match self.state {
            State::Motion(Motion {
                run: Run::Move(_) | Run::Stream(_),
                ..
            })
            | State::Stopping { .. } => Err(COLLISION),
            _ => Ok(()),
        }
    }

    /// A move may start: as a jog, and on a jogging or moving axis only
    /// with `supersede`.
    pub(super) fn move_collides(&self, supersede: bool) -> Result<(), Code> {
        match self.state {
            State::Motion(Motion {
                run: Run::Jog(_) | Run::Move(_),
                ..
            }) if supersede => Ok(()),
            State::Motion(Motion {
                run: Run::Halt(_), ..
            }) => Ok(()),
            State::Motion(_) | State::Stopping { .. } => Err(COLLISION),
            _ => Ok(()),
        }
    }

    /// The fastest an operation may ask for now: `max_speed` (when any is
    /// known), and `unhomed_speed` while not homed.
    pub(super) fn speed_cap(&self) -> f64 {
        let max = self.limits.max_speed.unwrap_or(f64::INFINITY);
        if self.status.homed {
            max
        } else {
            max.min(self.limits.unhomed_speed)
        }
    }

    /// Speed, acceleration and deceleration of a jog or move (the speed's
    /// magnitude; its sign is a jog's direction).
    pub(super) fn check_dynamics(&self, speed: f64, accel: f64, decel: f64) -> Result<(), Code> {
        let s = speed.abs();
        if !(s.is_finite() && s > 0.0 && s <= self.speed_cap()) {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_SPEED));
        }
        if !(accel.is_finite() && accel > 0.0) {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_ACCELERATION));
        }
        if !(decel.is_finite() && decel > 0.0 && decel <= self.limits.max_deceleration) {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_DECELERATION));
        }
        Ok(())
    }

    /// A jog's lease: 50 ms ..= 5 s.
    pub(super) fn check_lease(&self, lease_ns: u64) -> Result<(), Code> {
        if (JOG_LEASE_NS.0..=JOG_LEASE_NS.1).contains(&lease_ns) {
            Ok(())
        } else {
            Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_LEASE))
        }
    }
}
