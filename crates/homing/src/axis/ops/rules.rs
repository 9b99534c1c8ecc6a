//! What an operation needs before it may start, checked in the order a
//! Logix instruction reports it, and the checks of its operands. A failed
//! check is the operation's refusal: nothing changes.
//!
//! | asked | refused with |
//! |---|---|
//! | enable, jog, move, stream start | 16 homing in process · 20 faulted · 12/12 shutdown · 5/1 not a servo axis · 12/40 no valid feedback |
//! | jog, move, stream start | also 5 servo off (not enabled, or a disable in progress) |
//! | jog, move, stream start | 13/7 no speed bound (no `max_speed`, none derived from the homing speeds) |
//! | jog | 3 on a moving or streaming axis (a jog on a jogging axis replaces it) · 13/1..3, 13/6, 13/8 operands · 9 towards a tripped limit switch · 13/4 towards a travel limit already reached, or a stop that would end outside |
//! | move | 3 on a jogging or moving axis without `supersede`, on a streaming axis · 13/5 target not finite · 13/1..3, 13/8 operands · 13/4 target outside the travel limits (or ±`max_position`), or a stop that would end outside · 9 towards a tripped limit switch |
//! | stream start | 3 on an axis in motion (stopping too) · then 13/7 as above · 1019/7 not homed (unless `stream_unhomed`) · 13/1 a speed cap of 0 (unhomed, no `unhomed_speed`) · 13/3 no `max_deceleration` |
//! | setpoint (an axis fault, 1019) | 1 not finite · 2 outside the travel limits · 3 faster than the speed cap (unhomed: `unhomed_speed`) on the program's timeline, or the command held back by it further than it can follow · 4 a change of velocity above `stream_acceleration` on the program's timeline, or the command held back by it further than it can follow · 5 nothing for `stream_timeout_ms` since the last one arrived · 6 out of order · 7 not homed |
//! | change (`change.rs`) | as jog's first two rows, then 3 streaming · 3/1 no jog or move runs · 13/1..3, 13/8 operands · 13/4 a stop that would end outside |
//! | gear | as stream start, then 3 on an axis in motion (stopping too) · 13/9 ratio not finite or 0 · 13/2 clutch not above 0 · 13/3 no `max_deceleration` · 1025/3 the master faulted · 1025/5 no position of the master (the cycle's own: 1025/4 itself, 1025/6 chained) |
//! | reset | 16 homing in process |
//! | redefine | 16/25 homing in process · 20/25 faulted · 1023/1 not homed · 3/25 not at rest (jog, move, stream, stop or enable under way) · 12/40 no valid feedback · 1023/3 geared, master or slave (`coupling_allows_redefine`, `Core::gear_refusal`) · 1023/2 not finite |
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
use crate::op_limits::{JOG_LEASE_NS, MAX_JERK};

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
                run: Run::Move(_) | Run::Stream(_) | Run::Gear(_),
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

    /// Every motion has a speed bound: `max_speed`, or the one the homing
    /// speeds give (`effective_max_speed`). Without one nothing moves the
    /// axis (13 / 7, naming `max_speed`); homing still works.
    pub(super) fn speed_bound(&self) -> Result<f64, Code> {
        self.limits
            .max_speed
            .ok_or((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_NO_MAX_SPEED))
    }

    /// The fastest an operation may ask for now: `max_speed` (0 when none
    /// is known: nothing may move), and `unhomed_speed` while not homed —
    /// for jog, move and stream alike.
    pub(super) fn speed_cap(&self) -> f64 {
        let max = self.limits.max_speed.unwrap_or(0.0);
        if self.status.homed {
            max
        } else {
            max.min(self.limits.unhomed_speed)
        }
    }

    /// Speed, acceleration and deceleration of a jog or move (the speed's
    /// magnitude; its sign is a jog's direction).
    pub(super) fn check_dynamics(&self, speed: f64, accel: f64, decel: f64) -> Result<(), Code> {
        self.speed_bound()?;
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

    /// A jog's or move's jerk: 0 (a trapezoid) ..= `MAX_JERK` (13 / 8).
    pub(super) fn check_jerk(&self, jerk: f64) -> Result<(), Code> {
        if (0.0..=MAX_JERK).contains(&jerk) {
            Ok(())
        } else {
            Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_JERK))
        }
    }

    /// Redefine position on a geared slave would move the positions its
    /// gear follows (1023 / 3). A master does not know it is one: the
    /// cycle, which sees both ends of every gear, refuses it there with the
    /// same code (`Core::gear_refusal`).
    pub(super) fn coupling_allows_redefine(&self) -> Result<(), Code> {
        if self.status.gearing {
            return Err((ERR_REDEFINE_REFUSED, EX_REDEFINE_GEARED));
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
