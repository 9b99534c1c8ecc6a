//! The application behind each emulated SubDevice: a CiA 402 servo drive
//! in cyclic synchronous position mode over [`motion_plant::Plant`].
//!
//! * Object dictionary with the CiA 402 objects the backend needs, PDO
//!   mapping and assignment objects that are really evaluated (the process
//!   image is packed / unpacked from them), sync-manager parameter objects.
//! * The slave side of the CiA 402 state machine (controlword in,
//!   statusword out), fault reaction, quick stop (0x605A = 2: ramp on
//!   0x6085, then Switch on disabled), fault reset on the rising edge of bit 7.
//! * Touch probes: probe 1 on the encoder index (zero impulse), probe 2 on
//!   the home-switch input, first-event mode, rising or falling edge; every
//!   0 → 1 of an enable bit re-arms the plant's latch with a fresh internal
//!   id, so the latched positions are the plant's exact ones.
//! * One [`Drive::cycle`] per process-data exchange: outputs applied, plant
//!   stepped by the sync-manager cycle time (0x1C32:02), inputs updated.
//!   Without process data (SM watchdog expired, not OP) only a running
//!   quick-stop / fault-reaction ramp advances, by wall time
//!   ([`Drive::tick`]).
//!
//! Units: the plant works in position units, the objects in counts
//! (`counts_per_unit` of the config): positions round to nearest, velocity
//! in counts/s, torque in per mille of rated.

use motion_homing::{Command, Edge, LatchArm};
use motion_plant::{Plant, PlantConfig};

use crate::od::{abort, Access, Mappable, Od};

/// Error code (0x603F) of a following error (the plant's tolerance tripped).
pub const ERR_FOLLOWING: u16 = 0x8611;
/// Error code of the communication loss (SM watchdog expired in OP).
pub const ERR_COMMUNICATION: u16 = 0x8130;

/// Which torque-limit objects the drive has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TorqueObjects {
    /// 0x60E0 / 0x60E1 and 0x6072.
    PerDirection,
    /// 0x6072 only.
    MaxTorqueOnly,
}

/// One emulated drive.
#[derive(Clone, Debug)]
pub struct DriveConfig {
    /// SubDevice name (SII order/name string, 0x1008).
    pub name: String,
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision: u32,
    pub serial: u32,
    /// Counts per plant position unit.
    pub counts_per_unit: f64,
    pub plant: PlantConfig,
    /// Has the touch-probe objects 0x60B8..0x60BD.
    pub touch_probe: bool,
    /// Supports distributed clocks (SYNC0).
    pub dc: bool,
    pub torque_objects: TorqueObjects,
    /// Quick-stop deceleration, units/s² (0x6085 in counts/s²).
    pub quick_stop_deceleration: f64,
    /// Default 0x1C32:02 (the plant's step), ns.
    pub cycle_ns: u32,
    /// 0x60FD bit that shows "an index pulse passed last cycle"
    /// (manufacturer-specific range 16..=31); `None`: not reported.
    pub index_pulse_bit: Option<u8>,
    /// 0x100A; a long one needs a segmented upload.
    pub software_version: String,
}

impl DriveConfig {
    /// A drive named `name` with defaults: 1000 counts/unit, touch probes,
    /// DC, per-direction torque limits, 1 ms cycle, no enable delay.
    pub fn new(name: &str) -> DriveConfig {
        DriveConfig {
            name: name.to_string(),
            vendor_id: 0x0000_0EC7,
            product_code: 0x0402_0001,
            revision: 1,
            serial: 1,
            counts_per_unit: 1000.0,
            plant: PlantConfig {
                enable_delay_cycles: 0,
                ..PlantConfig::default()
            },
            touch_probe: true,
            dc: true,
            torque_objects: TorqueObjects::PerDirection,
            quick_stop_deceleration: 1000.0,
            cycle_ns: 1_000_000,
            index_pulse_bit: Some(16),
            software_version: "ecat-emu".to_string(),
        }
    }
}

/// CiA 402 states (slave side).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    NotReadyToSwitchOn,
    SwitchOnDisabled,
    ReadyToSwitchOn,
    SwitchedOn,
    OperationEnabled,
    QuickStopActive,
    FaultReactionActive,
    Fault,
}

