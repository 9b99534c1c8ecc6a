//! The control queue's requests as the cycle applies them: one function per
//! request, each answering per axis in the domain's words ([`Refusal`]).
//! The rules that need the configuration's names (unknown axes, gantry
//! sides) were applied by the control thread before; these are the ones
//! only the cycle can judge (in process, attached, busy, leaving).

use motion_homing::codes::{ERR_AXIS_FAULTED, ERR_EXECUTION_COLLISION, ERR_ILLEGAL_HOMING_CONFIG};

use super::ops::Then;
use super::Core;
use crate::shared::{Ack, AxisAck, Control, Refusal};

/// The axes of `mask` among the first `n`, in index order.
pub(super) fn named(mask: u64, n: usize) -> impl Iterator<Item = usize> {
    (0..n.min(64)).filter(move |&i| mask & (1 << i) != 0)
}

impl Core {
    /// Applies one control request; requests with an id are answered (with
    /// the cycle in which they take effect: the next step) — the operations
    /// an engine must judge after that step ([`Core::answers`]).
    pub fn control(&mut self, c: Control, now_ns: u64) -> Option<Ack> {
        let mut ack = match c {
            Control::Home {
                id,
                mask,
                parallel,
                timeout_ns,
            } => self.home(Ack::new(id), mask, parallel, timeout_ns, now_ns),
            Control::Stop { id, mask } => self.stop(Ack::new(id), mask),
            Control::Unhome { id, mask } => self.unhome(Ack::new(id), mask),
            Control::Trace { id, axis } => self.trace(Ack::new(id), axis),
            Control::Restore { id, axis, offset } => {
                self.restore(Ack::new(id), axis, offset, now_ns)
            }
            Control::Exit => {
                self.exit();
                return None;
            }
            Control::Op {
                id,
                mask,
                op,
                token,
            } => {
                let then = match op {
                    motion_homing::Operation::Jog { .. } => Then::Jog(token),
                    _ => Then::Nothing,
                };
                self.op(Ack::new(id), mask, op, then)?
            }
            Control::JogRenew {
                id,
                token,
                mask,
                end,
            } => self.jog_renew(Ack::new(id), token, mask, end),
            Control::StreamAcquire { id, mask, token } => self.op(
                Ack::new(id),
                mask,
                motion_homing::Operation::StreamStart,
                Then::Own(token),
            )?,
            Control::StreamRelease { id, token } => self.stream_release(Ack::new(id), token)?,
        };
        ack.cycle = self.cycle + 1;
        Some(ack)
    }

    /// Why axis `i` cannot start homing now, if it cannot.
    fn home_refusal(&self, i: usize) -> Option<Refusal> {
        let slot = &self.slots[i];
        if self.exiting {
            return Some(Refusal::Exiting);
        }
        if self.stream.owner_of(i) != 0 {
            return Some(Refusal::Owned);
        }
        if slot.status().ip || slot.rung.pending > 0 {
            return Some(Refusal::AlreadyHoming);
        }
        // The engine would refuse these too, by the Home instruction's ER —
        // which would overwrite the axis fault's own ERR / EXERR: answered
        // here instead, and the engine never sees the rung rise.
        let s = slot.status();
        if s.faulted {
            return Some(Refusal::Instruction {
                err: ERR_AXIS_FAULTED,
                exerr: 0,
            });
        }
        if s.jogging || s.moving || s.streaming {
            return Some(Refusal::Instruction {
                err: ERR_EXECUTION_COLLISION,
                exerr: 0,
            });
        }
        if self.seq.busy() & (1 << i) != 0 {
            return Some(Refusal::Busy);
        }
        if let Some(exerr) = slot.engine.config_error() {
            return Some(Refusal::Instruction {
                err: ERR_ILLEGAL_HOMING_CONFIG,
                exerr,
            });
        }
        if !self.links[slot.io].attached() {
            return Some(Refusal::IoNotAttached);
        }
        None
    }

    /// Home the axes of `mask` as one sequence: all of them or none (a
    /// sequence with holes would home the machine in the wrong order).
    fn home(&mut self, mut ack: Ack, mask: u64, parallel: bool, timeout_ns: u64, now: u64) -> Ack {
        let n = self.slots.len();
        let mut accepted = 0u64;
        for i in named(mask, n) {
            ack.axes[i] = match self.home_refusal(i) {
                Some(r) => AxisAck::Refused(r),
                None => {
                    accepted |= 1 << i;
                    AxisAck::Accepted
                }
            };
        }
        let all_ok = named(mask, n).all(|i| ack.axes[i].accepted());
        if !all_ok || accepted == 0 {
            for a in ack.axes.iter_mut().filter(|a| a.accepted()) {
                *a = AxisAck::Refused(Refusal::NotStarted);
            }
            return ack;
        }
        let deadline = if timeout_ns > 0 {
            now.saturating_add(timeout_ns)
        } else {
            0
        };
        if !self.seq.begin(accepted, parallel, deadline) {
            for i in named(accepted, n) {
                ack.axes[i] = AxisAck::Refused(Refusal::Busy);
            }
        }
        ack
    }

    /// Stop (MAS) the axes of `mask`; a rising edge still pending is dropped.
    fn stop(&mut self, mut ack: Ack, mask: u64) -> Ack {
        for i in named(mask, self.slots.len()) {
            let rung = &mut self.slots[i].rung;
            rung.request.stop = true;
            rung.pending = 0;
            ack.axes[i] = AxisAck::Accepted;
        }
        ack
    }

    /// Clear HomedStatus of the axes of `mask` (refused while homing).
    fn unhome(&mut self, mut ack: Ack, mask: u64) -> Ack {
        for i in named(mask, self.slots.len()) {
            let slot = &mut self.slots[i];
            ack.axes[i] = if slot.rung.pending == 0 && slot.engine.clear_homed() {
                slot.homed.cleared();
                AxisAck::Accepted
            } else {
                AxisAck::Refused(Refusal::AlreadyHoming)
            };
        }
        ack
    }

    /// Record every cycle of the next homing of `axis`.
    fn trace(&mut self, mut ack: Ack, axis: usize) -> Ack {
        if axis < self.slots.len() {
            self.tracer.arm(axis);
            ack.axes[axis] = AxisAck::Accepted;
        }
        ack
    }

    /// Apply a stored reference to `axis` without motion (the engine checks
    /// the feedback and the travel limits).
    fn restore(&mut self, mut ack: Ack, axis: usize, offset: f64, now: u64) -> Ack {
        if axis >= self.slots.len() {
            return ack;
        }
        let busy = self.slots[axis].rung.pending > 0 || self.seq.busy() & (1 << axis) != 0;
        let slot = &mut self.slots[axis];
        ack.axes[axis] = if self.exiting {
            AxisAck::Refused(Refusal::Exiting)
        } else if busy {
            AxisAck::Refused(Refusal::Busy)
        } else {
            match slot.engine.restore_reference(now, offset) {
                Ok(()) => {
                    slot.homed.restored();
                    AxisAck::Accepted
                }
                Err(why) => AxisAck::Refused(Refusal::Restore(why)),
            }
        };
        ack
    }

    /// Leaving: stop every axis (setpoints are no longer taken); the drives
    /// are disabled once at rest.
    fn exit(&mut self) {
        self.exiting = true;
        self.stream.drop_axes(u64::MAX);
        for s in &mut self.slots {
            s.rung.pending = 0;
            s.rung.request.home = false;
            s.rung.request.stop = true;
        }
    }
}
