//! The power stage and the drive's faults: enable (MSO), disable (MSF),
//! fault reset (MAFR), and what the drive's state bits mean for the axis.
//!
//! * **A drive fault is an axis fault**, whenever it is seen (at rest too):
//!   ER 12 / 16 and `faulted`, the power stage requested off; a motion
//!   ends with the drive (it no longer follows: the command holds where
//!   the axis is). Homing, enable, jog, move and stream are refused (ERR
//!   20) until `Reset`: the drive's fault is never cleared by enabling it
//!   again (Logix: MAH on a faulted axis errors with 20). Homing used to
//!   toggle the enable to reset a fault by itself; it no longer does.
//! * **Reset** clears the axis's ER and `faulted` and sets
//!   `Command::fault_reset` for at least [`RESET_MIN_STEPS`] steps and
//!   until the drive reports no fault (bounded by `enable_timeout`): the
//!   drive sees a rising edge whatever the frame timing. A fault the
//!   drive still reports after that (a wire break, an overload that
//!   persists) is an axis fault again. Reset never enables, never moves.
//! * **A fault during a reset is a fault.** The reset excuses only the
//!   fault it was asked to clear: the drive's fault bit is not judged
//!   while the drive still reports the fault it reported when the reset
//!   was accepted, and only until it first reports none. A reset accepted
//!   on a drive without a fault (a jogging axis) excuses nothing: a fault
//!   in the next cycle ends the motion at once, however many resets came.
//! * **The power stage never comes on by itself.** The engine requests it
//!   on only for an `Enable` or a homing start; when the drive faults or
//!   drops it (STO, a power return, an I/O process restart) the request is
//!   withdrawn in the step that sees it, in every state — idle, enabling,
//!   every homing leg, homing's abort ramp, an operation's motion or its
//!   stop — so the drive stays off until someone enables it again
//!   (EN 60204-1 §7.5), and a reset can never walk it back on. A drive
//!   the I/O process reports lost, and the drives of a restarted I/O
//!   process, are treated alike (`drive_gone_away`). A stop in
//!   progress is abandoned (the drive no longer follows it: the command
//!   holds where the axis is). In motion that is an axis fault (12 / 16).
//! * **Enable** holds the actual position: while the power stage is off
//!   the command follows the actual position, so it comes on without a
//!   jump. The drive must report enabled within `enable_timeout`, else ER
//!   12 / 42 (an axis fault: the drive did not do what it was told).

use super::Code;
use crate::axis::intake::Sample;
use crate::axis::state::State;
use crate::axis::{Abort, Axis};
use crate::codes::*;
use crate::operation::{OpKind, StopCause};
use crate::profile::Profile;

/// Fewest steps `Command::fault_reset` stays set after a reset.
pub const RESET_MIN_STEPS: u8 = 3;

/// The power stage as the operations see it.
#[derive(Clone, Copy, Debug, Default)]
pub(in crate::axis) struct Power {
    /// An `Enable` waits for the drive: its op id, and since when.
    pub enabling: Option<(u32, u64)>,
    /// The drive has reported enabled since the power stage was last
    /// requested on.
    pub confirmed: bool,
    /// A fault reset in progress.
    pub reset: Option<Reset>,
}

/// A fault reset in progress.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Reset {
    op: u32,
    since: u64,
    /// Commands sent with `fault_reset` set.
    sent: u8,
    /// The drive still reports the fault it reported when the reset was
    /// accepted (never reported none since): that fault is not judged.
    excused: bool,
}

impl Axis {
    /// ServoActionStatus: the power stage requested on and the drive
    /// reporting it enabled, without a fault.
    pub(super) fn servo_action(&self) -> bool {
        self.enable
            && self
                .last
                .is_some_and(|s| s.fb.drive.enabled && !s.fb.drive.fault)
    }

    /// MSO.
    pub(super) fn enable_op(&mut self, now: u64) -> Result<(), Code> {
        self.power_gate()?;
        let id = self.accept_op(OpKind::Enable);
        // An enable cancels a disable waiting for the axis to stop (the
        // stop goes on; the power stage stays on).
        if let Some((_, true)) = self.ops.await_rest {
            self.ops.await_rest = None;
        }
        if self.servo_action() {
            self.op_done(id, true);
        } else {
            self.enable = true;
            self.ops.power.enabling = Some((id, now));
        }
        Ok(())
    }