impl State {
    fn bits(self) -> u16 {
        match self {
            State::NotReadyToSwitchOn => 0x0000,
            State::SwitchOnDisabled => 0x0040,
            State::ReadyToSwitchOn => 0x0021,
            State::SwitchedOn => 0x0033,
            State::OperationEnabled => 0x0037,
            State::QuickStopActive => 0x0017,
            State::FaultReactionActive => 0x001F,
            State::Fault => 0x0008,
        }
    }
}

/// What a deceleration ramp ends in.
#[derive(Clone, Copy, Debug, PartialEq)]
enum After {
    SwitchOnDisabled,
    Fault(u16),
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Ramp {
    position: f64,
    velocity: f64,
    after: After,
}

#[derive(Clone, Copy, Debug, Default)]
struct ProbeUnit {
    enabled: bool,
    id: u8,
}

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
    pending_fault: Option<u16>,
    probes: [ProbeUnit; 2],
    next_probe_id: u8,
    cycles: u64,
    ticks: u64,
}

/// PDO mapping objects' capacity (sub-indices).
const MAP_SUBS: usize = 12;
/// Largest PDO the drive accepts, bytes.
const MAX_PDO_BYTES: usize = 64;

impl Drive {
    pub fn new(cfg: DriveConfig) -> Drive {
        let mut od = Od::new();
        use Access::*;
        use Mappable::*;
        od.var(0x1000, "device type", 32, Ro, No, 0x0002_0192);
        od.var(0x1001, "error register", 8, Ro, No, 0);
        od.string(0x1008, "manufacturer device name", &cfg.name);
        od.string(0x1009, "manufacturer hardware version", "1.0");
        od.string(
            0x100A,
            "manufacturer software version",
            &cfg.software_version,
        );
        od.record(
            0x1018,
            "identity",
            Ro,
            &[
                (32, Ro, No, u64::from(cfg.vendor_id)),
                (32, Ro, No, u64::from(cfg.product_code)),
                (32, Ro, No, u64::from(cfg.revision)),
                (32, Ro, No, u64::from(cfg.serial)),
            ],
        );
        // default mapping: controlword + target / statusword + position
        let mut rx = vec![(32, Rw, No, 0u64); MAP_SUBS];
        rx[0].3 = 0x6040_0010;
        rx[1].3 = 0x607A_0020;
        od.record(0x1600, "RxPDO mapping", Rw, &rx);
        od.put(0x1600, 0, 2);
        let mut tx = vec![(32, Rw, No, 0u64); MAP_SUBS];
        tx[0].3 = 0x6041_0010;
        tx[1].3 = 0x6064_0020;
        od.record(0x1A00, "TxPDO mapping", Rw, &tx);
        od.put(0x1A00, 0, 2);
        od.record(
            0x1C00,
            "sync manager communication type",
            Ro,
            &[
                (8, Ro, No, 1),
                (8, Ro, No, 2),
                (8, Ro, No, 3),
                (8, Ro, No, 4),
            ],
        );
        od.record(0x1C12, "RxPDO assign", Rw, &[(16, Rw, No, 0x1600)]);
        od.record(0x1C13, "TxPDO assign", Rw, &[(16, Rw, No, 0x1A00)]);
        let modes = if cfg.dc { 0x0007 } else { 0x0003 };
        for index in [0x1C32, 0x1C33] {
            od.record(
                index,
                "sync manager parameter",
                Ro,
                &[
                    (16, Rw, No, 0),                       // 1 sync type: free run
                    (32, Rw, No, u64::from(cfg.cycle_ns)), // 2 cycle time
                    (32, Ro, No, 0),                       // 3 shift time
                    (16, Ro, No, modes),                   // 4 supported sync types
                    (32, Ro, No, 125_000),                 // 5 minimum cycle time
                    (32, Ro, No, 10_000),                  // 6 calc and copy time
                ],
            );
        }
        od.var(0x603F, "error code", 16, Ro, Tx, 0);
        od.var(0x6040, "controlword", 16, Rw, Rx, 0);
        od.var(0x6041, "statusword", 16, Ro, Tx, 0);
        od.var(0x605A, "quick stop option code", 16, Rw, No, 2);
        od.var(0x6060, "modes of operation", 8, Rw, Rx, 0);
        od.var(0x6061, "modes of operation display", 8, Ro, Tx, 0);
        od.var(0x6064, "position actual value", 32, Ro, Tx, 0);
        od.var(
            0x6065,
            "following error window",
            32,
            Rw,
            No,
            u64::from(u32::MAX),
        );
        od.var(0x606C, "velocity actual value", 32, Ro, Tx, 0);
        od.var(0x6072, "max torque", 16, Rw, Rx, 0xFFFF);
        od.var(0x6077, "torque actual value", 16, Ro, Tx, 0);
        od.var(0x607A, "target position", 32, Rw, Rx, 0);
        let qs =
            (cfg.quick_stop_deceleration * cfg.counts_per_unit).clamp(1.0, f64::from(u32::MAX));
        od.var(0x6085, "quick stop deceleration", 32, Rw, No, qs as u64);
        if cfg.touch_probe {
            od.var(0x60B8, "touch probe function", 16, Rw, Rx, 0);
            od.var(0x60B9, "touch probe status", 16, Ro, Tx, 0);
            od.var(0x60BA, "touch probe 1 positive edge", 32, Ro, Tx, 0);
            od.var(0x60BB, "touch probe 1 negative edge", 32, Ro, Tx, 0);
            od.var(0x60BC, "touch probe 2 positive edge", 32, Ro, Tx, 0);
            od.var(0x60BD, "touch probe 2 negative edge", 32, Ro, Tx, 0);
        }
        if cfg.torque_objects == TorqueObjects::PerDirection {
            od.var(0x60E0, "positive torque limit value", 16, Rw, Rx, 3000);
            od.var(0x60E1, "negative torque limit value", 16, Rw, Rx, 3000);
        }
        od.var(0x60FD, "digital inputs", 32, Ro, Tx, 0);
        od.var(0x6502, "supported drive modes", 32, Ro, No, 0x80);

        let plant = Plant::new(cfg.plant);
        let mut d = Drive {
            cfg,
            od,
            plant,
            state: State::NotReadyToSwitchOn,
            enabling: false,
            last_cw: 0,
            ramp: None,
            pending_fault: None,
            probes: [ProbeUnit::default(); 2],
            next_probe_id: 0,
            cycles: 0,
            ticks: 0,
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

    // ----------------------------------------------------------------- PDO

    fn mapping(&self, assign: u16) -> Vec<(u16, u8, u16)> {
        let mut out = Vec::new();
        let n = self.od.get(assign, 0) as u8;
        for i in 1..=n {
            let pdo = self.od.get(assign, i) as u16;
            let m = self.od.get(pdo, 0) as u8;
            for j in 1..=m {
                let v = self.od.get(pdo, j) as u32;
                out.push(((v >> 16) as u16, (v >> 8) as u8, (v & 0xFF) as u16));
            }
        }
        out
    }

    /// Output (RxPDO) bytes of the current mapping.
    pub fn rx_bytes(&self) -> usize {
        self.mapping(0x1C12)
            .iter()
            .map(|e| usize::from(e.2) / 8)
            .sum()
    }

    /// Input (TxPDO) bytes of the current mapping.
    pub fn tx_bytes(&self) -> usize {
        self.mapping(0x1C13)
            .iter()
            .map(|e| usize::from(e.2) / 8)
            .sum()
    }

    /// Stores the received outputs into the mapped objects.
    pub fn apply_outputs(&mut self, buf: &[u8]) {
        let mut at = 0;
        for (index, sub, bits) in self.mapping(0x1C12) {
            let n = usize::from(bits) / 8;
            if let Some(b) = buf.get(at..at + n) {
                self.od.set_bytes(index, sub, b);
            }
            at += n;
        }
    }

    /// Packs the mapped inputs.
    pub fn fill_inputs(&self, buf: &mut [u8]) {
        let mut at = 0;
        for (index, sub, bits) in self.mapping(0x1C13) {
            let n = usize::from(bits) / 8;
            let v = self.od.get(index, sub).to_le_bytes();
            if let Some(dst) = buf.get_mut(at..at + n) {
                dst.copy_from_slice(&v[..n]);
            }
            at += n;
        }
    }

    // ----------------------------------------------------------------- SDO

    /// An SDO download, with the rules of the mapping, assignment, mode and
    /// sync objects. `preop`: the ESC is in PRE-OP (mapping changes allowed).
    pub fn sdo_download(
        &mut self,
        index: u16,
        sub: u8,
        data: &[u8],
        preop: bool,
    ) -> Result<(), u32> {
        self.od.check_download(index, sub, data)?;
        let mut v = [0u8; 8];
        let n = data.len().min(8);
        v[..n].copy_from_slice(&data[..n]);
        let value = u64::from_le_bytes(v);
        match index {
            0x1600..=0x17FF | 0x1A00..=0x1BFF => {
                if !preop {
                    return Err(abort::STATE);
                }
                let want = if index < 0x1A00 {
                    Mappable::Rx
                } else {
                    Mappable::Tx
                };
                if sub == 0 {
                    let count = value as usize;
                    if count > MAP_SUBS {
                        return Err(abort::VALUE_RANGE);
                    }
                    let mut bytes = 0;
                    for j in 1..=count as u8 {
                        let m = self.od.get(index, j) as u32;
                        self.check_mappable(m, want)?;
                        bytes += (m & 0xFF) as usize / 8;
                    }
                    if bytes > MAX_PDO_BYTES {
                        return Err(abort::PDO_TOO_LONG);
                    }
                } else {
                    if self.od.get(index, 0) != 0 {
                        return Err(abort::SUBINDEX0_MUST_BE_ZERO);
                    }
                    self.check_mappable(value as u32, want)?;
                }
            }
            0x1C12 | 0x1C13 => {
                if !preop {
                    return Err(abort::STATE);
                }
                let range = if index == 0x1C12 {
                    0x1600..=0x17FF
                } else {
                    0x1A00..=0x1BFF
                };
                if sub == 0 {
                    for j in 1..=value as u8 {
                        let pdo = self.od.get(index, j) as u16;
                        if !range.contains(&pdo) || !self.od.has_object(pdo) {
                            return Err(abort::VALUE_RANGE);
                        }
                    }
                } else {
                    if self.od.get(index, 0) != 0 {
                        return Err(abort::SUBINDEX0_MUST_BE_ZERO);
                    }
                    let pdo = value as u16;
                    if !range.contains(&pdo) || !self.od.has_object(pdo) {
                        return Err(abort::VALUE_RANGE);
                    }
                }
            }
            // cyclic synchronous position only (0 = no mode)
            0x6060 if value as u8 as i8 != 8 && value != 0 => return Err(abort::VALUE_RANGE),
            0x1C32 | 0x1C33 if sub == 1 => {
                let ok = match value {
                    0 | 1 => true,
                    2 => self.cfg.dc,
                    _ => false,
                };
                if !ok {
                    return Err(abort::VALUE_RANGE);
                }
            }
            _ => {}
        }
        self.od.set_bytes(index, sub, data);
        if index == 0x6060 {
            self.od.put(0x6061, 0, value);
        }
        Ok(())
    }

    fn check_mappable(&self, m: u32, want: Mappable) -> Result<(), u32> {
        if m == 0 {
            return Err(abort::CANNOT_MAP);
        }
        let (index, sub, bits) = ((m >> 16) as u16, (m >> 8) as u8, (m & 0xFF) as u16);
        match self.od.entry(index, sub) {
            Ok(e) if e.map == want && e.bits == bits => Ok(()),
            Ok(_) => Err(abort::CANNOT_MAP),
            // the object is not there at all: say so
            Err(code) => Err(code),
        }
    }

    // ------------------------------------------------------------- control

    /// Faults the drive at the next cycle (power stage off at once) with
    /// `code` in 0x603F.
    pub fn inject_fault(&mut self, code: u16) {
        self.pending_fault = Some(code);
    }

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
                    None => (fb.position, fb.velocity),
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

    fn transitions(&mut self, cw: u16) {
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
                } else if quick_stop {
                    let fb = self.plant.feedback();
                    self.ramp = Some(Ramp {
                        position: fb.position,
                        velocity: fb.velocity,
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

    fn limits(&self) -> (f64, f64) {
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

    fn probe_arms(&mut self) -> (LatchArm, LatchArm) {
        let f = self.od.get(0x60B8, 0) as u16;
        let mut arms = [LatchArm::default(); 2];
        for (k, (en_bit, shift)) in [(0x0001u16, 0u16), (0x0100, 8)].into_iter().enumerate() {
            let en = f & en_bit != 0;
            let unit = &mut self.probes[k];
            if en && !unit.enabled {
                self.next_probe_id = self.next_probe_id.wrapping_add(1).max(1);
                unit.id = self.next_probe_id;
            }
            if !en {
                unit.id = 0;
            }
            unit.enabled = en;
            let source = (f >> (shift + 2)) & 0b11;
            let rising = f & (0x0010 << shift) != 0;
            let falling = f & (0x0020 << shift) != 0;
            // probe 1: index (01); probe 2: its input (00)
            let source_ok = if k == 0 {
                source == 0b01
            } else {
                source == 0b00
            };
            if en && source_ok && (rising || falling) {
                arms[k] = LatchArm {
                    id: unit.id,
                    edge: if rising { Edge::Rising } else { Edge::Falling },
                };
            }
        }
        (arms[0], arms[1])
    }

    fn step_plant(&mut self, dt: f64, outputs_valid: bool) {
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
        } else if self.state == State::OperationEnabled && outputs_valid {
            let target = self.od.get_signed(0x607A, 0) as i32;
            // 32-bit target: extended around the current position
            let here = (fb.position * cpu).round();
            let here32 = here as i64 as i32;
            let counts = here + f64::from(target.wrapping_sub(here32));
            cmd.enable = true;
            cmd.position = counts / cpu;
            cmd.position_error_tolerance = tolerance;
        } else if self.state == State::OperationEnabled {
            // SAFE-OP with the drive enabled cannot happen (outputs_lost);
            // hold the position
            cmd.enable = true;
        } else if self.enabling {
            cmd.enable = true;
        }
        let was_enabled = self.plant.feedback().drive.enabled;
        let out = self.plant.step(&cmd, dt);
        if self.enabling {
            if out.drive.enabled {
                self.enabling = false;
                self.state = State::OperationEnabled;
            }
        } else if was_enabled
            && !out.drive.enabled
            && out.drive.fault
            && matches!(self.state, State::OperationEnabled | State::QuickStopActive)
        {
            self.ramp = None;
            self.state = State::Fault;
            self.od.put(0x603F, 0, u64::from(ERR_FOLLOWING));
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

    fn update_inputs(&mut self) {
        let fb = self.plant.feedback();
        let cpu = self.cfg.counts_per_unit;
        let mut sw = self.state.bits() | 0x0200;
        if self.state == State::OperationEnabled {
            sw |= 0x1000;
        }
        if self.od.get(0x603F, 0) as u16 == ERR_FOLLOWING && self.state == State::Fault {
            sw |= 0x2000;
        }
        self.od.put(0x6041, 0, u64::from(sw));
        let counts = |u: f64| -> u64 { ((u * cpu).round() as i64) as u32 as u64 };
        self.od.put(0x6064, 0, counts(fb.position));
        let v = (fb.velocity * cpu)
            .round()
            .clamp(i32::MIN as f64, i32::MAX as f64) as i32;
        self.od.put(0x606C, 0, v as u32 as u64);
        let t = (fb.torque * 10.0).round().clamp(-32768.0, 32767.0) as i16;
        self.od.put(0x6077, 0, t as u16 as u64);
        let mut di = 0u32;
        if fb.overtravel_negative {
            di |= 1 << 0;
        }
        if fb.overtravel_positive {
            di |= 1 << 1;
        }
        if fb.home_switch {
            di |= 1 << 2;
        }
        if let (true, Some(bit)) = (fb.marker_pulse, self.cfg.index_pulse_bit) {
            di |= 1 << (bit & 31);
        }
        self.od.put(0x60FD, 0, u64::from(di));
        if self.cfg.touch_probe {
            let f = self.od.get(0x60B8, 0) as u16;
            let mut st = 0u16;
            if self.probes[0].enabled {
                st |= 0x0001;
                let l = fb.marker_latch;
                if l.id != 0 && l.id == self.probes[0].id && l.latched {
                    if f & 0x0010 != 0 {
                        st |= 0x0002;
                        self.od.put(0x60BA, 0, counts(l.position));
                    } else {
                        st |= 0x0004;
                        self.od.put(0x60BB, 0, counts(l.position));
                    }
                }
            }
            if self.probes[1].enabled {
                st |= 0x0100;
                let l = fb.switch_latch;
                if l.id != 0 && l.id == self.probes[1].id && l.latched {
                    if f & 0x1000 != 0 {
                        st |= 0x0200;
                        self.od.put(0x60BC, 0, counts(l.position));
                    } else {
                        st |= 0x0400;
                        self.od.put(0x60BD, 0, counts(l.position));
                    }
                }
            }
            self.od.put(0x60B9, 0, u64::from(st));
        }
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
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drive() -> Drive {
        let mut cfg = DriveConfig::new("EMU");
        cfg.plant.marker_every = 10.0;
        cfg.plant.marker_at = 2.5;
        cfg.plant.switch = Some((5.0, 8.0));
        let mut d = Drive::new(cfg);
        // map like the backend does
        let rx = [
            0x6040_0010u32,
            0x607A_0020,
            0x60B8_0010,
            0x60E0_0010,
            0x60E1_0010,
        ];
        let tx = [
            0x6041_0010u32,
            0x6064_0020,
            0x606C_0020,
            0x6077_0010,
            0x60FD_0020,
            0x60B9_0010,
            0x60BA_0020,
            0x60BB_0020,
            0x60BC_0020,
            0x60BD_0020,
            0x603F_0010,
        ];
        for (idx, list) in [(0x1600u16, &rx[..]), (0x1A00, &tx[..])] {
            d.sdo_download(idx, 0, &[0], true).unwrap();
            for (i, m) in list.iter().enumerate() {
                d.sdo_download(idx, i as u8 + 1, &m.to_le_bytes(), true)
                    .unwrap();
            }
            d.sdo_download(idx, 0, &[list.len() as u8], true).unwrap();
        }
        d.sdo_download(0x6060, 0, &[8], true).unwrap();
        d
    }

    fn out(cw: u16, target: i32, tp: u16) -> Vec<u8> {
        let mut v = Vec::new();
        v.extend_from_slice(&cw.to_le_bytes());
        v.extend_from_slice(&target.to_le_bytes());
        v.extend_from_slice(&tp.to_le_bytes());
        v.extend_from_slice(&1000u16.to_le_bytes());
        v.extend_from_slice(&1000u16.to_le_bytes());
        v
    }

    fn run(d: &mut Drive, cw: u16, target: i32, tp: u16) -> DriveView {
        d.apply_outputs(&out(cw, target, tp));
        d.cycle(true);
        d.view()
    }

    fn enable(d: &mut Drive) {
        for cw in [0x0000, 0x0006, 0x0007, 0x000F, 0x000F] {
            run(d, cw, 0, 0);
        }
        assert_eq!(d.view().state, State::OperationEnabled);
    }

    #[test]
    fn mapping_rules() {
        let mut d = drive();
        assert_eq!(d.rx_bytes(), 12);
        assert_eq!(d.tx_bytes(), 36);
        // sub 0 must be 0 before entries change
        assert_eq!(
            d.sdo_download(0x1600, 1, &0x6040_0010u32.to_le_bytes(), true),
            Err(abort::SUBINDEX0_MUST_BE_ZERO)
        );
        // mapping changes only in PRE-OP
        assert_eq!(d.sdo_download(0x1600, 0, &[0], false), Err(abort::STATE));
        d.sdo_download(0x1600, 0, &[0], true).unwrap();
        // an input object in the RxPDO cannot be mapped
        assert_eq!(
            d.sdo_download(0x1600, 1, &0x6041_0010u32.to_le_bytes(), true),
            Err(abort::CANNOT_MAP)
        );
        // a missing object is named as such
        let mut cfg = DriveConfig::new("NOTP");
        cfg.touch_probe = false;
        let mut n = Drive::new(cfg);
        n.sdo_download(0x1600, 0, &[0], true).unwrap();
        assert_eq!(
            n.sdo_download(0x1600, 3, &0x60B8_0010u32.to_le_bytes(), true),
            Err(abort::OBJECT_NOT_FOUND)
        );
        assert_eq!(n.od.upload(0x60B8, 0), Err(abort::OBJECT_NOT_FOUND));
        // modes and sync types
        assert_eq!(
            d.sdo_download(0x6060, 0, &[1], true),
            Err(abort::VALUE_RANGE)
        );
        assert_eq!(d.od.get(0x6061, 0), 8);
        d.sdo_download(0x1C32, 1, &2u16.to_le_bytes(), true)
            .unwrap();
        let mut cfg = DriveConfig::new("NODC");
        cfg.dc = false;
        let mut n = Drive::new(cfg);
        assert_eq!(
            n.sdo_download(0x1C32, 1, &2u16.to_le_bytes(), true),
            Err(abort::VALUE_RANGE)
        );
        assert_eq!(n.od.get(0x1C32, 4), 0x0003);
    }

    #[test]
    fn state_machine_follow_and_latch() {
        let mut d = drive();
        assert_eq!(d.view().state, State::NotReadyToSwitchOn);
        enable(&mut d);
        assert_eq!(d.view().statusword, 0x1237);
        // CSP: the plant follows the target at once (1000 counts/unit)
        let v = run(&mut d, 0x000F, 1500, 0);
        assert_eq!(v.position, 1.5);
        let mut buf = vec![0u8; d.tx_bytes()];
        d.fill_inputs(&mut buf);
        assert_eq!(i32::from_le_bytes(buf[2..6].try_into().unwrap()), 1500);
        // arm probe 1 (index, rising) and probe 2 (input, rising)
        run(&mut d, 0x000F, 1500, 0x1115);
        let v = run(&mut d, 0x000F, 3000, 0x1115);
        assert_eq!(
            v.touch_probe_status & 0x0303,
            0x0103,
            "{:#06x}",
            v.touch_probe_status
        );
        assert_eq!(d.od.get_signed(0x60BA, 0), 2500);
        let v = run(&mut d, 0x000F, 6000, 0x1115);
        assert_eq!(v.touch_probe_status & 0x0303, 0x0303);
        assert_eq!(d.od.get_signed(0x60BC, 0), 5000);
        // re-arm by toggling: stored bits clear, nothing new until an edge
        run(&mut d, 0x000F, 6000, 0x0000);
        let v = run(&mut d, 0x000F, 6000, 0x0015);
        assert_eq!(v.touch_probe_status, 0x0001);
        // torque limits per mille → %
        assert_eq!(v.torque_limit_positive, 100.0);
    }

    #[test]
    fn quick_stop_ramps_then_switch_on_disabled() {
        let mut d = drive();
        enable(&mut d);
        // moving at 10 units/s: 10 counts per 1 ms cycle
        let mut t = 0;
        for _ in 0..100 {
            t += 10;
            run(&mut d, 0x000F, t, 0);
        }
        let v = run(&mut d, 0x0002, t, 0);
        assert_eq!(v.state, State::QuickStopActive);
        let mut n = 0;
        while d.view().state == State::QuickStopActive {
            run(&mut d, 0x0002, t, 0);
            n += 1;
            assert!(n < 1000);
        }
        // 10 units/s at 1000 units/s²: ~10 cycles
        assert!((8..=12).contains(&n), "{n}");
        assert_eq!(d.view().state, State::SwitchOnDisabled);
        assert_eq!(d.view().velocity, 0.0);
    }

    #[test]
    fn faults_and_reset() {
        let mut d = drive();
        enable(&mut d);
        d.inject_fault(0x2310);
        let v = run(&mut d, 0x000F, 0, 0);
        assert_eq!(v.state, State::Fault);
        assert_eq!(v.error_code, 0x2310);
        assert!(!v.enabled);
        // no edge: stays
        let v = run(&mut d, 0x0000, 0, 0);
        assert_eq!(v.state, State::Fault);
        let v = run(&mut d, 0x0080, 0, 0);
        assert_eq!(v.state, State::SwitchOnDisabled);
        assert_eq!(v.error_code, 0);
        enable(&mut d);

        // following error: tolerance window 100 counts, jump 1000 counts
        d.sdo_download(0x6065, 0, &100u32.to_le_bytes(), false)
            .unwrap();
        let mut cfg = d.cfg.clone();
        cfg.plant.hard_stop = Some((-1.0, 0.5));
        let mut d2 = drive();
        d2.cfg = cfg.clone();
        d2.plant = Plant::new(cfg.plant);
        enable(&mut d2);
        d2.sdo_download(0x6065, 0, &100u32.to_le_bytes(), false)
            .unwrap();
        let v = run(&mut d2, 0x000F, 1000, 0);
        assert_eq!(v.state, State::Fault);
        assert_eq!(v.error_code, ERR_FOLLOWING);
        assert_eq!(v.statusword & 0x2000, 0x2000);
    }

    #[test]
    fn watchdog_loss_ramps_then_faults() {
        let mut d = drive();
        enable(&mut d);
        let mut t = 0;
        for _ in 0..50 {
            t += 20;
            run(&mut d, 0x000F, t, 0);
        }
        d.outputs_lost(true);
        assert_eq!(d.view().state, State::FaultReactionActive);
        let mut n = 0;
        while d.ramping() {
            d.tick();
            n += 1;
            assert!(n < 1000);
        }
        let v = d.view();
        assert_eq!(v.state, State::Fault);
        assert_eq!(v.error_code, ERR_COMMUNICATION);
        assert_eq!(v.velocity, 0.0);
        assert!(v.position > 1.0);
    }
}
