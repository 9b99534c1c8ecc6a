//! The operations around homing as the cycle applies them (enable,
//! disable, reset, jog, move, the stream's acquire and release, jog
//! renewals): the rules only the cycle can judge, the delivery to every
//! engine of a request in the same cycle, the engines' answers after the
//! step, and what the cycle keeps up between requests (a gantry's sides
//! never move alone, an owner's axes while they stream).
//!
//! Rules here, each in a function of its own: a program's axes refuse
//! home, jog, move and another owner (ERR 3, [`Refusal::Owned`]); an axis
//! in a home sequence refuses motion ([`Refusal::Busy`]); an axis whose
//! I/O process is not attached refuses enable and motion; everything else
//! (servo off, homing, faulted, parameters, limits) is the engine's to
//! judge, with the instruction's ERR / EXERR. A request for a gantry is
//! accepted on all its sides or on none: sides an engine accepted while
//! another side refused are stopped again in the next cycle (nothing has
//! moved by more than one cycle's acceleration) and answered "not started".

use motion_homing::{OpKind, Operation, RedefineSpec, Setpoint};

use super::{named, Core};
use crate::shared::{Ack, AxisAck, Refusal};

/// Requests waiting for their engines' answers (the control thread asks
/// one at a time; four is room to spare).
pub(super) const MAX_PENDING: usize = 4;

/// What a request answered after the step does when accepted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Then {
    /// Nothing more.
    Nothing,
    /// A jog: its token goes with every axis (for the renewals).
    Jog(u64),
    /// A stream: the token owns the axes.
    Own(u64),
}

/// A request delivered to engines in this cycle, answered after the step.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pending {
    ack: Ack,
    mask: u64,
    then: Then,
    /// A motion (jog, move, stream) or a redefine: a gantry accepts it
    /// whole or not at all.
    motion: bool,
    /// Answered in place (a change): accepted when the engine left no
    /// refusal, the running motion's id unchanged.
    in_place: bool,
    kind: OpKind,
}

/// Operations that move the axis (or take it over to be moved).
fn is_motion(op: &Operation) -> bool {
    op.kind().moves()
}

impl Core {
    /// Why axis `i` cannot be given `op` now, before its engine judges it.
    fn op_refusal(&self, i: usize, op: &Operation) -> Option<Refusal> {
        let slot = &self.slots[i];
        let always = matches!(
            op,
            Operation::Disable | Operation::Stop | Operation::StreamEnd
        );
        if self.exiting && !always {
            return Some(Refusal::Exiting);
        }
        if slot.rung.request.op.is_some() {
            return Some(Refusal::Busy);
        }
        let motion = is_motion(op);
        if motion && self.stream.owner_of(i) != 0 {
            return Some(Refusal::Owned);
        }
        if motion && (slot.rung.pending > 0 || self.seq.busy() & (1 << i) != 0) {
            return Some(Refusal::Busy);
        }
        if (motion || *op == Operation::Enable) && !self.links[slot.io].attached() {
            return Some(Refusal::IoNotAttached);
        }
        self.gear_refusal(i, op)
    }

    /// Delivers `op` (as the client gave it: each engine fills what was
    /// left out from its own configuration) to every engine of `mask` in
    /// this step; a hold-to-run one is named by `token` for its renewals.
    pub(super) fn op(&mut self, ack: Ack, mask: u64, op: Operation, token: u64) -> Option<Ack> {
        let then = if op.kind().held() {
            Then::Jog(token)
        } else {
            Then::Nothing
        };
        self.deliver(ack, mask, op, then)
    }

    /// `token` takes the axes of `mask` over for its setpoint stream: they
    /// start streaming in this step (all of them, or none).
    pub(super) fn stream_acquire(&mut self, ack: Ack, mask: u64, token: u64) -> Option<Ack> {
        self.deliver(ack, mask, Operation::StreamStart, Then::Own(token))
    }

