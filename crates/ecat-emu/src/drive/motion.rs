//! The plant behind an emulated drive stepped: CSP set-points (32-bit
//! targets extended around the position), the quick-stop ramp (0x6085) and
//! the fault reaction after a lost watchdog, power off, a following error
//! (the plant's tolerance, 0x6065) turned into a fault.

use motion_homing::Command;

use super::config::TorqueObjects;
use super::state::State;
use super::{Drive, ERR_COMMUNICATION, ERR_FOLLOWING, ERR_LIMIT_WIRING};

/// What a deceleration ramp ends in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum After {
    SwitchOnDisabled,
    Fault(u16),
}

/// A running deceleration ramp (quick stop, fault reaction): where the
/// set-point is, how fast it moves, what the drive does at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Ramp {
    pub position: f64,
    pub velocity: f64,
    pub after: After,
}

impl Drive {
    /// The outputs are no longer valid (left OP; `watchdog`: the SM watchdog
    /// expired): an enabled drive ramps down on its quick-stop ramp; after a
    /// watchdog loss it then faults ([`ERR_COMMUNICATION`]).
    pub fn outputs_lost(&mut self, watchdog: bool) {
        let after = if watchdog {
            After::Fault(ERR_COMMUNICATION)
        } else {
            After::SwitchOnDisabled
        };
        match self.state {
            State::OperationEnabled | State::QuickStopActive => {
                let fb = self.plant.feedback();
                let (position, velocity) = match self.ramp {
                    Some(r) => (r.position, r.velocity),
                    None => (fb.position, self.ramp_velocity()),
                };
                self.ramp = Some(Ramp {
                    position,
                    velocity,
                    after,
                });
                self.state = if watchdog {
                    State::FaultReactionActive
                } else {
                    State::QuickStopActive
                };
            }
            State::ReadyToSwitchOn | State::SwitchedOn => {
                self.enabling = false;
                self.state = match after {
                    After::Fault(code) => {
                        self.od.put(0x603F, 0, u64::from(code));
                        State::Fault
                    }
                    After::SwitchOnDisabled => State::SwitchOnDisabled,
                };
            }
            _ => {}
        }
        self.update_inputs();
    }

    /// The torque limits in force, % rated.
    pub(super) fn limits(&self) -> (f64, f64) {
        let max = self.od.get(0x6072, 0) as f64;
        let (p, n) = if self.cfg.torque_objects == TorqueObjects::PerDirection {
            (
                (self.od.get(0x60E0, 0) as f64).min(max),
                (self.od.get(0x60E1, 0) as f64).min(max),
            )
        } else {
            (max, max)
        };
        (p / 10.0, n / 10.0)
    }

    /// The velocity a ramp starts from. The plant follows set-points
    /// ideally, so one set-point the master repeated (a late cycle) reads
    /// as standing still for a cycle; a real drive's mechanics do not stop
    /// in a cycle: the mean of the last two cycles' velocities then.
    pub(super) fn ramp_velocity(&self) -> f64 {
        let v = self.plant.feedback().velocity;
        if v.abs() < self.prev_velocity.abs() {
            (v + self.prev_velocity) / 2.0
        } else {
            v
        }
    }

