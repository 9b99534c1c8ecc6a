//! `motion-frames`: the per-cycle command and feedback frames exchanged
//! between `motion-supervisor` and the drive-I/O processes over iceoryx2 0.10
//! shared memory, their conversion from/to the homing engine's
//! [`motion_homing::Command`] / [`motion_homing::Feedback`], and the IPC
//! plumbing every process of the product shares.
//!
//! * [`frame`] — `#[repr(C)]` wire types with pinned layout and versioned
//!   iceoryx2 type names.
//! * [`convert`] — units ↔ counts, pure and allocation-free.
//! * [`domain`] — the supervisor's private iceoryx2 domain: runtime
//!   directory, session file and key, node creation with its guards.
//! * [`names`] — service names.
//! * [`ports`] — the frame ports of one I/O process ([`SupervisorPorts`],
//!   [`IoPorts`]).
//! * [`wait`] — exact waits on an iceoryx2 listener (`ppoll`).
//! * [`cleanup`] — leaving nothing behind in `/dev/shm`.
//! * [`error`] — engineer-readable errors.

pub mod backend;
pub mod cleanup;
pub mod convert;
pub mod domain;
pub mod error;
pub mod frame;
pub mod names;
pub mod ports;
pub mod wait;

pub use cleanup::{cleanup_domain, CleanupReport};
pub use convert::{
    axis_to_command, axis_to_feedback, command_to_axis, counts_to_units, feedback_to_axis,
    units_to_counts, INVALID_COUNTS,
};
pub use domain::Domain;
pub use error::IpcError;
pub use frame::*;
pub use names::IoServiceNames;
pub use ports::{IoPorts, Ports, Sent, SupervisorPorts};

/// `CLOCK_MONOTONIC` now, in ns: the clock of every frame timestamp. It is
/// system-wide on Linux, so values taken in `motion-supervisor` and
/// `motion-io` compare directly. (The runtime's clock, under the name the
/// frame code uses.)
pub use motion_rt::now_ns as monotonic_ns;
