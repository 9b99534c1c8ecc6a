//! Homing done by the drive (`drive_homing`; EtherCAT: CiA 402 homing mode
//! 6), and the drive's presence as its I/O process reports it.
//!
//! **The plan.** An active, non-immediate sequence of a `drive_homing` axis
//! runs `plan::DRIVE_HOMES`: one leg "the drive homes" ([`Leg::DriveHomes`]), then the
//! ordinary move to Home Position. The sequence and direction chose the
//! drive's method (or `drive_homing_method` did); the I/O process wrote it
//! with the speeds at start-up. The engine only asks and watches:
//!
//! 1. the leg sets `Command::drive_home` and holds the command on the
//!    actual position (the drive, not the command, moves the axis; the
//!    command follows, so nothing jumps when the drive hands back);
//! 2. the drive reports `active` (homing mode in force for this request),
//!    then `attained`: the home event is the drive's position 0 (the I/O
//!    process writes its home offset 0x607C = 0, so whatever a vendor makes
//!    of that object's sign, the home point reads 0). The axis position is
//!    redefined there as for any event (Home Position − Home Offset), the
//!    request drops, and the leg waits until the drive is back in cyclic
//!    position mode (`active` clear: the I/O process took its set-point from
//!    the actual position first);
//! 3. the move to Home Position (event + Home Offset) follows as in every
//!    sequence, from the actual position read after homing.
//!
//! A homing error, homing mode refused (not `active` within
//! [`DRIVE_ACK_NS`]) or left before home was attained ends the sequence
//! with ERR 12 / EXERR 46; a stop, the home timeout, lost feedback abort it
//! as any other leg (the request drops: the drive halts and hands back).
//!
//! **Plausibility.** The drive redefines its position when it attains home:
//! a jump the plausibility rule would refuse as a forged frame. During the
//! leg the rule is re-anchored on every sample (each sample is only checked
//! for being finite and in range); from the sample that ends the leg on, it
//! checks again, in the drive's new frame.
//!
//! **A lost drive.** `Request::drive_lost` is the I/O process's word that
//! the axis's drive is gone while the process itself is alive; it shows in
//! `Status::drive_lost`, names the loss (ERR 12 / EXERR 45 instead of 40),
//! and when the drive is back its first samples are judged afresh (a
//! power-cycled drive's encoder may have restarted anywhere).

use super::intake::Sample;
use super::plausible::Plausibility;
use super::state::{DriveRun, Run, State};
use super::{Abort, Axis};
use crate::codes::{ERR_SERVO_MESSAGE, EX_DRIVE_HOMING_ERROR};
use crate::plan::Leg;
use crate::profile::Profile;

/// The drive must report homing mode in force this long after it was asked
/// for, or the leg fails (12 / 46): a drive that never takes homing mode is
/// not waited for until the home timeout (which may be off).
pub const DRIVE_ACK_NS: u64 = 2_000_000_000;

impl Axis {
    /// The drive's presence as the I/O process reports it, before this
    /// step's intake: shown in the status; a drive that comes back is judged
    /// afresh.
    pub(super) fn drive_presence(&mut self, lost: bool) {
        if self.status.drive_lost && !lost {
            self.plausible = Plausibility::new(&self.cfg);
        }
        self.status.drive_lost = lost;
        if self.in_drive_homing_leg() {
            // the drive moves the axis and redefines its position: every
            // sample of the leg is judged on its own
            self.plausible = Plausibility::new(&self.cfg);
        }
    }

    /// The current leg is the drive's homing.
    pub(super) fn in_drive_homing_leg(&self) -> bool {
        matches!(&self.state, State::Homing(h) if h.current() == Some(Leg::DriveHomes))
    }

    /// `Command::drive_home`: asked for from the start of the leg until the
    /// drive attained home.
    pub(super) fn drive_home_requested(&self) -> bool {
        match &self.state {
            State::Homing(h) => matches!(h.run, Run::Drive(d) if !d.attained),
            _ => false,
        }
    }

    /// The drive moves the axis on its own (homing, or still handing back
    /// after a stop): the command follows it. Outside the drive's leg only.
    pub(super) fn follow_the_drive(&mut self, now: u64, s: &Sample) {
        if s.fb.drive_homing.active && !self.in_drive_homing_leg() {
            self.profile.set(Profile::hold(now, s.fb.position));
        }
    }

    /// Starts the drive's homing leg at `now`.
    pub(super) fn start_drive_homing(&mut self, now: u64, s: &Sample) -> Run {
        self.profile.set(Profile::hold(now, s.fb.position));
        Run::Drive(DriveRun {
            since: now,
            seen_active: false,
            attained: false,
        })
    }

    /// One fresh sample of the drive's homing leg.
    pub(super) fn drive_homing_step(&mut self, now: u64, s: &Sample, mut d: DriveRun) {
        let h = s.fb.drive_homing;
        self.profile.set(Profile::hold(now, s.fb.position));
        if h.error {
            return self.fail(
                now,
                ERR_SERVO_MESSAGE,
                EX_DRIVE_HOMING_ERROR,
                Abort::Controlled,
            );
        }
        if !d.seen_active {
            if !h.active {
                if now.saturating_sub(d.since) > DRIVE_ACK_NS {
                    self.fail(
                        now,
                        ERR_SERVO_MESSAGE,
                        EX_DRIVE_HOMING_ERROR,
                        Abort::Controlled,
                    );
                }
                return;
            }
            d.seen_active = true;
        }
        if !d.attained {
            if h.attained && h.active {
                // the home point is the drive's position 0 (0x607C = 0)
                self.event(now, 0.0);
                d.attained = true;
            } else if !h.active {
                // left homing mode without attaining home
                return self.fail(
                    now,
                    ERR_SERVO_MESSAGE,
                    EX_DRIVE_HOMING_ERROR,
                    Abort::Controlled,
                );
            }
        }
        if d.attained && !h.active {
            // back in cyclic position mode: on from the position read now
            return self.next_leg(now, s, true);
        }
        if let State::Homing(hm) = &mut self.state {
            hm.run = Run::Drive(d);
        }
    }
}
