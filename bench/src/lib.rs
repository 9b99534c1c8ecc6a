//! `motion-bench`'s library: what the benchmarks share (see
//! `bench/README.md`). The binaries — `jitter`, `cpcost`, `ipc`, `soak`,
//! `deadpeer`, `stream` — and the engine's criterion benches are thin
//! sequences of these and of the crates.
//!
//! * The run of a bench: [`flags`] the common command-line groups,
//!   [`outcome`] how a run starts and ends, [`host`] the machine.
//! * The binaries and the daemon: [`bins`] where they are, [`proc`] the
//!   bench's processes (the harness's children, the stop handler,
//!   stress-ng), [`drive`] a daemon started, ready, stopped and its
//!   leftovers cleaned; [`machine`] the machines the benches generate.
//! * What is measured: [`runs`] a timed daemon run read back (its report
//!   and its `.hlog`), [`slice`] the slices of a variant merged;
//!   [`homing`] homings run and tallied, repeated while a daemon is
//!   measured, a traced homing; [`clients`] a deployed machine's
//!   `motionctl` clients as a load; [`spy`] the frame spy on one I/O
//!   process's topics; [`bare`] plain iceoryx2 ports of the frames' sizes
//!   and their echo (the IPC bench's floor); [`cyclictest`] the jitter
//!   bench's reference; [`stream`] a streaming program; [`engine`] engine
//!   states reached by real homing (the engine bench's inputs).
//!
//! One direction: this library uses the test harness (`motion-harness`:
//! children, readiness, leftover checks, the EtherCAT rig), never the other
//! way round; the `.hlog` is the supervisor's (`hlog`), the tables' cells
//! `motion-report`'s, the plot `motion-plot`'s. Nothing here runs in a
//! real-time loop but the spy, the bare echo and the streaming program's
//! thread; the rest is orchestration, parsing and reporting.
//! Invariants: the cycle's figures are the supervisor's own (its JSON
//! report and interval log, read back through `motion-report`'s types),
//! never timed by a bench; no process a bench starts outlives it (its
//! children are the harness's, ended with their handles, also on SIGINT).

pub mod bare;
pub mod bins;
pub mod clients;
pub mod cyclictest;
pub mod drive;
pub mod engine;
pub mod flags;
pub mod homing;
pub mod host;
pub mod machine;
pub mod outcome;
pub mod proc;
pub mod runs;
pub mod slice;
pub mod spy;
pub mod stream;

pub use motion_harness::ecat;
pub use motion_plot as plot;
pub use motion_report::table;
pub use motion_supervisor::hlog;
pub use motion_supervisor::stats::{histogram, percentiles};
