//! `motion-frames`: the per-cycle command and feedback frames exchanged
//! between `motion-supervisor` and the drive-I/O process `motion-io` over
//! iceoryx2 0.10 shared memory, their conversion from/to the homing engine's
//! [`motion_homing::Command`] / [`motion_homing::Feedback`], and the iceoryx2
//! port helpers both processes use.
//!
//! * [`frame`] — `#[repr(C)]` wire types with pinned layout and versioned
//!   iceoryx2 type names.
//! * [`convert`] — units ↔ counts, pure and allocation-free.
//! * [`ipc`] — service names, QoS, node and ports ([`SupervisorPorts`],
//!   [`IoPorts`]), engineer-readable errors.

pub mod convert;
pub mod frame;
pub mod ipc;

pub use convert::{
    axis_to_command, axis_to_feedback, command_to_axis, counts_to_units, feedback_to_axis,
    units_to_counts, INVALID_COUNTS,
};
pub use frame::*;
pub use ipc::{
    service_names, IoPorts, IpcConfig, IpcError, Ports, Sent, ServiceNames, SupervisorPorts,
};

/// `CLOCK_MONOTONIC` now, in ns: the clock of every frame timestamp. It is
/// system-wide on Linux, so values taken in `motion-supervisor` and
/// `motion-io` compare directly. (The runtime's clock, under the name the
/// frame code uses.)
pub use motion_rt::now_ns as monotonic_ns;
