//! Shared pieces of the benchmarks (see `bench/README.md`):
//!
//! * `jitter` — the supervisor's real cycle side by side with cyclictest
//!   (and, with `--ethercat`, with the EtherCAT backend over a veth pair to
//!   emulated drives, `motion_harness::ecat`);
//! * `ipc` — the command/feedback round trip through iceoryx2, next to a bare
//!   iceoryx2 ping-pong;
//! * `benches/engine.rs` — criterion benches of one engine step and one
//!   whole cycle's compute.
//!
//! Nothing here runs in a real-time loop except [`sys::sleep_until`] and the
//! IPC bench's measuring thread; the rest is orchestration, parsing and
//! reporting.

pub mod cli;
pub mod cyclictest;
pub mod hist;
pub mod host;
pub mod run_report;
pub mod svg;
pub mod sys;

// The harness's pieces, under the names the bench binaries use: children
// and the stop flag, driving a running supervisor, its machines, the frame
// spy, the EtherCAT rig.
pub use motion_harness::generated as machine;
pub use motion_harness::process as proc;
pub use motion_harness::{ecat, spy};

/// Driving a running supervisor from the benches (`motion_harness`).
pub mod drive {
    pub use motion_harness::bins::Binaries;
    pub use motion_harness::daemon::{spawn_run, status, stop_run, wait_until_ready};
    pub use motion_harness::homing::*;
    pub use motion_harness::leftovers::{clean_leftovers, leftovers};
    pub use motion_harness::procs::{io_children, stress};
}