    /// Delivers `op` to every engine of `mask` in this step (all of them, or
    /// none when the cycle refuses one); answered after the step.
    fn deliver(&mut self, mut ack: Ack, mask: u64, op: Operation, then: Then) -> Option<Ack> {
        let n = self.slots.len();
        for i in named(mask, n) {
            if let Some(r) = self.op_refusal(i, &op) {
                ack.axes[i] = AxisAck::Refused(r);
            }
        }
        if named(mask, n).any(|i| ack.axes[i] != AxisAck::NotNamed) {
            for i in named(mask, n) {
                if ack.axes[i] == AxisAck::NotNamed {
                    ack.axes[i] = AxisAck::Refused(Refusal::NotStarted);
                }
            }
            return Some(ack);
        }
        let Some(free) = self.pending.iter_mut().find(|p| p.is_none()) else {
            for i in named(mask, n) {
                ack.axes[i] = AxisAck::Refused(Refusal::Busy);
            }
            return Some(ack);
        };
        *free = Some(Pending {
            ack,
            mask,
            then,
            motion: is_motion(&op),
            in_place: op.kind().in_place(),
            kind: op.kind(),
        });
        for i in named(mask, n) {
            let side_op = self.whole_gantry(i, op);
            let slot = &mut self.slots[i];
            slot.op_before = slot.status().op.id;
            slot.rung.request.op = Some(side_op);
        }
        None
    }

    /// A gantry is redefined as a whole: `--position P` on a side becomes
    /// the shift that makes its gantry's first side read P, the same shift
    /// for every side (their skew is kept). The first side's command is at
    /// rest when the redefine is accepted, so the shift is the one its
    /// engine would work out in the step.
    fn whole_gantry(&self, i: usize, op: Operation) -> Operation {
        let Operation::Redefine(r) = op else {
            return op;
        };
        let Some(sides) = self.gantry_mask.iter().copied().find(|g| g & (1 << i) != 0) else {
            return op;
        };
        if r.relative {
            return op;
        }
        let lead = &self.slots[sides.trailing_zeros() as usize].engine;
        let p = lead.to_axis(lead.last_command().position);
        Operation::Redefine(RedefineSpec::by(r.value - p))
    }

    /// Renews (or ends) jog `token` on the axes of `mask` (0: every axis)
    /// that still run it; refused ([`Refusal::Token`]) where none does.
    pub(super) fn jog_renew(&mut self, mut ack: Ack, token: u64, mask: u64, end: bool) -> Ack {
        let n = self.slots.len();
        let mask = if mask == 0 { u64::MAX } else { mask };
        for (i, slot) in self.slots.iter_mut().enumerate() {
            let named = mask & (1 << i) != 0;
            if !named || token == 0 || slot.jog_token != token {
                continue;
            }
            if end {
                // A stop of the jog itself (MAS), not a new operation: the
                // jog's own id ends with it (PC once at rest).
                slot.rung.request.stop = true;
            } else {
                slot.rung.request.jog_renew = true;
            }
            ack.axes[i] = AxisAck::Accepted;
        }
        if !ack.axes[..n].iter().any(AxisAck::accepted) {
            for i in named(mask, n) {
                ack.axes[i] = AxisAck::Refused(Refusal::Token);
            }
        }
        ack
    }

    /// Ends the stream of `token`: its axes stop (`StreamEnd`), their
    /// setpoints are no longer taken.
    /// The answer (after the step) carries the `StreamEnd`s' operation ids:
    /// a client follows those to see the axes at rest.
    pub(super) fn stream_release(&mut self, ack: Ack, token: u64) -> Option<Ack> {
        let mask = self.stream.mask_of(token);
        if mask == 0 {
            return Some(ack);
        }
        self.stream.drop_axes(mask);
        self.deliver(ack, mask, Operation::StreamEnd, Then::Nothing)
    }

    /// After the step: every pending request's answer per axis (the
    /// engine's: a new operation id, or its refusal), handed to `each`.
    pub(super) fn op_answers(&mut self, mut each: impl FnMut(Ack)) {
        for k in 0..MAX_PENDING {
            let Some(mut p) = self.pending[k].take() else {
                continue;
            };
            let n = self.slots.len();
            let mut accepted = 0u64;
            for i in named(p.mask, n) {
                let s = self.slots[i].status().op;
                let in_place = p.in_place && s.refused.is_none();
                if in_place || s.id != self.slots[i].op_before {
                    accepted |= 1 << i;
                    p.ack.axes[i] = AxisAck::Accepted;
                    p.ack.op_ids[i] = s.id;
                } else {
                    let (err, exerr) = s.refused.unwrap_or((0, 0));
                    p.ack.axes[i] = AxisAck::Refused(Refusal::Operation { err, exerr });
                }
            }
            if p.motion || matches!(p.then, Then::Own(_)) {
                accepted = self.whole_or_nothing(&mut p, accepted);
            }
            self.carry_out(p.then, accepted);
            p.ack.cycle = self.cycle;
            each(p.ack);
        }
    }

