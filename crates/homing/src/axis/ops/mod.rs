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
//! * `jog`, `moves`, `stream`, `gear`: each motion, its start and its
//!   progress; `change`: MCD, new dynamics for the running jog or move;
//!   `follower`: the bounded follower of the stream and the gear (one
//!   cycle of arithmetic);
//! * `limits`: software travel limits (homed, linear) and the hardware
//!   limit switches;
//! * `redefine`: redefine position (MRP), the offset alone;
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
//!   limit, never beyond, whatever the step timing). The stream is the one
//!   motion made step by step: its setpoints make a reference path (a
//!   profile of linear segments), which the command follows within the
//!   speed cap and `stream_acceleration` on the cycle's own timeline
//!   (`follower`), whatever the setpoints' timestamps claim.
//! * **Every motion has a speed bound.** `max_speed`, or the one the
//!   homing speeds give; without one jog, move and stream are refused
//!   (13 / 7). Not homed, `unhomed_speed` caps all three.
//! * **Stops stay inside.** Every stop of an operation's motion on a homed
//!   linear axis ends at or inside the travel limits (`limits::stop_within`):
//!   where its deceleration would carry it past a limit, it decelerates
//!   harder and ends on the limit. A stop keeps the limits that applied
//!   when it began, also when the fault that caused it cleared HomedStatus
//!   in the same step. A motion that could not be stopped inside from where
//!   it is (a reversal, a supersede) is refused.
//! * **Which stops keep the jerk.** A normal stop of a jog or move (MAS, a
//!   jog's lease, a jog ended by its client, a disable, a move superseded
//!   by a stop, a jog meeting a travel limit) is planned with the motion's
//!   jerk: an S-curve motion ends as an S-curve. A fault's stop (a limit
//!   switch, a drive fault, lost or implausible feedback, a refused
//!   setpoint) and every stop of the stream are planned with jerk 0: the
//!   shortest stop the deceleration allows (the acceleration steps once,
//!   at its start). A fault during a jerk-limited stop plans a new one
//!   with jerk 0 from where the stop is.
//! * **A stop can stop what was commanded.** A fault's stop brakes at
//!   `max_deceleration` or harder: a stream's at the larger of
//!   `max_deceleration` and `stream_acceleration` (no configuration rule
//!   ties the two, so the stop takes what the stream was allowed); a fault
//!   during a stop never brakes it less hard.
//! * **A refusal is not a fault.** An operation refused leaves everything
//!   as it was. An axis fault (drive fault, limit switch, refused setpoint,
//!   lost feedback while moving, enable timeout) sets ER and `faulted`;
//!   only `Reset` clears them.
//! * **The drive decides the power stage's fate, never a reset.** A drive
//!   fault or a dropped power stage withdraws the enable request in every
//!   state; a reset excuses only the fault it was asked to clear (`power`).

mod change;
mod follower;
mod gear;
mod jog;
mod limits;
pub(super) mod motion;
mod moves;
mod power;
mod redefine;
mod rules;
mod stream;

