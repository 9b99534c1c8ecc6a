//! The application behind each emulated SubDevice: a CiA 402 servo drive
//! in cyclic synchronous position mode over [`motion_plant::Plant`].
//!
//! * [`config`] — what a drive is ([`DriveConfig`]: identity, objects it
//!   has, DC, units).
//! * [`dictionary`] — its object dictionary: the CiA 402 objects the
//!   backend needs, PDO mapping and assignment objects, sync-manager
//!   parameter objects.
//! * [`pdo`] — the process image packed / unpacked from the mapping and
//!   assignment objects as they are (really evaluated).
//! * [`sdo`] — the rules of an SDO download (mapping only in PRE-OP,
//!   mappable objects, CSP only, sync types).
//! * [`cia402`] — the slave side of the CiA 402 state machine (controlword
//!   in, statusword out), fault reset on the rising edge of bit 7.
//! * [`motion`] — the plant stepped: CSP set-points, the quick-stop ramp
//!   (0x605A = 2: ramp on 0x6085, then Switch on disabled), the fault
//!   reaction after a lost watchdog, power off.
//! * [`probes`] — touch probes: probe 1 on the encoder index (zero impulse),
//!   probe 2 on the home-switch input, first-event mode, rising or falling
//!   edge; every 0 → 1 of an enable bit re-arms the plant's latch with a
//!   fresh internal id, so the latched positions are the plant's exact ones.
//! * [`inputs`] — the input objects (statusword, positions, digital inputs)
//!   from the plant.
//!
//! One [`Drive::cycle`] per process-data exchange: outputs applied, plant
//! stepped by the sync-manager cycle time (0x1C32:02), inputs updated.
//! Without process data (SM watchdog expired, not OP) only a running
//! quick-stop / fault-reaction ramp advances, by wall time
//! ([`Drive::tick`]).
//!
//! Units: the plant works in position units, the objects in counts
//! (`counts_per_unit` of the config): positions round to nearest, velocity
//! in counts/s, torque in per mille of rated.

pub mod cia402;
pub mod config;
pub mod dictionary;
pub mod homing;
pub mod inputs;
pub mod motion;
pub mod pdo;
pub mod probes;
pub mod sdo;
pub mod state;

use motion_plant::Plant;

use crate::od::Od;

pub use config::{DriveConfig, ModeDisplay, PdoProfile, TorqueObjects, SUPPORTED_METHODS};
use motion::Ramp;
use probes::ProbeUnit;
pub use state::State;

/// Error code (0x603F) of a following error (the plant's tolerance tripped).
pub const ERR_FOLLOWING: u16 = 0x8611;
/// Error code of the communication loss (SM watchdog expired in OP).
pub const ERR_COMMUNICATION: u16 = 0x8130;
/// Error code of a limit-switch wire break (both NC limit inputs open): a
/// manufacturer-specific code (0xFF00..), as real drives report wiring
/// faults; not 0x73xx, which the supervisor reads as an encoder fault.
pub const ERR_LIMIT_WIRING: u16 = 0xFF01;

/// Values the tests read back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveView {
    pub state: State,
    pub statusword: u16,
    pub controlword: u16,
    pub error_code: u16,
    /// Plant position, units (exact).
    pub position: f64,
    pub velocity: f64,
    pub torque: f64,
    pub enabled: bool,
    pub touch_probe_function: u16,
    pub touch_probe_status: u16,
    /// Effective torque limits, % rated.
    pub torque_limit_positive: f64,
    pub torque_limit_negative: f64,
    pub following_error_window: u32,
    pub mode: i8,
    pub cycles: u64,
    pub ticks: u64,
}

/// The drive.
#[derive(Clone, Debug)]
pub struct Drive {
    pub cfg: DriveConfig,
    pub od: Od,
    plant: Plant,
    state: State,
    /// Transition 4 asked for, waiting for the plant's power stage.
    enabling: bool,
    last_cw: u16,
    ramp: Option<Ramp>,
    /// The plant's velocity one cycle before the last (see
    /// [`Drive::ramp_velocity`]).
    prev_velocity: f64,
    pending_fault: Option<u16>,
    probes: [ProbeUnit; 2],
    next_probe_id: u8,
    cycles: u64,
    ticks: u64,
    /// Homing mode's run, if one was started.
    homing: Option<homing::HomingRun>,
    /// Added to the plant's position to make the drive's (units): homing
    /// redefines it; a power cycle restarts the encoder at its start value.
    offset: f64,
    /// The ESC is in SAFE-OP or OP (a late mode display shows only then).
    operational: bool,
}

impl Drive {
    pub fn new(cfg: DriveConfig) -> Drive {
        let od = dictionary::build(&cfg);
        let plant = Plant::new(cfg.plant);
        let mut d = Drive {
            cfg,
            od,
            plant,
            state: State::NotReadyToSwitchOn,
            enabling: false,
            last_cw: 0,
            ramp: None,
            prev_velocity: 0.0,
            pending_fault: None,
            probes: [ProbeUnit::default(); 2],
            next_probe_id: 0,
            cycles: 0,
            ticks: 0,
            homing: None,
            offset: 0.0,
            operational: false,
        };
        d.update_inputs();
        d
    }

    /// The plant step (0x1C32:02), seconds.
    pub fn dt(&self) -> f64 {
        let ns = self.od.get(0x1C32, 2);
        if ns == 0 {
            f64::from(self.cfg.cycle_ns) * 1e-9
        } else {
            ns as f64 * 1e-9
        }
    }

