//! The drive's power-stage state: enable delay, faults and the fault reset.
//!
//! A fault disables the power stage and stays reported — also while
//! `enable` is false — until it is reset, in either of two ways:
//!
//! * the rising edge of `Command::fault_reset` (MAFR; CiA 402 control word
//!   bit 7): the fault clears, the power stage stays off until a new
//!   rising edge of `enable` (an enable held high through the fault does
//!   not switch it on again by itself);
//! * the classic handshake: a rising edge of `enable` resets it and the
//!   normal enable delay runs from that edge. The engine no longer relies
//!   on it (a faulted axis refuses to enable until it is reset), but the
//!   EtherCAT emulator's CiA 402 machine drives the plant's power stage
//!   that way, so it stays.
//!
//! Keeping the fault visible while disabled lets the engine see why the
//! axis dropped out. A fault whose cause persists (a condition the plant
//! checks every step) trips again in the step it is reset.

use motion_homing::DriveState;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Drive {
    /// `enable` as requested in the previous step (edge detection).
    requested: bool,
    /// `fault_reset` as requested in the previous step (edge detection).
    reset_requested: bool,
    enabled: bool,
    fault: bool,
    /// Tripped since the last rising edge of `enable`: the power stage
    /// comes on only after a new one.
    locked: bool,
    /// Steps waited since the rising edge.
    waited: u32,
}

impl Drive {
    /// Start-of-step handling of the enable request. `command_ok` is false
    /// for a command the drive cannot execute (non-finite values): that
    /// faults the drive, whatever `enable` says.
    pub(crate) fn begin_step(
        &mut self,
        enable: bool,
        fault_reset: bool,
        delay_cycles: u32,
        command_ok: bool,
    ) {
        let rising = enable && !self.requested;
        self.requested = enable;
        if fault_reset && !self.reset_requested {
            self.reset_fault();
        }
        self.reset_requested = fault_reset;
        if rising {
            self.fault = false;
            self.locked = false;
            self.waited = 0;
        }
        if !command_ok {
            self.trip();
        }
        if !enable {
            self.enabled = false;
            self.waited = 0;
            return;
        }
        if self.fault || self.locked || self.enabled {
            return;
        }
        if self.waited >= delay_cycles {
            self.enabled = true;
        } else {
            self.waited += 1;
        }
    }

    /// Fault now: power stage off until a reset.
    pub(crate) fn trip(&mut self) {
        self.fault = true;
        self.locked = true;
        self.enabled = false;
    }

    /// Fault reset (the rising edge of `fault_reset`): the fault clears;
    /// the power stage stays off until the next rising edge of `enable`.
    pub(crate) fn reset_fault(&mut self) {
        self.fault = false;
    }

    /// Power stage on and following the command.
    pub(crate) fn enabled(&self) -> bool {
        self.enabled
    }

    pub(crate) fn state(&self) -> DriveState {
        DriveState {
            enabled: self.enabled,
            fault: self.fault,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(d: &mut Drive, enable: bool, delay: u32) -> DriveState {
        d.begin_step(enable, false, delay, true);
        d.state()
    }

    #[test]
    fn a_fault_reset_edge_clears_the_fault_and_enables_nothing() {
        let off = DriveState {
            enabled: false,
            fault: false,
        };
        for enable in [false, true] {
            let mut d = Drive::default();
            run(&mut d, true, 0);
            d.trip();
            d.begin_step(enable, true, 0, true);
            assert_eq!(d.state(), off, "enable held {enable}");
            // A level, not an edge: nothing more; the enable held high
            // through the fault does not switch it on again.
            d.begin_step(enable, true, 0, true);
            d.begin_step(enable, false, 0, true);
            assert_eq!(d.state(), off);
            // A new rising edge of enable does.
            d.begin_step(false, false, 0, true);
            d.begin_step(true, false, 0, true);
            assert!(d.state().enabled);
        }
        // A fault that comes while the reset is held is not reset by it.
        let mut d = Drive::default();
        d.begin_step(false, true, 0, true);
        d.trip();
        d.begin_step(false, true, 0, true);
        assert!(d.state().fault);
    }

    #[test]
    fn enable_delay_counts_steps_from_the_rising_edge() {
        for delay in 0..4 {
            let mut d = Drive::default();
            for step in 0..delay {
                assert!(
                    !run(&mut d, true, delay).enabled,
                    "delay {delay} step {step}"
                );
            }
            assert!(run(&mut d, true, delay).enabled, "delay {delay}");
            assert!(!run(&mut d, false, delay).enabled, "off at once");
        }
    }

    #[test]
    fn fault_needs_the_reset_handshake() {
        let mut d = Drive::default();
        run(&mut d, true, 0);
        d.trip();
        assert_eq!(
            run(&mut d, true, 0),
            DriveState {
                enabled: false,
                fault: true
            }
        );
        assert!(run(&mut d, false, 0).fault, "still reported while disabled");
        assert_eq!(
            run(&mut d, true, 0),
            DriveState {
                enabled: true,
                fault: false
            }
        );
    }

    #[test]
    fn bad_command_faults_even_on_the_rising_edge() {
        let mut d = Drive::default();
        d.begin_step(true, false, 0, false);
        assert_eq!(
            d.state(),
            DriveState {
                enabled: false,
                fault: true
            }
        );
    }
}
