//! What the status table's getters read: one axis as the cycle's snapshot
//! holds it ([`AxisSnap`]: the engine's `Status` and the slot's facts), the
//! keeper's note about it ([`AxisNote`]), and both with the axis's
//! configuration and the snapshot's time ([`Source`]).
//!
//! Pure data, copied by the real-time thread into a preallocated snapshot
//! every 10 ms and read by the control thread, which fills the status frame
//! from it (`motion-supervisor`'s `status_fill`, off the cycle).

use motion_homing::{AxisConfig, Status};

/// Why HomedStatus was lost after a homing had set it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LostCause {
    /// Another reason (invalid or implausible feedback, a shutdown), or
    /// none known.
    #[default]
    Other,
    /// The feedback-loss rule tripped (or the I/O process detached).
    Feedback,
    /// The I/O process reconnected (restarted or attached again).
    Reconnect,
}

/// One axis as the reporting side sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisSnap {
    pub status: Status,
    /// Raw and axis position from the newest valid feedback.
    pub raw: Option<f64>,
    pub axis: Option<f64>,
    /// From the newest valid feedback.
    pub velocity: f64,
    pub torque: f64,
    pub switch: bool,
    pub marker: bool,
    pub enabled: bool,
    pub fault: bool,
    pub drive_error_code: u16,
    /// Fresh feedback this cycle.
    pub fresh: bool,
    pub cmd_position: f64,
    pub cmd_velocity: f64,
    pub enable: bool,
    /// Home requests the engine has been given (rising edges applied).
    pub homes_started: u32,
    /// The home sequence this axis was part of was aborted because this
    /// axis (index) failed.
    pub aborted_by: Option<u8>,
    /// The sequence's `timeout_ns` ran out and the axis was stopped.
    pub timed_out: bool,
    /// A gantry side: the largest skew of its gantry's last homing, units.
    pub skew: Option<f64>,
    /// A sequence has started, or will start, this axis.
    pub in_sequence: bool,
    /// A trace of this axis's next homing is armed or recording.
    pub traced: bool,
    /// HomedStatus was lost after the last homing succeeded: when (ns), and
    /// why.
    pub lost_homed_ns: Option<u64>,
    pub lost_cause: LostCause,
    /// The raw → axis offset while homed.
    pub offset: Option<f64>,
    /// HomedStatus comes from a stored reference (absolute axis, restored
    /// without motion), not from a homing run since start-up.
    pub restored: bool,
    /// The owner token of the setpoint stream that owns the axis (0: none).
    pub owner: u64,
    /// This cycle's command position in axis coordinates.
    pub cmd_axis: Option<f64>,
    /// The cycle monitor's trip in force (until a reset), and its trips
    /// since start: the control thread logs each one with its values.
    pub monitor: Option<motion_monitor::Trip>,
    pub monitor_trips: u32,
}

impl AxisSnap {
    /// Homing finished (either way) and the axis is at rest.
    pub fn settled(&self) -> bool {
        let s = &self.status;
        !s.ip && !s.stopping && (s.dn || s.er) && self.cmd_velocity == 0.0
    }
}

/// `AxisNote::warnings`: the last homing's event lay further than
/// `drift_limit` from the recent events of the axis.
pub const W_DRIFT: u8 = 1 << 1;
/// The last homing's switch-to-marker distance lay further than
/// `drift_limit` from the recent ones.
pub const W_SWITCH_DRIFT: u8 = 1 << 2;
/// The stored reference of this absolute axis was invalidated (the reason
/// is in the log and the homing record).
pub const W_REFERENCE_INVALIDATED: u8 = 1 << 3;

/// What the keeper (homing record, drift, stored references) says about an
/// axis beyond what its engine reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisNote {
    /// `W_*`.
    pub warnings: u8,
    /// With `W_DRIFT` / `W_SWITCH_DRIFT`: distance from the recent median.
    pub drift: f64,
}

impl Default for AxisNote {
    fn default() -> Self {
        Self {
            warnings: 0,
            drift: f64::NAN,
        }
    }
}

/// Everything a row's getter may read for one axis.
pub struct Source<'a> {
    /// The snapshot's axis.
    pub a: &'a AxisSnap,
    /// Its engine's status (`a.status`).
    pub status: &'a Status,
    /// Its configuration.
    pub cfg: &'a AxisConfig,
    pub note: &'a AxisNote,
    /// The snapshot's time, ns (monotonic).
    pub now_ns: u64,
}

impl<'a> Source<'a> {
    pub fn new(a: &'a AxisSnap, cfg: &'a AxisConfig, note: &'a AxisNote, now_ns: u64) -> Self {
        Self {
            a,
            status: &a.status,
            cfg,
            note,
            now_ns,
        }
    }

    /// Seconds between two monotonic times (0 if `to` is earlier).
    pub fn seconds(from_ns: u64, to_ns: u64) -> f64 {
        to_ns.saturating_sub(from_ns) as f64 * 1e-9
    }
}
