//! Shared pieces of the benchmarks (see `bench/README.md`):
//!
//! * `jitter` — the supervisor's real cycle side by side with cyclictest
//!   (and, with `--ethercat`, with the EtherCAT backend over a veth pair to
//!   emulated drives, [`ecat`]);
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
pub mod drive;
pub mod ecat;
pub mod hist;
pub mod host;
pub mod machine;
pub mod proc;
pub mod run_report;
pub mod spy;
pub mod svg;
pub mod sys;