    /// MSF: always accepted. Stops what moves first (homing aborts with
    /// 12 / 1), then switches the power stage off.
    pub(super) fn disable_op(&mut self, now: u64) {
        let id = self.accept_op(OpKind::Disable);
        self.ops.power.enabling = None;
        if self.status.ip {
            self.abort_homing(now);
        }
        self.stop_motion(now, Some(id), StopCause::Disable);
        if matches!(self.state, State::Idle) {
            self.power_off();
            self.op_done(id, true);
        } else {
            self.ops.await_rest = Some((id, true));
        }
    }

    /// MAFR: refused only while homing (stop it first).
    pub(super) fn reset_op(&mut self, now: u64) -> Result<(), Code> {
        if self.status.ip {
            return Err((ERR_HOME_IN_PROCESS, 0));
        }
        let op = self.accept_op(OpKind::Reset);
        self.status.er = false;
        self.status.err = 0;
        self.status.exerr = 0;
        self.status.faulted = false;
        self.status.bad_attribute = None;
        self.ops.power.reset = Some(Reset {
            op,
            since: now,
            sent: 0,
            excused: self.last.is_some_and(|s| s.fb.drive.fault),
        });
        Ok(())
    }

    /// The power stage off now (an enable waiting for it fails). The
    /// command stays where it is: at rest, the axis is there; from the next
    /// sample on it follows the actual position.
    pub(in crate::axis) fn power_off(&mut self) {
        self.enable = false;
        self.ops.power.confirmed = false;
        if let Some((id, _)) = self.ops.power.enabling.take() {
            self.op_done(id, false);
        }
    }

    /// The drive no longer follows (a fault, a shutdown): the power stage
    /// off, and the command holds where the axis is, not where it was sent.
    pub(super) fn power_off_here(&mut self, now: u64) {
        self.power_off();
        let hold = self
            .last
            .map_or(self.profile.sample(now).0, |s| s.fb.position);
        self.profile.set(Profile::hold(now, hold));
    }

    /// A fault reset is clearing the fault the drive reported when it was
    /// accepted: that fault bit is not judged (it may take a few cycles to
    /// clear). Any other fault is.
    pub(in crate::axis) fn in_reset(&self) -> bool {
        self.ops.power.reset.is_some_and(|r| r.excused)
    }

    /// `Command::fault_reset` of this step's command.
    pub(in crate::axis) fn fault_reset_out(&mut self) -> bool {
        match &mut self.ops.power.reset {
            Some(r) => {
                r.sent = r.sent.saturating_add(1);
                true
            }
            None => false,
        }
    }

    /// Time limits of the power stage, judged every step (fresh feedback
    /// or not): the enable timeout (12 / 42) and the end of a reset window.
    pub(in crate::axis) fn power_tick(&mut self, now: u64) {
        let timeout = self.enable_timeout_ns;
        if let Some(r) = self.ops.power.reset {
            if now.saturating_sub(r.since) > timeout {
                // The drive still reports its fault: judged again from the
                // next sample on (an axis fault once more).
                self.ops.power.reset = None;
                self.op_done(r.op, false);
            }
        }
        if let Some((id, since)) = self.ops.power.enabling {
            if now.saturating_sub(since) > timeout {
                self.ops.power.enabling = None;
                self.op_done(id, false);
                self.set_fault((ERR_SERVO_MESSAGE, EX_ENABLE_TIMEOUT));
                self.power_off();
            }
        }
    }

    /// What this sample's drive state bits mean: a reset that took, an
    /// enable confirmed, a fault, a power stage dropped by the drive.
    pub(in crate::axis) fn watch_drive(&mut self, now: u64, s: &Sample) {
        let d = s.fb.drive;
        if let Some(r) = &mut self.ops.power.reset {
            // Cleared once: a fault from now on is a new one.
            r.excused &= d.fault;
            if r.sent >= RESET_MIN_STEPS && !d.fault {
                let op = r.op;
                self.ops.power.reset = None;
                self.op_done(op, true);
            }
        }
        if !self.enable {
            self.ops.power.confirmed = false;
        } else if d.enabled && !d.fault {
            self.ops.power.confirmed = true;
            if let Some((id, _)) = self.ops.power.enabling.take() {
                self.op_done(id, true);
            }
        }
        if d.fault && !self.in_reset() {
            self.drive_fault(now);
        } else if self.enable && self.ops.power.confirmed && !d.enabled && !d.fault {
            self.drive_dropped(now);
        }
    }

