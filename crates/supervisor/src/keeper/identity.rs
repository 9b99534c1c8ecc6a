//! What a raw position of an axis means, as the keys of its configuration
//! that define it: a stored reference is valid only under the same ones.

use motion_config::{EthercatDrive, MachineConfig};
use motion_homing::TravelMode;
use motion_state::AxisIdentity;

/// The identity of axis `i`: its I/O process and slot in it, its drive on
/// an EtherCAT bus, the scaling, the Home Position, the travel mode, the
/// home mode and whether the encoder is absolute. Travel limits are not
/// part of it: they are checked against the restored position instead.
pub fn identity(m: &MachineConfig, i: usize) -> AxisIdentity {
    let a = &m.axes[i];
    let e = &a.engine;
    let slot = m.axes_of(a.io).iter().position(|&j| j == i).unwrap_or(0);
    let mut id = AxisIdentity::default()
        .with("io", &m.ios[a.io].name)
        .with("slot", slot)
        .with("counts_per_unit", e.counts_per_unit)
        .with("home_position", e.home_position)
        .with("travel_mode", e.travel.name())
        .with("home_mode", e.home_mode.name())
        .with("absolute", e.absolute);
    if e.travel == TravelMode::Cyclic {
        id = id.with("unwind", e.unwind);
    }
    if let Some(ec) = &a.ethercat {
        id = match &ec.drive {
            EthercatDrive::Position(p) => id.with("ethercat_position", p),
            EthercatDrive::Name(n) => id.with("ethercat_name", n),
        };
    }
    id
}
