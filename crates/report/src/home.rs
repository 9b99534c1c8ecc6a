//! `home --json` (fixed keys: docs/commands.md, "JSON") and `run --json`.

use crate::{ErrorEntry, IoReport, Latency};
use serde::{Deserialize, Serialize};

/// The result of homing one axis: a row of `home --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AxisResult {
    pub name: String,
    pub mode: String,
    pub sequence: String,
    pub direction: String,
    /// The I/O process that drives the axis.
    #[serde(default)]
    pub io: String,
    pub pc: bool,
    pub er: bool,
    pub err: u16,
    pub exerr: u16,
    /// HomedStatus when homing ended (and, for `home`, still at the end of
    /// the run: an axis that set PC and then lost its reference reads false).
    pub homed: bool,
    /// Raw position of the home event as the supervisor determined it.
    pub event_raw: Option<f64>,
    /// Axis position after homing.
    pub final_position: Option<f64>,
    /// Raw position at the end.
    pub final_raw: Option<f64>,
    pub duration_s: Option<f64>,
    /// What went wrong, in words (absent when nothing did).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// A gantry side: how far apart the gantry's sides found their events
    /// (the largest skew of the homing), units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skew: Option<f64>,
    /// Warnings that do not fail homing (ambiguous marker, drift, ...).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

impl AxisResult {
    /// Homed successfully and still homed: what `home`'s exit code requires.
    pub fn succeeded(&self) -> bool {
        self.pc && self.homed && !self.er
    }
}

/// Real-time settings the thread actually got.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RtInfo {
    pub cpu: Option<usize>,
    pub policy: String,
    pub priority: i32,
    pub memory_locked: bool,
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// System-allocator calls made by the cycle after warm-up (must be 0) and
/// the allocations its own pool served (iceoryx2's per-sample `Rc`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Allocations {
    pub system_calls_in_cycle: u64,
    pub pool_allocs_in_cycle: u64,
}

/// CPU use as a share of one core over the run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CpuUse {
    pub supervisor: Option<f64>,
    /// Per I/O process started by the supervisor, by name.
    #[serde(default)]
    pub io: Vec<(String, Option<f64>)>,
    pub wall_s: f64,
}

/// `motion-supervisor home --json`: the rows, then what `run --json` says
/// of the run (its fields follow `axes` at the same level).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HomeReport {
    pub axes: Vec<AxisResult>,
    #[serde(flatten)]
    pub run: RunReport,
}

/// `motion-supervisor run --json` (printed when the daemon ends), and the
/// part of `home --json` after the rows.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunReport {
    pub latency: Latency,
    #[serde(default)]
    pub io: Vec<IoReport>,
    pub rt: Option<RtInfo>,
    #[serde(default)]
    pub warnings: Vec<String>,
    #[serde(default)]
    pub allocations: Allocations,
    #[serde(default)]
    pub cpu: CpuUse,
    /// Problems that ended the run early (I/O process gone, signal, ...).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub errors: Vec<ErrorEntry>,
}

/// `motionctl home --json`: rows as in `motion-supervisor home --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CtlHomeReport {
    pub axes: Vec<AxisResult>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub errors: Vec<ErrorEntry>,
}

/// `motionctl stats --json`: latency since the daemon started or since the
/// last reset.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StatsReport {
    /// `"start"` or `"reset"`.
    pub since: String,
    /// Seconds covered.
    pub seconds: f64,
    pub latency: Latency,
    #[serde(default)]
    pub io: Vec<IoReport>,
    #[serde(default)]
    pub allocations: Allocations,
    /// Control requests refused (wrong key or layout) since start.
    #[serde(default)]
    pub requests_refused: u64,
}

/// `motion-supervisor check --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CheckReport {
    /// Where the config came from.
    pub source: String,
    pub cycle_us: u32,
    pub axes: Vec<String>,
    pub io: Vec<String>,
    /// Advice about the axes (not errors).
    #[serde(default)]
    pub notes: Vec<String>,
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The real-time environment checklist.
    #[serde(default)]
    pub environment: Vec<String>,
    /// Empty when the config is valid.
    pub errors: Vec<ErrorEntry>,
    /// Per axis: the bounds the operations around homing run within.
    #[serde(default)]
    pub operations: Vec<AxisOperationLimits>,
}

/// One axis's bounds of the operations around homing (jog, move, the
/// setpoint stream), each default resolved, as `check` shows them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AxisOperationLimits {
    pub axis: String,
    /// False for a feedback-only axis: nothing to enable or move (the
    /// other fields mean nothing then).
    pub movable: bool,
    /// `travel_limits` as enforced while homed; `None`: none (not set, or a
    /// cyclic axis).
    pub soft_limits: Option<[f64; 2]>,
    /// `max_speed`, or the one derived from the homing speeds; `None`:
    /// none known (jog, move and stream are refused: 13 / 7).
    pub max_speed: Option<f64>,
    pub unhomed_speed: f64,
    pub max_deceleration: f64,
    pub limit_switches: bool,
    pub stream_acceleration: f64,
    pub stream_timeout_ms: f64,
    pub stream_unhomed: bool,
}

/// `motionctl stop|unhome --json`, `motionctl home --no-wait --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AcceptedReport {
    pub accepted: Vec<String>,
}

/// `motionctl trace --json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TraceReport {
    pub axis: String,
    /// Cycles recorded.
    pub cycles: usize,
    /// Seconds the homing took.
    pub duration_s: f64,
    /// Raw position of the home event, if one was found.
    pub event_raw: Option<f64>,
    pub csv: String,
    pub plot: Option<String>,
}
