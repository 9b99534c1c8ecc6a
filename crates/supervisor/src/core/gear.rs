//! Gearing (MAG) across axes: the one place the cycle relates a geared
//! slave to its master. Each engine only knows its own axis; here the
//! cycle
//!
//! * steps every slave **after** every other axis, handing it its master's
//!   news of this same cycle (`Request::master`: command and actual
//!   position after the master's step, its acceleration bound, whether it
//!   was stopped, disabled or began homing, whether it is faulted) — no
//!   cycle of lag between master and slave;
//! * refuses what only it can see: a master that is the slave itself
//!   (ERR 1025 / 4), a chain (the master is geared, or the slave is a
//!   master: 1025 / 6 — one level keeps the stepping order exact);
//! * stops the master in the next cycle when a geared slave faults (its
//!   limit, its drive, a master it cannot follow);
//! * answers whether an axis takes part in a gearing ([`Core::in_gearing`]),
//!   which an operation that must not change an axis's positions under a
//!   gear (redefine position) reads.
//!
//! A master's stop here is an operator's `stop` of that axis (`Core::stop`,
//! or leaving), a `Stop` or `Disable` operation, or its homing starting;
//! the normal end of a master's jog or move is not a stop of the gearing.

use motion_homing::codes::{
    ERR_GEARING, ERR_REDEFINE_REFUSED, EX_GEAR_CHAINED, EX_GEAR_SELF, EX_REDEFINE_GEARED,
};
use motion_homing::{MasterFeed, Operation};

use super::slot::AxisSlot;
use super::Core;
use crate::shared::Refusal;

impl AxisSlot {
    /// The master this axis follows in this cycle: the one of a gear
    /// delivered now, else the one its engine follows.
    pub(super) fn gear_master(&self) -> Option<usize> {
        match self.rung.request.op {
            Some(Operation::Gear(g)) => g.master_index().map(usize::from),
            _ => self.engine.gear_master().map(usize::from),
        }
    }

    /// What a slave geared to this axis is told of it after its step.
    pub(super) fn master_feed(&self) -> MasterFeed {
        MasterFeed {
            commanded: self.command.position,
            actual: self.engine.raw_position(),
            accel: self.engine.acceleration_bound(),
            stopped: self.halted,
            faulted: self.status().faulted,
        }
    }
}

impl Core {
    /// The axes stepped after the others, with their master's news: every
    /// geared slave (and every axis a gear is delivered to now).
    pub(super) fn slaves(&self) -> u64 {
        (self.slots.iter().enumerate())
            .filter(|(_, s)| s.gear_master().is_some())
            .fold(0, |m, (i, _)| m | 1 << i)
    }

    /// Before a slave steps: its master's news of this cycle (`None`: the
    /// master's index is not an axis: the engine refuses or ends it).
    pub(super) fn feed_slave(&mut self, i: usize) {
        let feed = (self.slots[i].gear_master())
            .and_then(|m| self.slots.get(m))
            .map(AxisSlot::master_feed);
        self.slots[i].rung.request.master = feed;
    }

    /// Why axis `i` may not take `op` because of a gear, before its engine
    /// judges it: a gear whose master is the axis itself, or that would
    /// chain; a redefine position of a geared axis, master or slave (the
    /// reference the gear follows would move under it: 1023 / 3). The one
    /// place that sees both ends of every gear.
    pub(super) fn gear_refusal(&self, i: usize, op: &Operation) -> Option<Refusal> {
        if matches!(op, Operation::Redefine(_)) && self.in_gearing(i) {
            return Some(Refusal::Operation {
                err: ERR_REDEFINE_REFUSED,
                exerr: EX_REDEFINE_GEARED,
            });
        }
        let Operation::Gear(g) = op else {
            return None;
        };
        let master = g.master_index().map(usize::from)?;
        let code = |exerr| {
            Some(Refusal::Operation {
                err: ERR_GEARING,
                exerr,
            })
        };
        if master == i {
            return code(EX_GEAR_SELF);
        }
        let master_geared = self.slots.get(master).and_then(AxisSlot::gear_master);
        let is_a_master = self.slots.iter().any(|s| s.gear_master() == Some(i));
        if master_geared.is_some() || is_a_master {
            return code(EX_GEAR_CHAINED);
        }
        None
    }

    /// Axis `i` is geared, or is the master of a geared axis: its
    /// positions must not be redefined under the gear.
    pub fn in_gearing(&self, i: usize) -> bool {
        self.slots.get(i).is_some_and(|s| s.gear_master().is_some())
            || self.slots.iter().any(|s| s.gear_master() == Some(i))
    }

    /// After the step: the master of a slave that faulted while geared
    /// stops (in the next cycle, as a gantry's other sides do) — a gantry
    /// side as master stops with every side of its gantry, never alone.
    pub(super) fn gear_upkeep(&mut self) {
        for i in 0..self.slots.len() {
            let Some(m) = self.slots[i].stop_master.take() else {
                continue;
            };
            let sides = (self.gantry_mask.iter().copied())
                .find(|g| g & (1 << m) != 0)
                .unwrap_or(1 << m);
            for k in 0..self.slots.len() {
                if sides & (1 << k) == 0 {
                    continue;
                }
                let side = &mut self.slots[k];
                if side.rung.request.op.is_none() {
                    side.rung.request.op = Some(Operation::Stop);
                }
            }
        }
    }
}