    /// The drive reports a fault (not the one a reset is clearing): an
    /// axis fault in every state, and the power stage requested off in
    /// every state; a reset in progress ends without PC. Homing in process
    /// aborts with 12 / 16 (a passive watch goes on: someone else moves the
    /// axis); homing's abort ramp is abandoned.
    fn drive_fault(&mut self, now: u64) {
        let code = (ERR_SERVO_MESSAGE, EX_DRIVE_FAULT);
        if let Some(r) = self.ops.power.reset.take() {
            // Not the fault it was asked to clear: it needs a reset of its
            // own (a new rising edge of the drive's fault reset).
            self.op_done(r.op, false);
        }
        if let State::Motion(_) = self.state {
            self.op_fault(now, code, StopCause::DriveFault, true);
            return;
        }
        if self.status.ip && self.homing_drives_the_axis() {
            self.fail(now, code.0, code.1, Abort::Disable);
            return;
        }
        if !self.status.faulted {
            self.set_fault(code);
        }
        self.drive_gone(now);
    }

    /// The drive switched its power stage off by itself (no fault): the
    /// request is withdrawn in every state (it never comes back on by
    /// itself); in motion that is an axis fault; homing's moving legs end
    /// with 12 / 1 (`Axis::advance`), its abort ramp is abandoned.
    fn drive_dropped(&mut self, now: u64) {
        match self.state {
            State::Motion(_) => {
                self.op_fault(
                    now,
                    (ERR_SERVO_MESSAGE, EX_DRIVE_FAULT),
                    StopCause::DriveFault,
                    true,
                );
            }
            _ if self.status.ip && self.homing_drives_the_axis() => self.fail(
                now,
                ERR_SERVO_MESSAGE,
                EX_TERMINATED_ON_REQUEST,
                Abort::Disable,
            ),
            _ => self.drive_gone(now),
        }
    }

    /// The drive is gone — reported lost (`Request::drive_lost`) for
    /// longer than the feedback-loss rule tolerates, or its I/O process
    /// restarted (whose drives start off): as a dropped power stage,
    /// in every state the enable request is withdrawn at once (a drive that
    /// comes back is never switched on by a request left standing); an
    /// operation's motion ends as an axis fault (12 / `exerr`), homing that
    /// drives the axis aborts with it, homing's abort ramp is abandoned.
    pub(in crate::axis) fn drive_gone_away(&mut self, now: u64, exerr: u16) {
        match self.state {
            State::Motion(_) => {
                self.op_fault(
                    now,
                    (ERR_SERVO_MESSAGE, exerr),
                    StopCause::FeedbackLost,
                    true,
                );
            }
            _ if self.status.ip && self.homing_drives_the_axis() => {
                self.fail(now, ERR_SERVO_MESSAGE, exerr, Abort::Disable);
            }
            State::Idle if !self.enable => {}
            _ => self.drive_gone(now),
        }
    }

    /// Homing in process commands the drive (a leg that moves, the wait
    /// for the enable), as opposed to watching an axis someone else moves.
    fn homing_drives_the_axis(&self) -> bool {
        matches!(self.state, State::Enabling { .. }) || self.state.commands_motion()
    }

    /// The drive no longer follows, outside an operation's motion or a
    /// homing that commands it: the power stage off, the command holding
    /// where the axis is; homing's abort ramp (which the drive no longer
    /// follows) is abandoned, the overrides restored.
    fn drive_gone(&mut self, now: u64) {
        if let State::Stopping { .. } = self.state {
            self.overrides = false;
            self.state = State::Idle;
        }
        self.power_off_here(now);
    }

    /// `Request::shutdown` (MASD), a level: the power stage off at once;
    /// an operation's motion ends (no fault: the operator asked for it).
    pub(in crate::axis) fn shutdown_ops(&mut self, now: u64) {
        if let State::Motion(m) = self.state {
            self.op_done(m.op, false);
            self.status.last_stop = StopCause::Shutdown;
            self.state = State::Idle;
        }
        if let Some((id, _)) = self.ops.await_rest.take() {
            self.op_done(id, false);
        }
        self.power_off_here(now);
    }

    /// Homing aborts as a stop does (12 / 1), decelerating at Home
    /// Deceleration.
    pub(super) fn abort_homing(&mut self, now: u64) {
        self.fail(
            now,
            ERR_SERVO_MESSAGE,
            EX_TERMINATED_ON_REQUEST,
            Abort::Controlled,
        );
    }
}
