//! `status --json`: the live state of every axis and I/O process, as the
//! status service publishes it.

use crate::GapCounts;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AxisStatus {
    pub name: String,
    pub io: String,
    /// Homing phase by name (`idle`, `seek`, `return`, `move_home`, ...).
    pub phase: String,
    /// Axis HomingStatus / HomedStatus.
    pub homing: bool,
    pub homed: bool,
    /// The Home instruction's bits.
    pub en: bool,
    pub dn: bool,
    pub er: bool,
    pub ip: bool,
    pub pc: bool,
    pub err: u16,
    pub exerr: u16,
    /// Axis position (under the current reference) and raw position, units.
    pub position: Option<f64>,
    pub raw: Option<f64>,
    pub velocity: Option<f64>,
    /// % rated.
    pub torque: Option<f64>,
    /// Home switch actuated (logical, whatever the wiring).
    pub switch: bool,
    /// An index pulse passed in the last cycle / the marker latch holds a position.
    pub marker: bool,
    pub event_raw: Option<f64>,
    /// Homing time so far (or of the last homing) and its timeout (0 = none), s.
    pub elapsed_s: f64,
    pub timeout_s: f64,
    /// Distance travelled in the current search leg and the limit, units.
    pub search_travel: f64,
    pub search_limit: Option<f64>,
    pub enabled: bool,
    pub fault: bool,
    /// The drive's error code (CiA 402 0x603F) while it reports a fault.
    pub drive_error_code: u16,
    /// A gantry side: the skew of the gantry's last homing, units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skew: Option<f64>,
    /// HomedStatus comes from the stored reference of an absolute axis,
    /// applied at start-up without motion.
    #[serde(default)]
    pub restored: bool,
    /// The axis's drive is lost (its I/O process is alive and says so:
    /// the drive stopped answering, left operation or was power-cycled).
    #[serde(default)]
    pub drive_lost: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Warnings of the last homing (ambiguous marker, drift, invalidated
    /// stored reference).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// ServoActionStatus: enable requested and the drive reports enabled.
    #[serde(default)]
    pub servo_action: bool,
    /// JogStatus, MoveStatus, a setpoint stream commanding the axis.
    #[serde(default)]
    pub jogging: bool,
    #[serde(default)]
    pub moving: bool,
    #[serde(default)]
    pub streaming: bool,
    /// StoppingStatus: decelerating to rest (a stop, an abort, a limit).
    #[serde(default)]
    pub stopping: bool,
    /// The hardware overtravel limit switches.
    #[serde(default)]
    pub limit_negative: bool,
    #[serde(default)]
    pub limit_positive: bool,
    /// An axis fault is present: only `reset` clears it.
    #[serde(default)]
    pub faulted: bool,
    /// The program that owns the axis (setpoint stream), if any.
    #[serde(default)]
    pub owner: Option<String>,
    /// The last operation (enable, jog, move, ...).
    #[serde(default)]
    pub op: crate::OpReport,
    /// Why the last motion stopped: `none`, `operator`, `lease_expired`,
    /// `soft_limit`, `limit_switch`, `fault`, `feedback_lost`,
    /// `setpoint_refused`, `disable`, ...
    #[serde(default)]
    pub last_stop: String,
    /// The position commanded this cycle, axis coordinates (with
    /// `position`: the following error).
    #[serde(default)]
    pub command: Option<f64>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IoStatus {
    pub name: String,
    pub attached: bool,
    pub frames_received: u64,
    pub frames_missing: u64,
    pub frames_refused: u64,
    pub attachments: u64,
    pub gaps: GapCounts,
    /// Current gap (cycles without a fresh answer).
    pub gap_cycles: u64,
    /// A spawned I/O process: times the supervisor started it again.
    #[serde(default)]
    pub restarts: u32,
    /// A spawned I/O process waiting to be started again: in this many
    /// seconds (1 s doubling to 30 s while it keeps failing at start-up).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub retry_in_s: Option<f64>,
    /// A spawned I/O process: the error of its last failed start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_error: Option<String>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StatusReport {
    /// Cycle counter and cycle period of the supervisor.
    pub cycle: u64,
    pub cycle_us: u32,
    /// Milliseconds since the supervisor started.
    pub uptime_ms: u64,
    pub axes: Vec<AxisStatus>,
    pub io: Vec<IoStatus>,
    /// The setpoint stream's intake: frames, setpoints, refusals by kind.
    #[serde(default)]
    pub stream: crate::StreamIntake,
}
