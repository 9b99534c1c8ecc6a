//! The power stage: asked on only while someone asked for it (EN 60204-1
//! §7.5: a drive that went off never comes back on by itself).
//!
//! The permission is given by an explicit request the engine accepted —
//! enable, home, jog, move, stream — and withdrawn by what takes the power
//! stage away: a drive fault that appears, a power stage the drive dropped
//! while it was asked on (STO, a power return; also one found off when a
//! lost drive is back), a new I/O process (its drives were off or stopped
//! by its watchdog in between), a drive its I/O process reports lost while
//! an enable still waited for it, a shutdown. A disable withdraws it once
//! the axis has had the time its stop needs (the speed bound has decayed to
//! rest) and one more cycle: category 1, then off.
//!
//! Judged only on a cycle whose feedback is valid and whose drive is
//! present: the engine then knew what the monitor knows (a fault seen in
//! this cycle's feedback is one the engine must answer in this cycle). A
//! shutdown is judged at once.

use crate::events::Events;
use crate::trip::{Broken, Invariant, Withdrawn};
use motion_homing::{Operation, Request};

#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Power {
    /// Asked on since it last had to go off.
    allowed: bool,
    /// A disable was accepted and not overruled since.
    disabling: bool,
    /// Cycles the disabling axis has been at rest by the speed bound.
    rested: u8,
    /// What took the permission away last.
    why: Withdrawn,
}

impl Power {
    /// Takes this cycle's requests and drive events (requests first: a
    /// fault that appears in the cycle of an enable still withdraws it).
    pub fn observe(&mut self, ev: &Events, req: &Request) {
        let asked = matches!(
            ev.accepted,
            Some(
                Operation::Enable
                    | Operation::Jog { .. }
                    | Operation::Move { .. }
                    | Operation::StreamStart
            )
        );
        if asked || ev.home_started {
            self.allowed = true;
            self.disabling = false;
            self.rested = 0;
        }
        if ev.accepted == Some(Operation::Disable) {
            self.disabling = true;
        }
        // A drive lost while its power stage was on is judged by what it
        // reports when it is back (on, dropped, faulted); one lost while an
        // enable still waited for it takes that enable away.
        let was_on = ev.drive.is_some_and(|d| d.enabled && !d.fault);
        let why = if ev.drive_fault {
            Some(Withdrawn::DriveFault)
        } else if ev.dropped {
            Some(Withdrawn::PowerDropped)
        } else if req.drive_lost && !was_on {
            Some(Withdrawn::DriveLost)
        } else if ev.io_restarted {
            Some(Withdrawn::IoRestarted)
        } else if req.shutdown {
            Some(Withdrawn::Shutdown)
        } else {
            None
        };
        if let Some(w) = why {
            self.allowed = false;
            self.why = w;
        }
    }

    /// The command asks the power stage `on`: allowed? `at_rest`: the
    /// speed bound has decayed to rest.
    pub fn judge(
        &mut self,
        on: bool,
        at_rest: bool,
        ev: &Events,
        req: &Request,
    ) -> Result<(), Broken> {
        if self.disabling && !on {
            // The disable is done: off until asked again.
            self.disabling = false;
            self.allowed = false;
            self.why = Withdrawn::Disabled;
        }
        self.rested = if self.disabling && at_rest {
            self.rested.saturating_add(1)
        } else {
            0
        };
        let present = ev.fresh && !req.drive_lost;
        let withdrawn = if req.shutdown {
            Some(Withdrawn::Shutdown)
        } else if self.rested > 2 {
            Some(Withdrawn::Disabled)
        } else {
            (present && !self.allowed).then_some(self.why)
        };
        if let (true, Some(w)) = (on, withdrawn) {
            return Err(Broken {
                invariant: Invariant::Enable,
                value: 1.0,
                bound: 0.0,
                withdrawn: Some(w),
            });
        }
        Ok(())
    }

    /// After a trip's reset: off until asked again.
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}
