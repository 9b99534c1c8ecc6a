//! What the tools print, as typed `serde` structs: one definition shared by
//! the writer (`motion-supervisor`, `motionctl`) and every reader (the bench,
//! the tests, scripts). A field renamed here is renamed everywhere at once;
//! nothing is read back with `.unwrap_or(0)`.
//!
//! * [`latency`] — percentiles of the three latencies (`home`/`run`/`stats`).
//! * [`home`] — `home --json`: one row per axis (fixed keys).
//! * [`status`] — `status --json`: the live state of every axis and I/O
//!   process (its rows generated from `motion-status`'s table).
//! * [`io`] — per I/O process: attached, frames, gaps by length.
//! * [`motion`] — `move --json` / `stream --json`.
//! * [`errors`] — `{"errors": [...]}`, printed on every failure with `--json`
//!   (also for a refused command line).
//! * [`codes`] — ERR/EXERR in plain words.
//! * [`table`] — the fixed-width text tables of the same reports.
//! * [`trace`] — the trace CSV, written by the daemon and read by `motionctl`.
//! * [`panic`] — a panic with `--json`: one error object, like every failure.

pub mod codes;
pub mod errors;
pub mod home;
pub mod io;
pub mod latency;
pub mod motion;
pub mod panic;
pub mod status;
pub mod table;
pub mod trace;

pub use errors::{ErrorEntry, ErrorReport};
pub use home::AxisOperationLimits;
pub use home::{
    AcceptedReport, Allocations, AxisResult, CheckReport, CpuUse, CtlHomeReport, HomeReport,
    RtInfo, RunReport, StatsReport, TraceReport,
};
pub use io::{GapCounts, IoCounters, IoReport};
pub use latency::{LateWakeup, Latency, Percentiles};
pub use motion::{MotionReport, MotionRow};
pub use status::{AxisStatus, IoStatus, StatusReport, StreamIntake};
pub use trace::TraceRow;

/// Rounds to `digits` decimals for printing (JSON keeps what a reader can use,
/// not float noise).
pub fn round(x: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (x * k).round() / k
}

/// Nearest-rank percentile `p` (0..=1) of the sorted `v`; `None` if empty.
pub fn nearest_rank(v: &[f64], p: f64) -> Option<f64> {
    let k = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len().max(1));
    v.get(k - 1).copied()
}

/// Prints `v` as one line of JSON on stdout (and notes that a JSON object
/// is out: a panic after it prints no second one, see [`panic`]).
pub fn print_json<T: serde::Serialize>(v: &T) {
    panic::note_json_printed();
    match serde_json::to_string(v) {
        Ok(s) => println!("{s}"),
        // Our report types always serialize; say so rather than print nothing.
        Err(e) => println!(
            "{{\"errors\":[{{\"axis\":null,\"key\":null,\"err\":null,\"exerr\":null,\"message\":\"report could not be serialized: {}\"}}]}}",
            e.to_string().replace('"', "'")
        ),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn nearest_rank_of_sorted_values() {
        let v = [1.0, 2.0, 3.0, 4.0];
        let p = |q| super::nearest_rank(&v, q);
        assert_eq!(
            (p(0.0), p(0.25), p(0.5), p(0.99), p(1.0)),
            (Some(1.0), Some(1.0), Some(2.0), Some(4.0), Some(4.0))
        );
        assert_eq!(super::nearest_rank(&[], 0.5), None);
    }
}