    /// Sync type asked for in 0x1C32:01 (0 free run, 1 SM, 2 DC SYNC0).
    pub fn sync_type(&self) -> u16 {
        self.od.get(0x1C32, 1) as u16
    }

    /// Faults the drive at the next cycle (power stage off at once) with
    /// `code` in 0x603F.
    pub fn inject_fault(&mut self, code: u16) {
        self.pending_fault = Some(code);
    }

    /// One process-data cycle: `outputs_valid` (OP) applies the controlword
    /// and the set-points; then the plant steps one cycle and the inputs are
    /// updated.
    pub fn cycle(&mut self, outputs_valid: bool) {
        self.cycles += 1;
        let dt = self.dt();
        let cw = self.od.get(0x6040, 0) as u16;
        if let Some(code) = self.pending_fault.take() {
            self.plant.inject_fault();
            self.ramp = None;
            self.enabling = false;
            self.state = State::Fault;
            self.od.put(0x603F, 0, u64::from(code));
        } else if outputs_valid {
            self.transitions(cw);
            self.show_mode();
            self.homing_bits(cw);
        }
        self.last_cw = cw;
        self.step_plant(dt, outputs_valid);
        self.update_inputs();
    }

    /// Wall-time step without process data: advances a running ramp only.
    pub fn tick(&mut self) {
        if self.state == State::NotReadyToSwitchOn {
            self.state = State::SwitchOnDisabled;
        }
        if self.ramp.is_some() {
            self.ticks += 1;
            let dt = self.dt();
            self.step_plant(dt, false);
            self.update_inputs();
        }
    }

    /// A ramp is running (the chain calls [`tick`](Self::tick) while there
    /// is no process data).
    pub fn ramping(&self) -> bool {
        self.ramp.is_some()
    }

    /// Read-back for tests.
    pub fn view(&self) -> DriveView {
        let fb = self.plant.feedback();
        let (p, n) = self.limits();
        DriveView {
            state: self.state,
            statusword: self.od.get(0x6041, 0) as u16,
            controlword: self.od.get(0x6040, 0) as u16,
            error_code: self.od.get(0x603F, 0) as u16,
            position: fb.position,
            velocity: fb.velocity,
            torque: fb.torque,
            enabled: fb.drive.enabled,
            touch_probe_function: self.od.get(0x60B8, 0) as u16,
            touch_probe_status: self.od.get(0x60B9, 0) as u16,
            torque_limit_positive: p,
            torque_limit_negative: n,
            following_error_window: self.od.get(0x6065, 0) as u32,
            mode: self.od.get(0x6061, 0) as u8 as i8,
            cycles: self.cycles,
            ticks: self.ticks,
        }
    }

    /// The plant (tests: marker / switch geometry).
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The drive's position (what 0x6064 reports), units: the plant's plus
    /// the offset homing or a power cycle made.
    pub fn drive_position(&self) -> f64 {
        self.plant.feedback().position + self.offset
    }

    /// The ESC's AL state is (not) SAFE-OP or OP.
    pub fn set_operational(&mut self, operational: bool) {
        self.operational = operational;
        self.show_mode();
    }

    /// 0x6061 shows 0x6060 if the drive supports that mode (8; 6 with
    /// homing methods; 0), at once or, with `late_mode_display`, only in
    /// SAFE-OP / OP.
    fn show_mode(&mut self) {
        match self.cfg.mode_display {
            ModeDisplay::Never => return,
            ModeDisplay::Late if !self.operational => return,
            _ => {}
        }
        let want = self.od.get(0x6060, 0) as u8 as i8;
        let ok = match want {
            0 | 8 => true,
            6 => !self.cfg.homing_methods.is_empty(),
            _ => false,
        };
        if ok && self.od.get(0x6061, 0) as u8 as i8 != want {
            if want != 6 {
                self.homing = None;
            }
            self.od.put(0x6061, 0, u64::from(want as u8));
        }
    }

    /// The mode in force (0x6061).
    pub fn mode(&self) -> i8 {
        self.od.get(0x6061, 0) as u8 as i8
    }

    /// Homing mode: controlword bit 4's rising edge starts a run (in
    /// Operation enabled).
    fn homing_bits(&mut self, cw: u16) {
        if self.mode() == 6 && self.state == State::OperationEnabled {
            if cw & 0x0010 != 0 && self.last_cw & 0x0010 == 0 {
                self.start_homing();
            }
        } else {
            self.homing = None;
        }
    }

    /// Homing mode's statusword bits: 12 attained, 10 target reached (at
    /// rest after a run), 13 error.
    fn homing_statusword(&self) -> u16 {
        let Some(r) = &self.homing else { return 0 };
        let mut sw = 0;
        if r.attained {
            sw |= 0x1000;
        }
        if r.done {
            sw |= 0x0400;
        }
        if r.error {
            sw |= 0x2000;
        }
        sw
    }
}

#[cfg(test)]
mod tests;

impl Drive {
    /// This drive after a power cycle: a fresh dictionary and state machine
    /// over the same plant (at rest where it is, power stage off); the
    /// encoder reads its start value again.
    pub fn power_cycled(&self) -> Drive {
        let mut d = Drive::new(self.cfg.clone());
        d.plant = self.plant.clone();
        let here = d.plant.feedback().position;
        // power stage off: a zero-length step without enable
        d.plant.step(
            &motion_homing::Command {
                position: here,
                ..motion_homing::Command::default()
            },
            0.0,
        );
        d.offset = self.cfg.plant.start - here;
        d.update_inputs();
        d
    }
}
