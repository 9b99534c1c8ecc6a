//! Per I/O process: attached or not, frames, and the gaps in its feedback —
//! `motion-status`'s one declaration of these counters, as the `home`,
//! `run` and `stats` reports show them.

pub use motion_status::{GapCounts, IoCounters, IoReport};
