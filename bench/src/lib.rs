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
pub mod drive;
pub mod ecat;
pub mod flags;
pub mod hist;
pub mod host;
pub mod machine;
pub mod outcome;
pub mod plot;
pub mod proc;
pub mod slice;
pub mod spy;
pub mod table;
