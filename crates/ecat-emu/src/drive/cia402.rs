//! The slave side of the CiA 402 (IEC 61800-7-201) state machine:
//! controlword (0x6040) in, state (and statusword bits) out.
//!
//! Kept apart on purpose from the backend's master-side machine
//! (`motion_ethercat::cia402`), although both spell the same states and
//! statusword codes: each is written from the standard on its own, so that
//! one misreading of it shared by both could not pass the wire tests that
//! pit one against the other.

use super::motion::{After, Ramp};
use super::state::State;
use super::Drive;

impl Drive {
    /// Applies the controlword `cw` of a valid process-data cycle: at most
    /// one transition, as the standard's state table says.
    pub(super) fn transitions(&mut self, cw: u16) {
        let so = cw & 0x0001 != 0;
        let ev = cw & 0x0002 != 0;
        let qs = cw & 0x0004 != 0;
        let eo = cw & 0x0008 != 0;
        let reset_edge = cw & 0x0080 != 0 && self.last_cw & 0x0080 == 0;
        let disable_voltage = !ev;
        let quick_stop = ev && !qs;
        let shutdown = ev && qs && !so;
        let switch_on = ev && qs && so && !eo;
        let enable_op = ev && qs && so && eo;
        use State::*;
        match self.state {
            NotReadyToSwitchOn => self.state = SwitchOnDisabled,
            SwitchOnDisabled => {
                if shutdown {
                    self.state = ReadyToSwitchOn;
                }
            }
            ReadyToSwitchOn => {
                if switch_on {
                    self.state = SwitchedOn;
                } else if enable_op {
                    self.state = SwitchedOn;
                    self.enabling = true;
                } else if disable_voltage || quick_stop {
                    self.state = SwitchOnDisabled;
                }
            }
            SwitchedOn => {
                if enable_op {
                    self.enabling = true;
                } else if shutdown {
                    self.enabling = false;
                    self.state = ReadyToSwitchOn;
                } else if disable_voltage || quick_stop {
                    self.enabling = false;
                    self.state = SwitchOnDisabled;
                } else {
                    self.enabling = false;
                }
            }
            OperationEnabled => {
                if switch_on {
                    self.state = SwitchedOn;
                } else if shutdown {
                    self.state = ReadyToSwitchOn;
                } else if disable_voltage {
                    self.state = SwitchOnDisabled;
                } else if quick_stop && self.cfg.ignores_quick_stop {
                    // this drive does not implement quick stop: it goes on
                    // holding its set-point
                } else if quick_stop {
                    let fb = self.plant.feedback();
                    self.ramp = Some(Ramp {
                        position: fb.position,
                        velocity: self.ramp_velocity(),
                        after: After::SwitchOnDisabled,
                    });
                    self.state = QuickStopActive;
                }
            }
            QuickStopActive => {
                if disable_voltage {
                    self.ramp = None;
                    self.state = SwitchOnDisabled;
                }
            }
            FaultReactionActive => {}
            Fault => {
                if reset_edge {
                    self.state = SwitchOnDisabled;
                    self.od.put(0x603F, 0, 0);
                }
            }
        }
    }
}