use super::intake::Sample;
use super::state::State;
use super::Axis;
use crate::operation::{OpKind, OpStatus, Operation, Setpoint, StopCause};
use crate::profile::Kinematics;
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
    /// The travel limits (raw) in force after the previous step: a stop
    /// planned in a step that lost the reference keeps them.
    pub limits_before: Option<(f64, f64)>,
    /// This step's master of a geared slave (`Request::master`).
    pub master: Option<crate::operation::MasterFeed>,
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
            Operation::Change(c) => self.change_op(now, &c),
            Operation::Redefine(r) => self.redefine_op(&r),
            Operation::Arm(a) => self.arm_op(now, &a),
            Operation::Disarm => {
                self.disarm_registration();
                Ok(())
            }
            Operation::Gear(g) => self.gear_op(now, &g),
        };
        match result {
            Err(code) => self.status.op.refused = Some(code),
            // Answered in place: the running operation keeps its id.
            Ok(()) if op.kind().in_place() => self.status.op.refused = None,
            Ok(()) => {}
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
            // A disable already waiting for rest stays a disable: the stop
            // answers in its place, and the power stage still goes off at
            // rest (it stayed on before, and the cycle monitor tripped).
            let disabling = matches!(self.ops.await_rest, Some((_, true)));
            self.ops.await_rest = Some((id, disabling));
        }
    }

    /// The command state a motion continues from: time, and raw position,
    /// velocity and acceleration (the exact state of the profile: a re-plan
    /// from it steps in none of them). A stream's (and a gear's) command is
    /// made step by step (`follower`), so it continues from the last command, at
    /// the previous step, with the velocity it had then (its acceleration
    /// taken as 0: its stops have no jerk): a stop planned from there
    /// continues the motion the drive was last given.
    fn motion_state(&mut self, now: u64) -> (u64, Kinematics) {
        if let Some(v) = self.stepwise_velocity() {
            if let Some(t) = self.ops.prev_step_ns {
                return (t, Kinematics::moving(self.last_command.position, v));
            }
        }
        (now, self.profile.state(now))
    }

    /// A stream's stops brake at the larger of `max_deceleration` and
    /// `stream_acceleration`: the stream may approach a travel limit
    /// braking at `stream_acceleration`, and its stop must be able to stop
    /// what it was commanded (no configuration rule ties the two).
    fn stream_decel(&self) -> f64 {
        self.limits
            .max_deceleration
            .max(self.limits.stream_acceleration)
    }

    /// The command's velocity over the last step of a motion made step by
    /// step (a stream, a gear), whose profile only holds each command.
    fn stepwise_velocity(&self) -> Option<f64> {
        match self.state {
            State::Motion(Motion {
                run: Run::Stream(st),
                ..
            }) => Some(st.velocity),
            State::Motion(Motion {
                run: Run::Gear(g), ..
            }) => Some(g.velocity),
            _ => None,
        }
    }

    /// The deceleration of the running motion (a jog's or move's own, a
    /// stream's stop's, a stop's; else — a gear too — `max_deceleration`).
    fn running_decel(&self) -> f64 {
        match self.state {
            State::Motion(Motion {
                run: Run::Jog(j), ..
            }) => j.decel,
            State::Motion(Motion {
                run: Run::Move(m), ..
            }) => m.decel,
            State::Motion(Motion {
                run: Run::Stream(_),
                ..
            }) => self.stream_decel(),
            State::Motion(Motion {
                run: Run::Halt(h), ..
            }) => h.decel,
            _ => self.limits.max_deceleration,
        }
    }

    /// The jerk of the running motion (a jog's or move's own, a stop's);
    /// 0 for a stream and at rest.
    fn running_jerk(&self) -> f64 {
        match self.state {
            State::Motion(Motion {
                run: Run::Jog(j), ..
            }) => j.jerk,
            State::Motion(Motion {
                run: Run::Move(m), ..
            }) => m.jerk,
            State::Motion(Motion {
                run: Run::Halt(h), ..
            }) => h.jerk,
            _ => 0.0,
        }
    }

    /// Brings the motion to rest at `decel` and `jerk` (0: the shortest
    /// stop), inside the travel limits that apply now (or that applied
    /// when a stop in progress began), answering for operation `op`;
    /// `normal`: PC at rest.
    fn halt(&mut self, now: u64, op: u32, decel: f64, jerk: f64, cause: StopCause, normal: bool) {
        let limits = match self.state {
            State::Motion(Motion {
                run: Run::Halt(h), ..
            }) => h.limits,
            _ => self.stop_limits(),
        };
        let (t, k) = self.motion_state(now);
        self.profile
            .set(Self::stop_within(t, k, decel, jerk, limits));
        self.status.last_stop = cause;
        self.state = State::Motion(Motion {
            op,
            run: Run::Halt(Halt {
                normal,
                decel,
                jerk,
                limits,
            }),
        });
    }

    /// A normal stop of a jog, move or stream with its own deceleration
    /// and jerk (a stream's: none), answering for `op` (`None`: the motion's own operation). False when
    /// there was none to stop (idle, homing, or already stopping).
    pub(super) fn stop_motion(&mut self, now: u64, op: Option<u32>, cause: StopCause) -> bool {
        let State::Motion(m) = self.state else {
            return false;
        };
        if matches!(m.run, Run::Halt(_)) {
            return false;
        }
        let (decel, jerk) = (self.running_decel(), self.running_jerk());
        self.halt(now, op.unwrap_or(m.op), decel, jerk, cause, true);
        true
    }

    /// An axis fault while an operation moves the axis: ER with its code,
    /// `faulted`, the cause shown, the operation ended without PC; the axis
    /// stops at `max_deceleration` or harder with jerk 0, the shortest stop
    /// (a stream's: see `stream_decel`; a stop in progress goes on if it
    /// brakes at least as hard without jerk), inside the travel limits that applied when the stop began —
    /// or, with `power_off`, the drive no longer follows: the power stage
    /// is switched off and the command holds where the axis is.
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
            return true;
        }
        let decel = self.limits.max_deceleration.max(self.running_decel());
        match m.run {
            Run::Halt(h) if h.decel >= decel && h.jerk == 0.0 => {
                // The stop under way already brakes that hard: it goes on,
                // as a fault's.
                self.status.last_stop = cause;
                self.state = State::Motion(Motion {
                    op: m.op,
                    run: Run::Halt(Halt { normal: false, ..h }),
                });
            }
            _ => self.halt(now, m.op, decel, 0.0, cause, false),
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
            Run::Gear(g) => self.advance_gear(now, m.op, g),
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
        let run = match self.state {
            State::Motion(m) => Some(m.run),
            _ => None,
        };
        let halt = matches!(run, Some(Run::Halt(_)));
        self.status.jogging = matches!(run, Some(Run::Jog(_)));
        self.status.moving = matches!(run, Some(Run::Move(_)));
        self.status.streaming = matches!(run, Some(Run::Stream(_)));
        self.status.gearing = matches!(run, Some(Run::Gear(_)));
        self.status.stopping |= halt;
        self.status.servo_action = self.servo_action();
        let (neg, pos) = self.last.map_or((false, false), |s| self.switches(&s));
        self.status.limit_negative = neg;
        self.status.limit_positive = pos;
    }

    /// The velocity the command carries while streaming or geared, instead
    /// of the profile's (which holds each step's command): a stream's
    /// feed-forward while the command is on the reference's segment, else
    /// the command's own velocity over the step.
    pub(super) fn stepwise_command_velocity(&self, now: u64) -> Option<f64> {
        match self.state {
            State::Motion(Motion {
                run: Run::Stream(st),
                ..
            }) => Some(match st.feed_forward {
                Some(ff) if st.on_reference && now <= st.seg_end_ns => ff,
                _ => st.velocity,
            }),
            _ => self.stepwise_velocity(),
        }
    }

    /// A motion of an operation is under way (not its stop).
    pub(super) fn op_in_motion(&self) -> bool {
        matches!(
            self.state,
            State::Motion(Motion {
                run: Run::Jog(_) | Run::Move(_) | Run::Stream(_) | Run::Gear(_),
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
