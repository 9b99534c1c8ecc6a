//! The operations around homing: enable, disable, reset, jog, move, stop
//! and the supervised stream (the types: [`operation`](crate::operation)).
//!
//! Each operation is applied in the step it arrives: refused without any
//! effect (the ERR / EXERR in `Status::op.refused`, the axis's ER left
//! alone), or accepted with a new `Status::op.id`. Where the rules live:
//!
//! * `rules`: what every operation needs before it may start (the Logix
//!   order: home in process 16, faulted 20, shutdown 12/12, not a servo
//!   axis 5/1, no feedback 12/40, servo off 5) and the operand checks (13);
//! * `power`: enable, disable, reset, the drive's faults and power stage;
//! * `jog`, `moves`, `stream`: each motion, its start and its progress;
//! * `limits`: software travel limits (homed, linear) and the hardware
//!   limit switches;
//! * `motion`: the data a motion carries from step to step;
//! * this file: the dispatch, stops, faults, and what the status shows.
//!
//! Design notes a reviewer will look for:
//!
//! * **A motion is a profile.** Jog, move and every stop are
//!   [`Profile`]s planned from the current command state and sampled in
//!   time, like homing's legs: a late step samples further along the same
//!   planned path, never past what was planned. A jog on a homed linear
//!   axis is planned as a move to the travel limit in its direction, so its
//!   stop at the limit is part of the profile (it comes to rest on the
//!   limit, never beyond, whatever the step timing).
//! * **Stops stay inside.** Every stop of an operation's motion on a homed
//!   linear axis ends at or inside the travel limits (`limits::stop_inside`):
//!   where its deceleration would carry it past a limit, it decelerates
//!   harder and ends on the limit. A motion that could not be stopped
//!   inside from where it is (a reversal, a supersede) is refused.
//! * **A refusal is not a fault.** An operation refused leaves everything
//!   as it was. An axis fault (drive fault, limit switch, refused setpoint,
//!   lost feedback while moving, enable timeout) sets ER and `faulted`;
//!   only `Reset` clears them.

mod jog;
mod limits;
pub(super) mod motion;
mod moves;
mod power;
mod rules;
mod stream;

use super::intake::Sample;
use super::state::State;
use super::Axis;
use crate::operation::{OpKind, OpStatus, Operation, Setpoint, StopCause};
use motion::{Halt, Motion, Run};
pub(super) use power::Power;

/// An ERR / EXERR pair of a refusal.
pub(super) type Code = (u16, u16);

/// What the operations keep besides the state.
#[derive(Clone, Copy, Debug, Default)]
pub(in crate::axis) struct Ops {
    pub power: Power,
    /// `now` of the previous step: a stream's segment starts there.
    pub prev_step_ns: Option<u64>,
    /// An operation answered once the axis is at rest (a stop or disable
    /// of homing or of a stop in progress): its id, and whether the power
    /// stage goes off then.
    pub await_rest: Option<(u32, bool)>,
}

impl Axis {
    /// Applies `op` (this step's `Request::op`), answering in `Status::op`.
    /// What the client left out is filled from this axis's configuration
    /// here, once ([`Operation::resolve`]).
    pub(super) fn operation(&mut self, now: u64, mut op: Operation) {
        op.resolve(&self.cfg);
        let result = match op {
            Operation::Enable => self.enable_op(now),
            Operation::Disable => {
                self.disable_op(now);
                Ok(())
            }
            Operation::Reset => self.reset_op(now),
            Operation::Jog(j) => self.jog_op(now, j.dynamics(), j.lease_ns()),
            Operation::Move(m) => self.move_op(now, &m, m.dynamics()),
            Operation::StreamStart => self.stream_start(now),
            Operation::StreamEnd => {
                self.stream_end(now);
                Ok(())
            }
            Operation::Stop => {
                self.stop_op(now);
                Ok(())
            }
        };
        if let Err(code) = result {
            self.status.op.refused = Some(code);
        }
    }

