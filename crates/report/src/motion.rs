//! `move --json` and `stream --json`: one row per axis, how its operation
//! ended.

use serde::{Deserialize, Serialize};

/// How one axis's move or stream ended.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MotionRow {
    pub name: String,
    /// The operation ended as asked: the move at its target, the stream
    /// released normally.
    pub pc: bool,
    /// An error: the operation was refused, or an axis fault stopped it.
    pub er: bool,
    pub err: u16,
    pub exerr: u16,
    /// Axis position at the end, units.
    pub position: Option<f64>,
    /// `stream`: the largest following error seen (command − actual, from
    /// the 100 Hz status), and the last setpoint − the final position,
    /// units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub following_error_max: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub final_error: Option<f64>,
    /// What went wrong, in words (absent when nothing did).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// `move --json`, `stream --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MotionReport {
    pub axes: Vec<MotionRow>,
}

impl MotionReport {
    /// Every axis ended as asked.
    pub fn succeeded(&self) -> bool {
        !self.axes.is_empty() && self.axes.iter().all(|r| r.pc && !r.er)
    }
}

/// One axis's latched registration (`arm --json`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RegistrationRow {
    pub name: String,
    /// Axis position of the latched edge, units (null: none latched — the
    /// registration was disarmed, or a homing started).
    pub position: Option<f64>,
}

/// `arm --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RegistrationReport {
    pub axes: Vec<RegistrationRow>,
}
