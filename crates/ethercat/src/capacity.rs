//! The fixed capacities of the bus, in one place: ethercrab sizes its
//! SubDevice group, process image and frame storage at compile time, and the
//! bus thread's per-cycle arrays follow them (no allocation in the cycle).

use ethercrab::PduStorage;

/// Most SubDevices on the bus (and axes of one backend).
pub const MAX_SUBDEVICES: usize = 32;
/// Most process-image bytes.
pub const MAX_PDI: usize = 2048;
/// Frames in flight (ethercrab's PDU storage).
pub const MAX_FRAMES: usize = 32;
/// Largest PDU payload of one frame.
pub const MAX_PDU_DATA: usize = PduStorage::element_size(1100);

// The config refuses more axes per EtherCAT I/O process than the bus holds.
const _: () = assert!(motion_config::limits::ETHERCAT_MAX_AXES <= MAX_SUBDEVICES);
