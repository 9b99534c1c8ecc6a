//! What an emulated drive is: identity, the objects it has, DC, units.

use motion_plant::PlantConfig;

/// How the drive's PDOs may be changed (real drives differ).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PdoProfile {
    /// Mapping (0x1600 / 0x1A00) and assignment (0x1C12 / 0x1C13)
    /// writable in PRE-OP.
    Writable,
    /// Fixed: 0x1600 / 0x1A00 hold these entries (mapping values) and
    /// cannot be written, nor can the assignment.
    Fixed { rx: Vec<u32>, tx: Vec<u32> },
    /// Predefined PDOs (index, entries), read only; the assignment is
    /// writable and holds the first RxPDO and TxPDO of the list at power-on.
    Predefined(Vec<(u16, Vec<u32>)>),
}

/// When 0x6061 (modes of operation display) shows a mode written to 0x6060.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeDisplay {
    /// At once.
    Immediate,
    /// Only once the ESC is in SAFE-OP or OP (some drives update it there).
    Late,
    /// Never (a drive that refuses the mode without an SDO abort).
    Never,
}

/// Which torque-limit objects the drive has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TorqueObjects {
    /// 0x60E0 / 0x60E1 and 0x6072.
    PerDirection,
    /// 0x6072 only.
    MaxTorqueOnly,
}

/// The homing methods the emulator implements (see `drive::homing`).
pub const SUPPORTED_METHODS: [i8; 9] = [3, 5, 19, 21, 33, 34, 37, -1, -2];

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
    /// How its PDOs may be changed.
    pub pdo: PdoProfile,
    /// When 0x6061 shows the mode written to 0x6060.
    pub mode_display: ModeDisplay,
    /// Quick stop (controlword) is ignored: the drive stays in Operation
    /// enabled, holding its set-point.
    pub ignores_quick_stop: bool,
    /// Homing methods of its homing mode (0x60E3); empty: no homing mode
    /// (and no 0x6098..0x609A, 0x607C, 0x60E3).
    pub homing_methods: Vec<i8>,
    /// Has 0x60FD digital inputs.
    pub digital_inputs: bool,
    /// Reports the limit switches in 0x60FD bits 0/1.
    pub limit_switches: bool,
    /// Objects the drive does not have (removed from its dictionary).
    pub without: Vec<u16>,
    /// Its ESC's clock runs this many parts per million fast (negative:
    /// slow) against the host's: a crystal's tolerance. The first DC
    /// SubDevice is the bus's reference clock, so the master's cycle
    /// follows it and drifts against the supervisor's by as much.
    pub clock_ppm: f64,
}

impl DriveConfig {
    /// A drive named `name` with defaults: 1000 counts/unit, touch probes,
    /// DC, per-direction torque limits, 1 ms cycle, no enable delay,
    /// writable PDOs, every homing method of [`SUPPORTED_METHODS`], digital
    /// inputs with limit switches.
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
            pdo: PdoProfile::Writable,
            mode_display: ModeDisplay::Immediate,
            ignores_quick_stop: false,
            homing_methods: SUPPORTED_METHODS.to_vec(),
            digital_inputs: true,
            limit_switches: true,
            without: Vec::new(),
            clock_ppm: 0.0,
        }
    }
}
