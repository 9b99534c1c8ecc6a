//! A recorded homing as CSV (`motionctl trace --out FILE.csv`): the cycle's
//! trace records in the columns of `motion_report::trace`, which also reads
//! them back.

use crate::shared::TraceRecord;
use motion_homing::Phase;
use motion_report::trace::{self, TraceRow};

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// One record as a row: non-finite numbers (no feedback) are absent.
pub fn row(r: &TraceRecord) -> TraceRow {
    TraceRow {
        t_s: r.t_ns as f64 * 1e-9,
        phase: Phase::from_number(r.phase),
        cmd_position: finite(r.cmd_position),
        cmd_velocity: finite(r.cmd_velocity),
        position: finite(r.position),
        velocity: finite(r.velocity),
        torque: finite(r.torque),
        switch: r.switch,
        marker: r.marker,
        fresh: r.fresh,
        event: r.event,
        event_raw: finite(r.event_raw),
        err: r.err,
        exerr: r.exerr,
    }
}

/// The records as CSV text (header included).
pub fn csv(records: &[TraceRecord]) -> String {
    trace::csv(records.iter().map(row))
}
