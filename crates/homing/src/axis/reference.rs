//! The stored reference of an absolute axis.
//!
//! Once homed, an axis's reference is one number: the raw → axis offset
//! (axis position = raw + offset, wrapped on a cyclic axis). An absolute
//! feedback device keeps its raw position over power cycles, so the
//! supervisor stores that offset and, after a restart, restores it: the axis
//! is homed again without moving.
//!
//! The offset is applied as it is, never added to anything: restoring twice
//! gives the same axis position, and homing again computes a fresh offset
//! from the raw position (not from the axis position), so an offset is never
//! applied twice (the failure of LinuxCNC issue #3717).

use super::Axis;
use crate::config::TravelMode;
use std::fmt;

/// Why [`Axis::restore_reference`] refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RestoreRefusal {
    /// No fresh valid feedback: the raw position the offset applies to is
    /// unknown.
    NoFeedback,
    /// The Home instruction is running: it establishes the reference itself.
    HomingInProcess,
    /// The axis position the offset gives lies outside the travel limits:
    /// the stored reference does not fit this machine (the encoder was
    /// replaced, or the mechanics moved).
    OutsideTravelLimits { position: f64 },
    /// The drive reports a fault: its position is not to be trusted.
    DriveFault,
    /// The feedback device is not absolute (`absolute = false`): its raw
    /// position after a restart is unrelated to the stored one.
    NotAbsolute,
    /// The offset is not a finite number.
    InvalidOffset,
}

impl fmt::Display for RestoreRefusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoFeedback => write!(f, "no fresh valid feedback"),
            Self::HomingInProcess => write!(f, "homing in process"),
            Self::OutsideTravelLimits { position } => write!(
                f,
                "the stored reference puts the axis at {position}, outside its travel limits"
            ),
            Self::DriveFault => write!(f, "drive fault"),
            Self::NotAbsolute => write!(f, "the feedback device is not absolute"),
            Self::InvalidOffset => write!(f, "the stored offset is not a finite number"),
        }
    }
}

impl std::error::Error for RestoreRefusal {}

impl Axis {
    /// The raw → axis offset once homed (axis position = raw + offset, wrapped
    /// on a cyclic axis): what the supervisor stores for an absolute axis.
    pub fn reference_offset(&self) -> Option<f64> {
        self.status.homed.then_some(self.offset)
    }

    /// The raw → axis offset the configured `travel_limits` are in while
    /// homed: the reference homing (or a stored reference) established,
    /// without the shift redefine position added since — so the soft limits
    /// stay on the machine. What an independent check of the soft limits
    /// (the cycle monitor) reads them in.
    pub fn limits_offset(&self) -> Option<f64> {
        self.status.homed.then_some(self.offset - self.shift)
    }

    /// The part of the offset redefine position added since homing (the
    /// soft limits' shift): stored with the offset, so the limits stay on
    /// the machine across a restart.
    pub fn reference_shift(&self) -> Option<f64> {
        self.status.homed.then_some(self.shift)
    }

    /// Applies a stored raw → axis offset without motion, with the shift
    /// redefine position had added to it (`shift`, 0 when none): HomedStatus
    /// is set (not PC, not DN: no instruction ran). Only with fresh valid
    /// feedback from an absolute device, no fault, not while homing, and
    /// only when the resulting axis position lies within the travel limits
    /// (linear axes; shifted by `shift`, the same place on the machine).
    /// The command does not change: nothing moves.
    pub fn restore_reference(
        &mut self,
        now_ns: u64,
        offset: f64,
        shift: f64,
    ) -> Result<(), RestoreRefusal> {
        if self.status.ip {
            return Err(RestoreRefusal::HomingInProcess);
        }
        if !self.cfg.absolute {
            return Err(RestoreRefusal::NotAbsolute);
        }
        if !(offset.is_finite() && shift.is_finite()) {
            return Err(RestoreRefusal::InvalidOffset);
        }
        let fresh_since = now_ns.saturating_sub(self.last_sample_ns.unwrap_or(0));
        let sample = match self.last {
            Some(s)
                if self.status.feedback_gap_ns == 0
                    && fresh_since <= self.cfg.feedback_timeout_ns =>
            {
                s
            }
            _ => return Err(RestoreRefusal::NoFeedback),
        };
        if sample.fb.drive.fault {
            return Err(RestoreRefusal::DriveFault);
        }
        let position = sample.fb.position + offset;
        if let (TravelMode::Linear, Some((lo, hi))) = (self.cfg.travel, self.cfg.travel_limits) {
            if !(lo + shift..=hi + shift).contains(&position) {
                return Err(RestoreRefusal::OutsideTravelLimits { position });
            }
        }
        self.offset = offset;
        self.shift = shift;
        self.status.homed = true;
        Ok(())
    }
}