    /// A motion accepted only in part (on some axes, or on some sides of a
    /// gantry) is taken back where it was accepted: those axes stop (a
    /// stream: ends) in the next step and are answered "not started"; a
    /// redefine is taken back at once (nothing moved; the frame already
    /// published carried no change). Returns what stays accepted.
    fn whole_or_nothing(&mut self, p: &mut Pending, accepted: u64) -> u64 {
        if accepted == p.mask {
            return accepted;
        }
        if p.kind == OpKind::Redefine {
            for i in named(accepted, self.slots.len()) {
                let slot = &mut self.slots[i];
                let id = slot.status().op.id;
                slot.engine.take_back_redefine(id);
                p.ack.axes[i] = AxisAck::Refused(Refusal::NotStarted);
            }
            return 0;
        }
        let undo = match p.then {
            Then::Own(_) => Operation::StreamEnd,
            // A change accepted by some sides only: those sides would run
            // on with other dynamics than the rest, so they stop too.
            _ => Operation::Stop,
        };
        for i in named(accepted, self.slots.len()) {
            self.slots[i].rung.request.op = Some(undo);
            p.ack.axes[i] = AxisAck::Refused(Refusal::NotStarted);
        }
        0
    }

    /// What an accepted request leaves behind: the jog's token, the
    /// stream's owner.
    fn carry_out(&mut self, then: Then, accepted: u64) {
        match then {
            Then::Nothing => {}
            Then::Jog(token) => {
                for i in named(accepted, self.slots.len()) {
                    let slot = &mut self.slots[i];
                    slot.jog_token = token;
                    slot.jog_op = slot.status().op.id;
                }
            }
            Then::Own(token) => {
                if accepted != 0 && !self.stream.grant(token, accepted) {
                    for i in named(accepted, self.slots.len()) {
                        self.slots[i].rung.request.op = Some(Operation::StreamEnd);
                    }
                }
            }
        }
    }

    /// This cycle's setpoints into the engines' requests (before they step).
    pub(super) fn hand_setpoints(&mut self) {
        for (i, slot) in self.slots.iter_mut().enumerate() {
            let sp: Option<Setpoint> = self.stream.setpoint(i);
            slot.rung.request.setpoint = sp;
        }
    }

    /// After the step: what ended by itself. A jog that no longer runs
    /// forgets its token; an owned axis that no longer streams (stopped, a
    /// refused setpoint, a fault, feedback lost, unhomed) is no longer
    /// owned; a gantry side whose jog or stream ended, or that faulted,
    /// stops the other sides (and its gantry's stream ends).
    pub(super) fn op_upkeep(&mut self) {
        let owned = self.stream.owned();
        let mut over = 0u64;
        for (i, slot) in self.slots.iter_mut().enumerate() {
            let s = *slot.status();
            if slot.jog_token != 0 && (s.op.id != slot.jog_op || !s.jogging) {
                slot.jog_token = 0;
                over |= 1 << i;
            }
            if owned & (1 << i) != 0 && !s.streaming {
                over |= 1 << i;
            }
            if s.faulted && !slot.was_faulted {
                over |= 1 << i;
            }
            slot.was_faulted = s.faulted;
        }
        self.stream.drop_axes(over & owned);
        for g in 0..self.gantry_mask.len() {
            let sides = self.gantry_mask[g];
            if over & sides == 0 {
                continue;
            }
            for i in named(sides & !over, self.slots.len()) {
                let slot = &mut self.slots[i];
                let s = slot.status();
                if s.jogging || s.moving || s.streaming || s.gearing {
                    slot.rung.request.op = Some(Operation::Stop);
                }
                slot.jog_token = 0;
            }
            self.stream.drop_axes(sides & owned);
        }
    }
}
