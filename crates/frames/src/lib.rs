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

/// `CLOCK_MONOTONIC` now, in ns. The clock is system-wide on Linux, so values
/// taken in `motion-supervisor` and `motion-io` can be compared directly (the
/// frame timestamps use it). Allocation-free, vDSO call.
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: valid pointer to a timespec; CLOCK_MONOTONIC always exists on Linux.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    debug_assert_eq!(rc, 0);
    (ts.tv_sec as u64)
        .saturating_mul(1_000_000_000)
        .saturating_add(ts.tv_nsec as u64)
}
