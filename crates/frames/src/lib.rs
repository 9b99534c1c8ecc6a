//! `motion-frames`: the wire types of the per-cycle exchange between
//! `motion-supervisor` and the drive-I/O processes, and their conversion
//! from/to the homing engine's [`motion_homing::Command`] /
//! [`motion_homing::Feedback`]. Nothing here opens a file, a socket or shared
//! memory: moving the frames between processes is `motion-ipc`'s job.
//!
//! * [`frame`] — `#[repr(C)]` wire types with pinned layout, the layout
//!   version and the versioned iceoryx2 type names.
//! * [`convert`] — units ↔ counts, pure and allocation-free.
//! * [`setpoint`] — the supervised setpoint stream's `#[repr(C)]` message
//!   (a program → the supervisor), versioned like the frames.
//! * `zero_copy` (feature `zero-copy`) — iceoryx2's `ZeroCopySend` (with the
//!   type names above) and `PlacementDefault` for the frames.
//!
//! # Why the iceoryx2 traits are a feature
//!
//! The frames travel through iceoryx2 shared memory, so they must implement
//! its `ZeroCopySend` and `PlacementDefault`. Those traits and their derives
//! live in two small iceoryx2 crates without any IPC
//! (`iceoryx2-bb-elementary-traits`, `iceoryx2-bb-derive-macros`); the derive
//! crate still brings iceoryx2's logger and synchronisation crates along. A
//! crate that only fills or reads frames (the EtherCAT backend, the emulator's
//! tests, the engine bench) needs none of it, so the traits sit behind the
//! `zero-copy` feature, which `motion-ipc` turns on: every crate that moves
//! frames through iceoryx2 depends on `motion-ipc` and so gets them, and a
//! wire-only user compiles no iceoryx2 code at all. The type names and the
//! layout are the same with and without the feature.

pub mod backend;
pub mod convert;
pub mod frame;
pub mod setpoint;
#[cfg(feature = "zero-copy")]
mod zero_copy;

pub use convert::{
    axis_to_command, axis_to_feedback, command_to_axis, counts_to_units, feedback_to_axis,
    units_to_counts, INVALID_COUNTS,
};
pub use frame::*;
pub use setpoint::*;
