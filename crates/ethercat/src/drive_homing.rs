//! The drive's own homing (CiA 402 homing mode 6) for one axis, cycle by
//! cycle: what the backend does with the command's `CW_DRIVE_HOME`. Pure.
//!
//! ```text
//!  Idle ─request─▶ ToHoming (0x6060 = 6) ─0x6061 shows 6─▶ Running (bit 4 ↑) ─bits 12+10─▶ Attained
//!                    │ not within the bound: Error         │ bit 13: Error                  │
//!                    │                                     │ request dropped: Halting       │ request dropped
//!                    ▼                                     ▼ (bit 8 halt, until at rest)    ▼
//!                 ToCsp (0x6060 = 8, bit 4 low, set-point = actual) ─0x6061 shows 8─▶ Idle
//! ```
//!
//! While not Idle the set-point sent is the drive's actual position: in
//! homing mode the drive ignores it, and when it is back in cyclic position
//! mode it follows from exactly where it is (no jump). The feedback says
//! `active` from homing mode confirmed until the hand-back is complete,
//! `attained` with bits 12 and 10 (home attained, at rest: the drive has
//! redefined its position), `error` with bit 13 or when the drive did not
//! take homing mode within [`MODE_BOUND_S`]. A drive that does not go back
//! to cyclic position mode within the bound is a failed hand-back: the axis
//! logic then stops and disables it with a fault.

use crate::objects::{MODE_CSP, MODE_HOMING};

/// How long the drive gets to show a mode change in 0x6061, s.
pub const MODE_BOUND_S: f64 = 1.0;

/// Statusword bits in homing mode.
pub mod sw {
    pub const TARGET_REACHED: u16 = 1 << 10;
    pub const HOMING_ATTAINED: u16 = 1 << 12;
    pub const HOMING_ERROR: u16 = 1 << 13;
}

/// Controlword bits in homing mode.
pub mod cw {
    /// 0 → 1 starts homing; 1 → 0 interrupts it.
    pub const HOMING_START: u16 = 1 << 4;
    /// Stop the axis on the homing acceleration.
    pub const HALT: u16 = 1 << 8;
}

/// Where the drive's homing is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Idle,
    ToHoming { cycles: u32 },
    Running,
    Attained,
    Error,
    Halting { cycles: u32 },
    ToCsp { cycles: u32 },
}

/// What this cycle sends and reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Out {
    /// 0x6060.
    pub mode: i8,
    /// Bits or'ed into the controlword (with the drive in Operation enabled).
    pub controlword: u16,
    /// The set-point is the actual position (not the command's).
    pub hold_actual: bool,
    pub active: bool,
    pub attained: bool,
    pub error: bool,
    /// The drive did not go back to cyclic position mode in time.
    pub failed_handback: bool,
}

/// The drive's homing of one axis.
#[derive(Clone, Copy, Debug)]
pub struct DriveHoming {
    phase: Phase,
    /// [`MODE_BOUND_S`] in cycles.
    mode_bound: u32,
    /// How long a halt may take before the hand-back goes on anyway.
    halt_bound: u32,
}

impl DriveHoming {
    pub fn new(cycle_s: f64, halt_s: f64) -> DriveHoming {
        let cycles = |s: f64| {
            if cycle_s > 0.0 {
                (s / cycle_s).ceil().clamp(1.0, f64::from(u32::MAX)) as u32
            } else {
                1000
            }
        };
        DriveHoming {
            phase: Phase::Idle,
            mode_bound: cycles(MODE_BOUND_S),
            halt_bound: cycles(halt_s),
        }
    }

    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// One cycle. `requested`: the command asks for the drive's homing and
    /// the drive may run it (enabled, no stop, no fault); `statusword`,
    /// `mode_display` (0x6061) and `at_rest` from this cycle's inputs.
    pub fn step(
        &mut self,
        requested: bool,
        statusword: u16,
        mode_display: i8,
        at_rest: bool,
    ) -> Out {
        let mut out = Out {
            mode: MODE_HOMING,
            controlword: 0,
            hold_actual: true,
            active: true,
            attained: false,
            error: false,
            failed_handback: false,
        };
        let shows = |m: i8| mode_display == m;
        self.phase = match self.phase {
            Phase::Idle if requested => Phase::ToHoming { cycles: 0 },
            Phase::Idle => Phase::Idle,
            Phase::ToHoming { .. } if !requested => Phase::ToCsp { cycles: 0 },
            Phase::ToHoming { .. } if shows(MODE_HOMING) => Phase::Running,
            Phase::ToHoming { cycles } if cycles >= self.mode_bound => Phase::Error,
            Phase::ToHoming { cycles } => Phase::ToHoming { cycles: cycles + 1 },
            Phase::Running if !requested => Phase::Halting { cycles: 0 },
            Phase::Running if statusword & sw::HOMING_ERROR != 0 => Phase::Error,
            Phase::Running
                if statusword & (sw::HOMING_ATTAINED | sw::TARGET_REACHED)
                    == sw::HOMING_ATTAINED | sw::TARGET_REACHED =>
            {
                Phase::Attained
            }
            Phase::Running => Phase::Running,
            Phase::Attained | Phase::Error if !requested => Phase::ToCsp { cycles: 0 },
            p @ (Phase::Attained | Phase::Error) => p,
            Phase::Halting { cycles } if at_rest || cycles >= self.halt_bound => {
                Phase::ToCsp { cycles: 0 }
            }
            Phase::Halting { cycles } => Phase::Halting { cycles: cycles + 1 },
            Phase::ToCsp { .. } if shows(MODE_CSP) => Phase::Idle,
            Phase::ToCsp { cycles } if cycles >= self.mode_bound => {
                out.failed_handback = true;
                Phase::Idle
            }
            Phase::ToCsp { cycles } => Phase::ToCsp { cycles: cycles + 1 },
        };
        match self.phase {
            Phase::Idle => {
                out.mode = MODE_CSP;
                out.hold_actual = false;
                out.active = false;
            }
            // not yet confirmed: bit 4 stays low (its rising edge starts)
            Phase::ToHoming { .. } => out.active = false,
            Phase::Running => out.controlword = cw::HOMING_START,
            Phase::Attained => {
                out.controlword = cw::HOMING_START;
                out.attained = true;
            }
            Phase::Error => {
                out.controlword = cw::HALT;
                out.error = true;
            }
            Phase::Halting { .. } => out.controlword = cw::HOMING_START | cw::HALT,
            Phase::ToCsp { .. } => out.mode = MODE_CSP,
        }
        out
    }

