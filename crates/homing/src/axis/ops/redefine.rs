//! MRP / MC_SetPosition: redefine position, without motion.
//!
//! The axis position is `raw + offset` (wrapped on a cyclic axis); every
//! command the engine makes, every profile and every stored limit inside
//! it is raw. Redefine position therefore changes `offset` and nothing
//! else: the command frame, the drive, the feedback and anything that
//! watches raw positions see no step. The software travel limits are
//! configured in axis coordinates; the shift is kept beside the offset
//! (`shift`) so they stay on the same machine place — their numbers read
//! `travel_limits + shift` — until homing establishes a new reference
//! (which sets the shift back to 0). HomedStatus, PC and the last
//! operation's progress of any earlier operation are kept; the redefine is
//! an operation of its own, accepted and complete in the same step.
//!
//! * **Which position becomes P**: the command position (exact at rest;
//!   the actual keeps its following error, as the drive sees no change).
//! * **Cyclic axes**: the shift is taken modulo `unwind` and the position
//!   reads wrapped into `[0, unwind)`: `--position 370` on a 360 unwind
//!   reads 10, `--by -20` from 10 reads 350.
//! * **Refused** (nothing changes), in this order: homing 16 / 25, faulted
//!   20 / 25, not homed 1023 / 1, not at rest (a jog, move, stream, a stop
//!   or an enable under way) 3 / 25, no valid feedback 12 / 40, coupled to
//!   another axis (`coupling_allows_redefine`), not finite or beyond
//!   ±`max_position` 1023 / 2.

use super::{within, Code};
use crate::axis::state::State;
use crate::axis::Axis;
use crate::codes::*;
use crate::config::TravelMode;
use crate::operation::{OpKind, RedefineSpec};
use crate::position::wrap;

impl Axis {
    /// The shift redefine `r` would apply now, or its refusal. Pure: the
    /// cycle asks it of every side of a gantry before any side is changed.
    pub fn redefine_shift(&self, r: &RedefineSpec) -> Result<f64, Code> {
        self.redefine_gate()?;
        let cyclic = self.cfg.travel == TravelMode::Cyclic && self.cfg.unwind > 0.0;
        let delta = if r.relative {
            r.value
        } else {
            r.value - self.to_axis(self.last_command.position)
        };
        let delta = if cyclic && delta.is_finite() {
            wrap(delta, self.cfg.unwind)
        } else {
            delta
        };
        // Every number that follows from it stays within ±max_position,
        // the bound every position of the axis has (NaN never does).
        let bound = self.cfg.max_position.min(f64::MAX);
        let offset = self.offset + delta;
        let shift = self.shift + delta;
        let (lo, hi) = self.cfg.travel_limits.unwrap_or((0.0, 0.0));
        let fits = [
            offset,
            shift,
            lo + shift,
            hi + shift,
            self.to_axis(self.last_command.position) + delta,
        ]
        .iter()
        .all(|x| within(*x, bound));
        if !fits {
            return Err((ERR_REDEFINE_REFUSED, EX_REDEFINE_NOT_FINITE));
        }
        Ok(delta)
    }

    /// Applies redefine `r` (accepted and complete in this step), or
    /// refuses it with nothing changed.
    pub(super) fn redefine_op(&mut self, r: &RedefineSpec) -> Result<(), Code> {
        let delta = self.redefine_shift(r)?;
        let id = self.accept_op(OpKind::Redefine);
        self.offset += delta;
        self.shift += delta;
        self.registration_follows(delta);
        self.last_redefine = Some((id, delta));
        self.status.redefines = self.status.redefines.wrapping_add(1);
        self.op_done(id, true);
        Ok(())
    }

    /// Takes back redefine `id` when it is the last one applied and no
    /// other operation came after it: a gantry whose other side refused in
    /// the same step is redefined whole or not at all. Nothing moved, so
    /// nothing else is undone. False when there was nothing to take back.
    pub fn take_back_redefine(&mut self, id: u32) -> bool {
        match self.last_redefine {
            Some((last, delta)) if last == id && self.status.op.id == id => {
                self.offset -= delta;
                self.shift -= delta;
                self.registration_follows(-delta);
                self.last_redefine = None;
                self.status.redefines = self.status.redefines.wrapping_sub(1);
                self.status.op.pc = false;
                self.status.shift = self.shift;
                self.status.soft_limits = self.soft_limits_axis();
                true
            }
            _ => false,
        }
    }

    /// What redefine position needs, in the order a Logix instruction
    /// reports it.
    fn redefine_gate(&self) -> Result<(), Code> {
        if self.status.ip {
            return Err((ERR_HOME_IN_PROCESS, EX_REDEFINE));
        }
        if self.status.faulted {
            return Err((ERR_AXIS_FAULTED, EX_REDEFINE));
        }
        if !self.status.homed {
            return Err((ERR_REDEFINE_REFUSED, EX_REDEFINE_NOT_HOMED));
        }
        let at_rest = matches!(self.state, State::Idle) && self.ops.await_rest.is_none();
        if !at_rest {
            return Err((ERR_EXECUTION_COLLISION, EX_REDEFINE));
        }
        if self.last.is_none() {
            return Err((ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST));
        }
        self.coupling_allows_redefine()
    }
}
