//! The object dictionary of an emulated drive: identity, the PDO mapping
//! (default: controlword + target / statusword + position) and assignment
//! objects, the sync-manager parameters, and the CiA 402 objects the
//! backend needs (the touch-probe and per-direction torque-limit objects
//! only where the [`DriveConfig`] says the drive has them).

use super::config::{DriveConfig, PdoProfile, TorqueObjects};
use crate::od::{Access, Mappable, Od};

/// PDO mapping objects' capacity (sub-indices).
pub(super) const MAP_SUBS: usize = 12;
/// Largest PDO the drive accepts, bytes.
pub(super) const MAX_PDO_BYTES: usize = 64;

/// The dictionary of a drive configured as `cfg`.
pub(super) fn build(cfg: &DriveConfig) -> Od {
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
    pdo_objects(&mut od, &cfg.pdo);
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
    let qs = (cfg.quick_stop_deceleration * cfg.counts_per_unit).clamp(1.0, f64::from(u32::MAX));
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
    if cfg.digital_inputs {
        od.var(0x60FD, "digital inputs", 32, Ro, Tx, 0);
    }
    homing_objects(&mut od, &cfg.homing_methods);
    for &index in &cfg.without {
        od.remove(index);
    }
    od
}

/// The mapping and assignment objects of the drive's PDO profile.
fn pdo_objects(od: &mut Od, profile: &PdoProfile) {
    use Access::*;
    use Mappable::*;
    let fixed = |od: &mut Od, index: u16, name: &'static str, entries: &[u32]| {
        let subs: Vec<(u16, Access, Mappable, u64)> = entries
            .iter()
            .map(|&m| (32, Ro, No, u64::from(m)))
            .collect();
        od.record(index, name, Ro, &subs);
    };
    match profile {
        PdoProfile::Writable => {
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
            od.record(0x1C12, "RxPDO assign", Rw, &[(16, Rw, No, 0x1600)]);
            od.record(0x1C13, "TxPDO assign", Rw, &[(16, Rw, No, 0x1A00)]);
        }
        PdoProfile::Fixed { rx, tx } => {
            fixed(od, 0x1600, "RxPDO mapping", rx);
            fixed(od, 0x1A00, "TxPDO mapping", tx);
            od.record(0x1C12, "RxPDO assign", Ro, &[(16, Ro, No, 0x1600)]);
            od.record(0x1C13, "TxPDO assign", Ro, &[(16, Ro, No, 0x1A00)]);
        }
        PdoProfile::Predefined(list) => {
            for (index, entries) in list {
                let name = if *index < 0x1A00 {
                    "RxPDO mapping"
                } else {
                    "TxPDO mapping"
                };
                fixed(od, *index, name, entries);
            }
            let first = |rx: bool| {
                list.iter()
                    .map(|(i, _)| *i)
                    .find(|i| (*i < 0x1A00) == rx)
                    .unwrap_or(0)
            };
            // room for two assigned PDOs
            let assign = |i: u16| [(16, Rw, No, u64::from(i)), (16, Rw, No, 0)];
            od.record(0x1C12, "RxPDO assign", Rw, &assign(first(true)));
            od.put(0x1C12, 0, 1);
            od.record(0x1C13, "TxPDO assign", Rw, &assign(first(false)));
            od.put(0x1C13, 0, 1);
        }
    }
}

/// Homing mode's objects where the drive has homing methods; 0x6502 says
/// which modes it supports (bit 7 CSP, bit 5 homing).
fn homing_objects(od: &mut Od, methods: &[i8]) {
    use Access::*;
    use Mappable::*;
    if methods.is_empty() {
        od.var(0x6502, "supported drive modes", 32, Ro, No, 0x80);
        return;
    }
    od.var(0x6502, "supported drive modes", 32, Ro, No, 0xA0);
    od.var(0x6098, "homing method", 8, Rw, No, 0);
    od.record(
        0x6099,
        "homing speeds",
        Ro,
        &[(32, Rw, No, 1000), (32, Rw, No, 100)],
    );
    od.var(0x609A, "homing acceleration", 32, Rw, No, 100_000);
    od.var(0x607C, "home offset", 32, Rw, No, 0);
    let list: Vec<(u16, Access, Mappable, u64)> = methods
        .iter()
        .map(|&m| (8, Ro, No, u64::from(m as u8)))
        .collect();
    od.record(0x60E3, "supported homing methods", Ro, &list);
}
