//! What an emulated drive is: identity, the objects it has, DC, units.

use motion_plant::PlantConfig;

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
