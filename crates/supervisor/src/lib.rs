//! `motion-supervisor`: the real-time cycle around the homing engine, and
//! the daemon around the cycle.
//!
//! * [`rt_thread`] — the pinned SCHED_FIFO thread and its cycle.
//! * [`core`] — one cycle's work without I/O (one slot per axis, control
//!   requests, I/O links, engines, home sequences, frames).
//! * [`shared`] — the lock-free hand-off between real-time and normal
//!   threads, in the domain's types (refusals, why HomedStatus was lost).
//! * [`control_thread`] — the control and status services, off the cycle.
//! * [`keeper`] — what outlives a run: stored references of absolute axes,
//!   the homing record with its drift checks (files in `state_dir`).
//! * [`hub`] — what the normal threads share (statistics, snapshot, trace).
//! * [`stats`], [`hlog`] — latency histograms and their logs.
//! * [`session`] — start-up and clean shut-down (domain, threads, I/O processes).
//! * [`commands`] — `run`, `home`, `check`.

pub mod cli;
pub mod commands;
pub mod control_thread;
pub mod core;
pub mod cpu;
pub mod hlog;
pub mod hub;
pub mod io_child;
pub mod keeper;
pub mod rt_thread;
pub mod session;
pub mod shared;
pub mod stats;
pub mod status_fill;
pub mod trace_csv;