    /// This step's other operation inputs: a jog's renewal and a setpoint.
    pub(super) fn operation_inputs(&mut self, now: u64, renew: bool, setpoint: Option<Setpoint>) {
        if renew {
            self.renew_jog(now);
        }
        if let Some(sp) = setpoint {
            self.take_setpoint(now, &sp);
        }
    }

    /// Accepts an operation of `kind`: a new id, in process.
    fn accept_op(&mut self, kind: OpKind) -> u32 {
        let id = self.status.op.id.wrapping_add(1).max(1);
        self.status.op = OpStatus {
            id,
            kind,
            ip: true,
            pc: false,
            refused: None,
        };
        id
    }

    /// Operation `id` ended: as meant (`pc`) or not. Nothing when a later
    /// operation has taken its place in the status.
    fn op_done(&mut self, id: u32, pc: bool) {
        if self.status.op.id == id {
            self.status.op.ip = false;
            self.status.op.pc = pc;
        }
    }

    /// MAS: ends a jog, move or stream normally; homing in process ends
    /// with ERR 12 / EXERR 1 (as `Request::stop`); a stop in progress
    /// goes on. PC at rest.
    fn stop_op(&mut self, now: u64) {
        let id = self.accept_op(OpKind::Stop);
        if self.status.ip {
            self.abort_homing(now);
        }
        if !self.stop_motion(now, Some(id), StopCause::Operator) {
            self.ops.await_rest = Some((id, false));
        }
    }

    /// The command state a motion continues from: time, raw position,
    /// velocity. A stream's segment may end before `now` (the command then
    /// rests on its setpoint until the next one), so a stream continues
    /// from the last command, at the previous step: a stop planned from
    /// there continues the motion the drive was last given.
    fn motion_state(&mut self, now: u64) -> (u64, f64, f64) {
        if let State::Motion(Motion {
            run: Run::Stream(st),
            ..
        }) = self.state
        {
            if let Some(t) = self.ops.prev_step_ns {
                let v = if t <= st.seg_end_ns {
                    st.seg_velocity
                } else {
                    0.0
                };
                return (t, self.last_command.position, v);
            }
        }
        let (p, v) = self.profile.at(now);
        (now, p, v)
    }

    /// The deceleration of the running motion (a stream's, or a stop's:
    /// `max_deceleration`).
    fn running_decel(&self) -> f64 {
        match self.state {
            State::Motion(Motion {
                run: Run::Jog(j), ..
            }) => j.decel,
            State::Motion(Motion {
                run: Run::Move(m), ..
            }) => m.decel,
            _ => self.limits.max_deceleration,
        }
    }

    /// Brings the motion to rest at `decel`, inside the travel limits,
    /// answering for operation `op`; `normal`: PC at rest.
    fn halt(&mut self, now: u64, op: u32, decel: f64, cause: StopCause, normal: bool) {
        let (t, p, v) = self.motion_state(now);
        let stop = self.stop_inside(t, p, v, decel);
        self.profile.set(stop);
        self.status.last_stop = cause;
        self.state = State::Motion(Motion {
            op,
            run: Run::Halt(Halt { normal }),
        });
    }

    /// A normal stop of a jog, move or stream with its own deceleration,
    /// answering for `op` (`None`: the motion's own operation). False when
    /// there was none to stop (idle, homing, or already stopping).
    pub(super) fn stop_motion(&mut self, now: u64, op: Option<u32>, cause: StopCause) -> bool {
        let State::Motion(m) = self.state else {
            return false;
        };
        if matches!(m.run, Run::Halt(_)) {
            return false;
        }
        let decel = self.running_decel();
        self.halt(now, op.unwrap_or(m.op), decel, cause, true);
        true
    }

    /// An axis fault while an operation moves the axis: ER with its code,
    /// `faulted`, the cause shown, the operation ended without PC; the axis
    /// stops at `max_deceleration` (inside the travel limits) — or, with
    /// `power_off`, the drive no longer follows: the power stage is
    /// switched off and the command holds where the axis is.
    pub(super) fn op_fault(
        &mut self,
        now: u64,
        code: Code,
        cause: StopCause,
        power_off: bool,
    ) -> bool {
        let State::Motion(m) = self.state else {
            return false;
        };
        self.set_fault(code);
        self.op_done(m.op, false);
        if power_off {
            self.status.last_stop = cause;
            self.power_off_here(now);
            self.state = State::Idle;
        } else {
            let decel = self.limits.max_deceleration;
            self.halt(now, m.op, decel, cause, false);
        }
        true
    }