    /// The drive can no longer home (disabled, faulted, lost, a stop):
    /// back to cyclic position mode.
    pub fn abort(&mut self) {
        if !matches!(self.phase, Phase::Idle | Phase::ToCsp { .. }) {
            self.phase = Phase::ToCsp { cycles: 0 };
        }
    }

    /// Forget everything (the drive was lost: it comes back in its own mode).
    pub fn forget(&mut self) {
        self.phase = Phase::Idle;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DONE: u16 = sw::HOMING_ATTAINED | sw::TARGET_REACHED;

    #[test]
    fn mode_6_start_watch_attained_and_back_to_csp() {
        let mut h = DriveHoming::new(0.001, 0.5);
        let o = h.step(true, 0, MODE_CSP, true);
        assert_eq!(
            (o.mode, o.controlword, o.active, o.hold_actual),
            (6, 0, false, true)
        );
        // the drive shows mode 6: bit 4 rises
        let o = h.step(true, 0, MODE_HOMING, true);
        assert_eq!((o.controlword, o.active), (cw::HOMING_START, true));
        let o = h.step(true, sw::HOMING_ATTAINED, MODE_HOMING, false);
        assert!(!o.attained, "attained needs target reached too");
        let o = h.step(true, DONE, MODE_HOMING, true);
        assert!(o.attained && o.active);
        // the request drops: back to CSP, holding the actual position
        let o = h.step(false, DONE, MODE_HOMING, true);
        assert_eq!(
            (o.mode, o.controlword, o.active, o.hold_actual),
            (8, 0, true, true)
        );
        let o = h.step(false, 0, MODE_HOMING, true);
        assert_eq!(o.mode, 8);
        let o = h.step(false, 0, MODE_CSP, true);
        assert_eq!((o.mode, o.active, o.hold_actual), (8, false, false));
        assert_eq!(h.phase(), Phase::Idle);
    }

    #[test]
    fn a_refused_mode_a_homing_error_and_a_stop() {
        // homing mode never shown: error after the bound
        let mut h = DriveHoming::new(0.001, 0.5);
        let mut o = h.step(true, 0, MODE_CSP, true);
        for _ in 0..1001 {
            o = h.step(true, 0, MODE_CSP, true);
        }
        assert!(o.error && o.controlword & cw::HALT != 0, "{o:?}");
        // bit 13
        let mut h = DriveHoming::new(0.001, 0.5);
        h.step(true, 0, MODE_CSP, true);
        h.step(true, 0, MODE_HOMING, true);
        let o = h.step(true, sw::HOMING_ERROR, MODE_HOMING, false);
        assert!(o.error);
        // a stop mid-homing: halt until at rest, then back
        let mut h = DriveHoming::new(0.001, 0.5);
        h.step(true, 0, MODE_CSP, true);
        h.step(true, 0, MODE_HOMING, false);
        let o = h.step(false, 0, MODE_HOMING, false);
        assert_eq!(o.controlword, cw::HOMING_START | cw::HALT);
        let o = h.step(false, 0, MODE_HOMING, true);
        assert_eq!((o.mode, o.controlword), (8, 0));
        // a drive that never goes back: failed hand-back after the bound
        let mut failed = false;
        for _ in 0..1002 {
            failed |= h.step(false, 0, MODE_HOMING, true).failed_handback;
        }
        assert!(failed);
        assert_eq!(h.phase(), Phase::Idle);
    }
}
