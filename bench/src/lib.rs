//! The benchmarks' shared pieces (see `bench/README.md`). The binaries —
//! `jitter`, `cpcost`, `ipc`, `soak`, `deadpeer`, `stream` — are thin
//! sequences of these and of the crates: [`flags`] their common
//! command-line groups, [`outcome`] how a run starts and ends, [`host`] the
//! machine. The rest is the harness's (starting, driving and observing the
//! binaries, supervisor runs read back and merged, the streaming program),
//! the supervisor's (histograms and their `.hlog`), `motion-report`'s (the
//! tables' cells) and `motion-plot`'s.
//!
//! Nothing here runs in a real-time loop except the IPC bench's measuring
//! thread; the rest is orchestration, parsing and reporting.

pub mod flags;
pub mod host;
pub mod outcome;

pub use motion_harness::generated as machine;
pub use motion_harness::process as proc;
pub use motion_harness::slices as slice;
pub use motion_harness::{bare, clients, cyclictest, ecat, spy, stream};
pub use motion_plot as plot;
pub use motion_report::table;
pub use motion_supervisor::hlog;
pub use motion_supervisor::stats::{histogram, percentiles};

/// Driving a running supervisor from the benches (`motion_harness`).
pub mod drive {
    pub use motion_harness::bins::Binaries;
    pub use motion_harness::daemon::{
        run_command, start_machine, start_run, status, stop_run, wait_until_ready, write_config,
    };
    pub use motion_harness::homing::*;
    pub use motion_harness::leftovers::clean_leftovers;
    pub use motion_harness::procs::{io_children, stress};
    pub use motion_harness::runs::{self, Measured};
}
