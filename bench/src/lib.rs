//! The benchmarks' shared pieces (see `bench/README.md`). The binaries —
//! `jitter`, `cpcost`, `ipc`, `soak`, `deadpeer` — are thin sequences of
//! these: [`flags`] their common command-line groups, [`outcome`] how a run
//! starts and ends, [`host`] the machine, [`slice`] a supervisor run read
//! back, [`hist`], [`table`] and [`plot`] the figures, [`cyclictest`] the
//! reference tool; [`drive`], [`proc`], [`machine`], [`spy`] and [`ecat`]
//! start, drive and observe the supervisor.
//!
//! Nothing here runs in a real-time loop except the IPC bench's measuring
//! thread; the rest is orchestration, parsing and reporting.

pub mod cyclictest;
pub mod flags;
pub mod hist;
pub mod host;
pub mod outcome;
pub mod plot;
pub mod slice;
pub mod table;

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