    /// One plant step of `dt` s: along a running ramp, to the CSP target
    /// (`outputs_valid`), holding, or power off; a following error faults.
    pub(super) fn step_plant(&mut self, dt: f64, outputs_valid: bool) {
        let (tpos, tneg) = self.limits();
        let cpu = self.cfg.counts_per_unit;
        let window = self.od.get(0x6065, 0) as u32;
        let tolerance = if window == u32::MAX || window == 0 {
            0.0
        } else {
            f64::from(window) / cpu
        };
        let (marker_arm, switch_arm) = self.probe_arms();
        let fb = self.plant.feedback();
        let mut cmd = Command {
            enable: false,
            position: fb.position,
            velocity: 0.0,
            torque_limit_positive: tpos,
            torque_limit_negative: tneg,
            position_error_tolerance: 0.0,
            velocity_error_tolerance: 0.0,
            marker_arm,
            switch_arm,
            ..Command::default()
        };
        if let Some(mut r) = self.ramp {
            let dec = (self.od.get(0x6085, 0) as f64 / cpu).max(1e-9);
            let dv = dec * dt;
            r.velocity = if r.velocity.abs() <= dv {
                0.0
            } else {
                r.velocity - dv.copysign(r.velocity)
            };
            r.position += r.velocity * dt;
            cmd.enable = true;
            cmd.position = r.position;
            cmd.velocity = r.velocity;
            if r.velocity == 0.0 {
                self.ramp = None;
                self.state = match r.after {
                    After::SwitchOnDisabled => State::SwitchOnDisabled,
                    After::Fault(code) => {
                        self.od.put(0x603F, 0, u64::from(code));
                        State::Fault
                    }
                };
                // at rest: this last step holds, then the power stage goes off
                self.plant.step(&cmd, dt);
                self.power_off(matches!(r.after, After::Fault(_)));
                return;
            } else {
                self.ramp = Some(r);
            }
        } else if self.state == State::OperationEnabled && outputs_valid && self.mode() == 6 {
            // homing mode: the run's own profile (holding where it stands
            // before one starts); halt (bit 8) or bit 4 low bring it to rest
            let cw = self.od.get(0x6040, 0) as u16;
            let halt = cw & 0x0100 != 0 || cw & 0x0010 == 0;
            cmd.enable = true;
            self.homing_command(dt, halt, &mut cmd);
        } else if self.state == State::OperationEnabled && outputs_valid && self.mode() == 8 {
            let target = self.od.get_signed(0x607A, 0) as i32;
            // 32-bit target (the drive's counts): extended around the
            // current position
            let here = ((fb.position + self.offset) * cpu).round();
            let here32 = here as i64 as i32;
            let counts = here + f64::from(target.wrapping_sub(here32));
            cmd.enable = true;
            cmd.position = counts / cpu - self.offset;
            cmd.position_error_tolerance = tolerance;
        } else if self.state == State::OperationEnabled {
            // SAFE-OP with the drive enabled cannot happen (outputs_lost);
            // no mode in force: hold the position
            cmd.enable = true;
        } else if self.enabling {
            cmd.enable = true;
        }
        let was_enabled = self.plant.feedback().drive.enabled;
        self.prev_velocity = self.plant.feedback().velocity;
        let out = self.plant.step(&cmd, dt);
        // The plant faults on a following error, or on a limit-switch wire
        // break (which it keeps while the wire is cut, also while enabling).
        let code = if self.plant.limit_wire_break() {
            ERR_LIMIT_WIRING
        } else {
            ERR_FOLLOWING
        };
        if self.enabling {
            if out.drive.enabled {
                self.enabling = false;
                self.state = State::OperationEnabled;
            } else if out.drive.fault && code == ERR_LIMIT_WIRING {
                self.enabling = false;
                self.state = State::Fault;
                self.od.put(0x603F, 0, u64::from(code));
            }
        } else if was_enabled
            && !out.drive.enabled
            && out.drive.fault
            && matches!(self.state, State::OperationEnabled | State::QuickStopActive)
        {
            self.ramp = None;
            self.state = State::Fault;
            self.od.put(0x603F, 0, u64::from(code));
        }
    }

    /// Power stage off now (a zero-length step without enable); `fault`:
    /// the plant reports a fault too (cleared by the next enable edge).
    fn power_off(&mut self, fault: bool) {
        if fault {
            self.plant.inject_fault();
        }
        let fb = self.plant.feedback();
        let (marker_arm, switch_arm) = self.probe_arms();
        let off = Command {
            enable: false,
            position: fb.position,
            marker_arm,
            switch_arm,
            ..Command::default()
        };
        self.plant.step(&off, 0.0);
    }
}
