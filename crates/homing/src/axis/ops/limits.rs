//! Software travel limits and hardware limit switches, for the operations'
//! motion (homing keeps its own rule: 12 / 43 on a tripped switch in the
//! direction of motion, and its search limit).
//!
//! * **Software overtravel** (as in Logix: meaningful once HomedStatus is
//!   set, off when it is cleared): while the axis is homed, linear and has
//!   `travel_limits`, no jog, move or stream commands a position outside
//!   them. A move's target outside is refused, a jog is planned to come to
//!   rest on the limit in its direction, a setpoint outside is refused, and
//!   every stop of an operation's motion ends at or inside the limits: where
//!   its deceleration would carry it past one, it decelerates harder (as
//!   hard as it must) and ends on the limit. A stop keeps the limits that
//!   applied when it began: a fault that clears HomedStatus (invalid, lost
//!   or implausible feedback) plans its stop inside the limits that applied
//!   before it, and the stop keeps them to its end. A cyclic axis has none.
//! * **Hardware overtravel** (`limit_switches`, default on): motion towards
//!   a tripped limit switch is refused (ERR 9) and, when it happens, stopped
//!   at `max_deceleration` as an axis fault (ER 12 / 43); motion away is
//!   allowed (after `Reset`). With `limit_switches = false` the inputs are
//!   ignored (and shown false).

use super::Code;
use crate::axis::intake::Sample;
use crate::axis::Axis;
use crate::codes::*;
use crate::config::TravelMode;
use crate::operation::StopCause;
use crate::profile::Profile;

impl Axis {
    /// The travel limits as raw positions, while they are enforced: homed,
    /// linear, configured.
    pub(in crate::axis) fn soft_limits_raw(&self) -> Option<(f64, f64)> {
        match (self.status.homed, self.cfg.travel, self.cfg.travel_limits) {
            (true, TravelMode::Linear, Some((lo, hi))) => {
                Some((lo - self.offset, hi - self.offset))
            }
            _ => None,
        }
    }

    /// Half a count, units: positions closer than this are the same to the
    /// drive (a jog that ended on a limit is "at" it).
    pub(super) fn half_count(&self) -> f64 {
        let cpu = self.cfg.counts_per_unit;
        if cpu.is_finite() && cpu > 0.0 {
            0.5 / cpu
        } else {
            0.0
        }
    }

    /// The travel limits a stop beginning now stays inside: those in force,
    /// or — when the reference was lost in this very step (invalid, lost or
    /// implausible feedback clears HomedStatus before the stop is planned)
    /// — those that were in force after the previous step.
    pub(super) fn stop_limits(&self) -> Option<(f64, f64)> {
        self.soft_limits_raw().or(self.ops.limits_before)
    }

    /// A stop from `(p, v)` at time `t` at `decel`, ending at or inside
    /// `limits` (raw): past the end a stop at `decel` would reach, it ends
    /// exactly on the limit (decelerating harder); an axis already at or
    /// beyond the limit it moves towards stops at once.
    pub(super) fn stop_within(
        t: u64,
        p: f64,
        v: f64,
        decel: f64,
        limits: Option<(f64, f64)>,
    ) -> Profile {
        let plain = Profile::stop(t, p, v, decel);
        let Some((lo, hi)) = limits else {
            return plain;
        };
        let limit = if v > 0.0 {
            hi
        } else if v < 0.0 {
            lo
        } else {
            return plain;
        };
        if (plain.end_position() - limit) * v <= 0.0 {
            plain
        } else if (limit - p) * v > 0.0 {
            Profile::stop_at(t, p, v, limit)
        } else {
            Profile::hold(t, p)
        }
    }

    /// A motion that starts from `(p, v)` and must first stop at `decel`
    /// (a reversal, a new target behind) stays inside the travel limits it
    /// is inside of; else refused 13 / 4.
    pub(super) fn stop_fits(&self, p: f64, v: f64, decel: f64) -> Result<(), Code> {
        let Some((lo, hi)) = self.soft_limits_raw() else {
            return Ok(());
        };
        if v == 0.0 {
            return Ok(());
        }
        let end = p + v * v.abs() / (2.0 * decel);
        let out = (v > 0.0 && p <= hi && end > hi) || (v < 0.0 && p >= lo && end < lo);
        if out {
            Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET))
        } else {
            Ok(())
        }
    }

    /// The limit switch inputs of a sample as the operations read them:
    /// (negative, positive) tripped; both false without `limit_switches`.
    pub(super) fn switches(&self, s: &Sample) -> (bool, bool) {
        if self.cfg.limit_switches {
            (s.fb.overtravel_negative, s.fb.overtravel_positive)
        } else {
            (false, false)
        }
    }

    /// Motion in direction `dir` (sign) may start: not towards a tripped
    /// limit switch (ERR 9).
    pub(super) fn switch_allows(&self, dir: f64) -> Result<(), Code> {
        let (neg, pos) = self.last.map_or((false, false), |s| self.switches(&s));
        if (dir > 0.0 && pos) || (dir < 0.0 && neg) {
            Err((ERR_OVERTRAVEL_CONDITION, 0))
        } else {
            Ok(())
        }
    }

    /// The operation's motion goes towards a tripped limit switch: stopped
    /// at `max_deceleration`, ER 12 / 43 (an axis fault). A fault's stop
    /// already under way goes on.
    pub(super) fn limit_switch_hit(&mut self, now: u64, s: &Sample) -> bool {
        let (neg, pos) = self.switches(s);
        if !(neg || pos) || self.status.faulted {
            return false;
        }
        let (_, _, v) = self.motion_state(now);
        if (v > 0.0 && pos) || (v < 0.0 && neg) {
            return self.op_fault(
                now,
                (ERR_SERVO_MESSAGE, EX_OVERTRAVEL),
                StopCause::LimitSwitch,
                false,
            );
        }
        false
    }
}
