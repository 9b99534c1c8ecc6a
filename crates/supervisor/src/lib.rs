//! `motion-supervisor`: the real-time cycle around the homing engine.
//!
//! * [`rt_thread`] — the pinned SCHED_FIFO thread and its cycle.
//! * [`core`] — one cycle's work without I/O (control, engines, frames).
//! * [`shared`] — the lock-free hand-off between real-time and normal threads.
//! * [`stats`] — latency histograms and their summaries.
//! * [`session`] — start-up and clean shut-down (I/O process, shared memory).
//! * [`commands`] — `run`, `home`, `check`.

pub mod cli;
pub mod commands;
pub mod core;
pub mod cpu;
pub mod hlog;
pub mod io_child;
pub mod report;
pub mod rt_thread;
pub mod session;
pub mod shared;
pub mod stats;
