//! What `home` prints: one row per axis (table or the JSON of interface.md).

use crate::shared::AxisSnap;
use motion_config::names::{name_of, HOME_DIRECTIONS, HOME_MODES, HOME_SEQUENCES};
use motion_config::AxisEntry;

/// The result of one axis.
#[derive(Clone, Debug)]
pub struct Row {
    pub name: String,
    pub mode: &'static str,
    pub sequence: &'static str,
    pub direction: &'static str,
    pub snap: AxisSnap,
    /// Why the axis has no result when it never ran (e.g. the run was interrupted).
    pub note: Option<String>,
}

impl Row {
    pub fn new(entry: &AxisEntry, snap: AxisSnap, note: Option<String>) -> Self {
        let c = &entry.engine;
        Self {
            name: entry.name.clone(),
            mode: name_of(HOME_MODES, c.home_mode),
            sequence: name_of(HOME_SEQUENCES, c.home_sequence),
            direction: name_of(HOME_DIRECTIONS, c.home_direction),
            snap,
            note,
        }
    }

    pub fn duration_s(&self) -> Option<f64> {
        let s = &self.snap.status;
        s.finished_ns
            .map(|f| f.saturating_sub(s.started_ns) as f64 * 1e-9)
    }

    /// Plain words for the error code.
    pub fn error_text(&self) -> Option<String> {
        let s = &self.snap.status;
        if let Some(n) = &self.note {
            return Some(n.clone());
        }
        s.er.then(|| {
            let what = explain(s.err, s.exerr);
            match s.bad_attribute {
                Some(a) => format!("{what} ({a})"),
                None => what.to_string(),
            }
        })
    }

    pub fn to_json(&self) -> serde_json::Value {
        let s = &self.snap.status;
        let r = |x: Option<f64>| x.map(|v| (v * 1e6).round() / 1e6);
        let mut v = serde_json::json!({
            "name": self.name,
            "mode": self.mode,
            "sequence": self.sequence,
            "direction": self.direction,
            "pc": s.pc,
            "er": s.er,
            "err": s.err,
            "exerr": s.exerr,
            "homed": s.homed,
            "event_raw": r(s.event_raw),
            "final_position": r(self.snap.axis),
            "final_raw": r(self.snap.raw),
            "duration_s": self.duration_s().map(|d| (d * 1000.0).round() / 1000.0),
        });
        if let Some(e) = self.error_text() {
            v["error"] = e.into();
        }
        v
    }
}

/// One line per ERR/EXERR of `motion_homing::codes`.
pub fn explain(err: u16, exerr: u16) -> &'static str {
    use motion_homing::codes::*;
    match (err, exerr) {
        (ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST) => "homing terminated by a stop or disable",
        (ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN) => "axis in shutdown",
        (ERR_SERVO_MESSAGE, EX_DRIVE_FAULT) => "drive fault during homing",
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST) => "feedback lost (I/O process silent or gone)",
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_INVALID) => "invalid feedback (non-finite or absurd)",
        (ERR_SERVO_MESSAGE, EX_ENABLE_TIMEOUT) => "drive did not enable in time",
        (ERR_SERVO_MESSAGE, EX_OVERTRAVEL) => "hardware overtravel during homing",
        (ERR_ILLEGAL_HOMING_CONFIG, _) => "illegal homing configuration",
        (ERR_INTERRUPTED, _) => "homing interrupted externally",
        (ERR_TIMEOUT, _) => "home timeout exceeded",
        (ERR_SEARCH_LIMIT, _) => "search travelled beyond the search limit",
        _ => "error",
    }
}

fn opt(x: Option<f64>, width: usize) -> String {
    match x {
        Some(v) => format!("{v:>width$.4}"),
        None => format!("{:>width$}", "-"),
    }
}

pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<6}{:<8}{:<20}{:<24}{:>4}{:>4}{:>10}{:>7}{:>12}{:>12}{:>12}{:>9}\n",
        "axis",
        "mode",
        "sequence",
        "direction",
        "PC",
        "ER",
        "ERR/EXERR",
        "homed",
        "event raw",
        "final pos",
        "final raw",
        "time s"
    );
    for r in rows {
        let st = &r.snap.status;
        let b = |x: bool| if x { "1" } else { "0" };
        s += &format!(
            "{:<6}{:<8}{:<20}{:<24}{:>4}{:>4}{:>10}{:>7}{}{}{}{}\n",
            r.name,
            r.mode,
            r.sequence,
            r.direction,
            b(st.pc),
            b(st.er),
            format!("{}/{}", st.err, st.exerr),
            if st.homed { "yes" } else { "no" },
            opt(st.event_raw, 12),
            opt(r.snap.axis, 12),
            opt(r.snap.raw, 12),
            opt(r.duration_s(), 9),
        );
        if let Some(e) = r.error_text() {
            s += &format!("      └ {e}\n");
        }
    }
    s
}
