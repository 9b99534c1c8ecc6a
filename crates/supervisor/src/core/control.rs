//! The control queue's requests as the cycle applies them: one function per
//! request, each answering per axis in the domain's words ([`Refusal`]).
//! The rules that need the configuration's names (unknown axes, gantry
//! sides) were applied by the control thread before; these are the ones
//! only the cycle can judge (in process, attached, busy, leaving).

use motion_homing::codes::{ERR_AXIS_FAULTED, ERR_EXECUTION_COLLISION, ERR_ILLEGAL_HOMING_CONFIG};

use super::{named, Core};
use crate::shared::{Ack, Ask, AxisAck, Control, Refusal};

impl Core {
    /// Applies one control request at `now_ns` (the cycle's time, on the
    /// clock of its deadline); requests with an id are answered (with the
    /// cycle in which they take effect: the next step) — the operations an
    /// engine must judge after that step ([`Core::answers`]). A request
    /// past its deadline is answered [`Ack::expired`] and has no effect at
    /// all: whoever asked has been told so.
    pub fn control(&mut self, c: Control, now_ns: u64) -> Option<Ack> {
        let ack = Ack::new(c.id);
        if now_ns > c.deadline_ns {
            return Some(Ack {
                expired: true,
                cycle: self.cycle,
                ..ack
            });
        }
        let mut ack = match c.ask {
            Ask::Home {
                mask,
                parallel,
                timeout_ns,
            } => self.home(ack, mask, parallel, timeout_ns, now_ns),
            Ask::Stop { mask } => self.stop(ack, mask),
            Ask::Unhome { mask } => self.unhome(ack, mask),
            Ask::Trace { axis } => self.trace(ack, axis),
            Ask::Restore {
                axis,
                offset,
                shift,
            } => self.restore(ack, axis, (offset, shift), now_ns),
            Ask::Exit => {
                self.exit();
                return None;
            }
            Ask::Op { mask, op, token } => self.op(ack, mask, op, token)?,
            Ask::JogRenew { token, mask, end } => self.jog_renew(ack, token, mask, end),
            Ask::StreamAcquire { mask, token } => self.stream_acquire(ack, mask, token)?,
            Ask::StreamRelease { token } => self.stream_release(ack, token)?,
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
        if s.jogging || s.moving || s.streaming || s.gearing {
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
            let slot = &mut self.slots[i];
            slot.rung.request.stop = true;
            slot.rung.pending = 0;
            slot.operator_stop = true;
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
    fn restore(&mut self, mut ack: Ack, axis: usize, reference: (f64, f64), now: u64) -> Ack {
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
            match slot.engine.restore_reference(now, reference.0, reference.1) {
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
            s.operator_stop = true;
        }
    }
}