    /// Sets the axis fault `code` (ER, ERR, EXERR, `faulted`).
    pub(super) fn set_fault(&mut self, (err, exerr): Code) {
        self.status.er = true;
        self.status.err = err;
        self.status.exerr = exerr;
        self.status.faulted = true;
    }

    /// One step of the operation's motion (`s`: this step's fresh sample).
    pub(super) fn advance_motion(&mut self, now: u64, s: Option<&Sample>) {
        let State::Motion(m) = self.state else {
            return;
        };
        if let Some(s) = s {
            if self.limit_switch_hit(now, s) {
                return;
            }
        }
        match m.run {
            Run::Jog(j) => self.advance_jog(now, m.op, j),
            Run::Move(mv) => self.advance_move(now, m.op, mv),
            Run::Stream(st) => self.advance_stream(now, m.op, st),
            Run::Halt(h) if self.profile.is_done(now) => {
                self.state = State::Idle;
                let awaited = self.ops.await_rest.is_some_and(|(id, _)| id == m.op);
                if h.normal && !awaited {
                    self.op_done(m.op, true);
                }
            }
            Run::Halt(_) => {}
        }
    }

    /// After the step's progress: the operation waiting for the axis to be
    /// at rest is answered (and the power stage switched off for a disable).
    pub(super) fn settle(&mut self) {
        let Some((id, disable)) = self.ops.await_rest else {
            return;
        };
        if matches!(self.state, State::Idle) {
            self.ops.await_rest = None;
            if disable {
                self.power_off();
            }
            self.op_done(id, true);
        }
    }

    /// The status bits of the operations, after a step.
    pub(super) fn report_ops(&mut self) {
        let (jog, mv, stream, halt) = match self.state {
            State::Motion(m) => match m.run {
                Run::Jog(_) => (true, false, false, false),
                Run::Move(_) => (false, true, false, false),
                Run::Stream(_) => (false, false, true, false),
                Run::Halt(_) => (false, false, false, true),
            },
            _ => (false, false, false, false),
        };
        self.status.jogging = jog;
        self.status.moving = mv;
        self.status.streaming = stream;
        self.status.stopping |= halt;
        self.status.servo_action = self.servo_action();
        let (neg, pos) = self.last.map_or((false, false), |s| self.switches(&s));
        self.status.limit_negative = neg;
        self.status.limit_positive = pos;
    }

    /// The velocity the command carries while streaming (the feed-forward,
    /// or the segment's), instead of the profile's: the profile rests on
    /// each setpoint at the end of its segment.
    pub(super) fn stream_velocity(&self, now: u64) -> Option<f64> {
        let State::Motion(Motion {
            run: Run::Stream(st),
            ..
        }) = self.state
        else {
            return None;
        };
        Some(if now <= st.seg_end_ns {
            st.feed_forward.unwrap_or(st.seg_velocity)
        } else {
            0.0
        })
    }

    /// A motion of an operation is under way (not its stop).
    pub(super) fn op_in_motion(&self) -> bool {
        matches!(
            self.state,
            State::Motion(Motion {
                run: Run::Jog(_) | Run::Move(_) | Run::Stream(_),
                ..
            })
        )
    }

    /// Homing takes over from an operation's stop in progress: the stop's
    /// operation ends without PC.
    pub(super) fn homing_takes_over(&mut self) {
        if let State::Motion(m) = self.state {
            self.op_done(m.op, false);
        }
        if let Some((id, _)) = self.ops.await_rest.take() {
            self.op_done(id, false);
        }
    }
}

/// `|x| <= bound`, false for NaN: the one comparison the checks need (a
/// value that is not a number is never within anything).
pub(super) fn within(x: f64, bound: f64) -> bool {
    x.abs() <= bound
}
