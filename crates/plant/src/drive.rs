//! The drive's power-stage state: enable delay, faults and the fault reset.
//!
//! Classic handshake: a fault disables the power stage and stays reported —
//! also while `enable` is false — until the *rising edge* of `enable` resets
//! it; the normal enable delay then runs again from that edge. Keeping the
//! fault visible while disabled lets the engine see why the axis dropped out.

use motion_homing::DriveState;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Drive {
    /// `enable` as requested in the previous step (edge detection).
    requested: bool,
    enabled: bool,
    fault: bool,
    /// Steps waited since the rising edge.
    waited: u32,
}

impl Drive {
    /// Start-of-step handling of the enable request. `command_ok` is false
    /// for a command the drive cannot execute (non-finite values): that
    /// faults the drive, whatever `enable` says.
    pub(crate) fn begin_step(&mut self, enable: bool, delay_cycles: u32, command_ok: bool) {
        let rising = enable && !self.requested;
        self.requested = enable;
        if rising {
            self.fault = false;
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
        if self.fault || self.enabled {
            return;
        }
        if self.waited >= delay_cycles {
            self.enabled = true;
        } else {
            self.waited += 1;
        }
    }

    /// Fault now: power stage off until the reset handshake.
    pub(crate) fn trip(&mut self) {
        self.fault = true;
        self.enabled = false;
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
        d.begin_step(enable, delay, true);
        d.state()
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
        d.begin_step(true, 0, false);
        assert_eq!(
            d.state(),
            DriveState {
                enabled: false,
                fault: true
            }
        );
    }
}
