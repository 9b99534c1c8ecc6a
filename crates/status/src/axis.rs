//! **The status table**: every field of an axis's status, once. A new
//! status field is one row here (and, if the engine does not know it yet,
//! its source in `motion_homing::Status`); everything else follows:
//!
//! * the wire entry's place and accessor ([`AxisStatusEntry`]) and the
//!   filler ([`fill`], called by `motion-supervisor`'s `status_fill`);
//! * the layout description `python/motion_supervisor_client/layout.json`
//!   (written by `motion-control`'s `tests/wire_layout.rs`, which fails when
//!   it is stale), from which the Python package builds its classes and a
//!   property per row;
//! * `status --json`'s axis row ([`AxisStatus`], re-exported by
//!   `motion-report`), and `motionctl status`'s flags column (a row's mark);
//! * the OPC UA variables of `Objects/Machine/Axes/<axis>` (a row's browse
//!   name; `motion-opcua`'s `space.rs`);
//! * the docs page `docs/status.md` ([`crate::docs::markdown`], checked by a
//!   test).
//!
//! Columns: name, type and place (bit of `flags`, or slot of `ints` /
//! `values`), unit, JSON key, mark in `motionctl status` (`-`: none), OPC
//! UA browse name (`-`: none), and the getter from the cycle's snapshot.
//! Places are written out, never counted: a new row takes a free place and
//! moves nothing (the rule is in [`crate::schema`]). OPC UA names are the
//! CIP attributes and bits where CIP has one.

use crate::entry::AxisStatusEntry;
use crate::schema::{Area, Row};
use crate::snap::{LostCause, Source, W_DRIFT, W_REFERENCE_INVALIDATED, W_SWITCH_DRIFT};
use motion_homing::{effective_search_limit, HomeDirection, HomeMode, HomeSequence};
use motion_homing::{OpKind, StopCause};

/// `aborted_by` when no other axis aborted the axis's home sequence.
pub const NO_AXIS: u16 = u16::MAX;

crate::status_table! {
    entry AxisStatusEntry, source Source<'_>, json AxisStatus;

    /// EN: the Home instruction's request was seen (cleared when the
    /// request drops after DN or ER).
    en: Flag @ 0, None, "en", "EN", "EN", |s| s.status.en;
    /// DN: the Home instruction finished (completed, or aborted / errored).
    dn: Flag @ 1, None, "dn", "DN", "DN", |s| s.status.dn;
    /// ER: an error — of the Home instruction, or an axis fault (drive
    /// fault, limit switch, refused setpoint, lost feedback): `err` /
    /// `exerr` say which.
    er: Flag @ 2, None, "er", "ER", "ER", |s| s.status.er;
    /// IP: homing in process.
    ip: Flag @ 3, None, "ip", "IP", "IP", |s| s.status.ip;
    /// PC: process complete — homed, and at Home Position where the
    /// sequence moves there.
    pc: Flag @ 4, None, "pc", "PC", "PC", |s| s.status.pc;
    /// Axis HomingStatus: a homing runs.
    homing: Flag @ 5, None, "homing", -, "HomingStatus", |s| s.status.homing;
    /// Axis HomedStatus: the machine reference is established.
    homed: Flag @ 6, None, "homed", -, "HomedStatus", |s| s.status.homed;
    /// ServoActionStatus: enable requested and the drive reports enabled.
    servo_action: Flag @ 14, None, "servo_action", "S", "ServoActionStatus",
        |s| s.status.servo_action;
    /// JogStatus: a jog runs (until its stop begins).
    jogging: Flag @ 15, None, "jogging", "J", "JogStatus", |s| s.status.jogging;
    /// MoveStatus: a move runs (until its stop begins).
    moving: Flag @ 16, None, "moving", "M", "MoveStatus", |s| s.status.moving;
    /// A setpoint stream commands the axis.
    streaming: Flag @ 17, None, "streaming", "T", "StreamStatus", |s| s.status.streaming;
    /// StoppingStatus: decelerating to rest (a stop, an abort, a limit).
    stopping: Flag @ 12, None, "stopping", "x", "Stopping", |s| s.status.stopping;
    /// An axis fault is present (ER by a drive fault, a limit switch, a
    /// refused setpoint, lost feedback): only `reset` clears it.
    faulted: Flag @ 20, None, "faulted", "F", "AxisFault", |s| s.status.faulted;
    /// The negative hardware overtravel limit switch is tripped.
    limit_negative: Flag @ 18, None, "limit_negative", "-", "NegativeOvertravel",
        |s| s.status.limit_negative;
    /// The positive hardware overtravel limit switch is tripped.
    limit_positive: Flag @ 19, None, "limit_positive", "+", "PositiveOvertravel",
        |s| s.status.limit_positive;
    /// The home switch is actuated (logical, whatever the wiring).
    switch: Flag @ 9, None, "switch", "s", "HomeSwitch", |s| s.a.switch;
    /// A marker passed in the last cycle, or the marker latch holds a
    /// position.
    marker: Flag @ 10, None, "marker", "m", "Marker", |s| s.a.marker;
    /// The drive reports enabled (a lost drive never is).
    enabled: Flag @ 7, None, "enabled", -, "DriveEnabled",
        |s| s.a.enabled && !s.status.drive_lost;
    /// The drive reports a fault (`drive_error_code` says which).
    fault: Flag @ 8, None, "fault", -, "DriveFault", |s| s.a.fault;
    /// Valid feedback arrives: `position`, `raw`, `velocity` and `torque`
    /// have values.
    feedback: Flag @ 11, None, "feedback", -, -, |s| s.a.raw.is_some();
    /// A trace of the axis's next homing is armed or recording.
    traced: Flag @ 13, None, "traced", -, -, |s| s.a.traced;
    /// The last operation (enable, jog, move, ...) is in process.
    op_ip: Flag @ 21, None, "op_ip", -, -, |s| s.status.op.ip;
    /// The last operation ended as asked (a move at its target; a jog or
    /// stream ended normally).
    op_pc: Flag @ 22, None, "op_pc", -, -, |s| s.status.op.pc;
    /// The last operation asked for was refused (`op_err` / `op_exerr`).
    op_refused: Flag @ 23, None, "op_refused", -, -, |s| s.status.op.refused.is_some();
    /// The home request's timeout stopped the axis.
    timed_out: Flag @ 24, None, "timed_out", -, -, |s| s.a.timed_out;
    /// HomedStatus was lost after the axis last homed successfully.
    lost_homed: Flag @ 25, None, "lost_homed", -, -, |s| s.a.lost_homed_ns.is_some();
    /// A home sequence will start, or has started, the axis.
    in_sequence: Flag @ 26, None, "in_sequence", -, -, |s| s.a.in_sequence;
    /// With `lost_homed`: lost because its feedback was lost.
    lost_feedback: Flag @ 27, None, "lost_feedback", -, -,
        |s| s.a.lost_cause == LostCause::Feedback;
    /// With `lost_homed`: lost because its I/O process reconnected.
    lost_reconnect: Flag @ 28, None, "lost_reconnect", -, -,
        |s| s.a.lost_cause == LostCause::Reconnect;
    /// HomedStatus comes from the stored reference of an absolute axis,
    /// applied at start-up without motion.
    restored: Flag @ 29, None, "restored", -, "Restored", |s| s.a.restored;
    /// The independent cycle monitor stopped the axis (ERR 1021; EXERR
    /// names the invariant, the log the value against its bound); cleared
    /// by a reset.
    monitor_tripped: Flag @ 40, None, "monitor_tripped", -, "MonitorTripped",
        |s| s.a.monitor.is_some();
    /// The I/O process reports the axis's drive lost (it stopped answering
    /// on its fieldbus, left operation, or was power-cycled).
    drive_lost: Flag @ 30, None, "drive_lost", -, -, |s| s.status.drive_lost;
    /// Warning: the last homing's marker lay closer to the switch edge
    /// than `marker_min_distance` (which marker is taken is chance).
    warn_ambiguous_marker: Flag @ 31, None, "warn_ambiguous_marker", -, -,
        |s| s.status.ambiguous_marker;
    /// Warning: the last homing's event lay further than `drift_limit`
    /// from the recent events of the axis (`drift`).
    warn_drift: Flag @ 32, None, "warn_drift", -, -, |s| s.note.warnings & W_DRIFT != 0;
    /// Warning: the last homing's switch-to-marker distance lay further
    /// than `drift_limit` from the recent ones (`drift`).
    warn_switch_drift: Flag @ 33, None, "warn_switch_drift", -, -,
        |s| s.note.warnings & W_SWITCH_DRIFT != 0;
    /// Warning: the stored reference of this absolute axis was
    /// invalidated (the reason is in the log and the homing record).
    warn_reference_invalidated: Flag @ 34, None, "warn_reference_invalidated", -, -,
        |s| s.note.warnings & W_REFERENCE_INVALIDATED != 0;

    /// ERR of the error `er` shows (Logix motion error codes).
    err: U16 @ 0, None, "err", -, "ERR", |s| s.status.err;
    /// EXERR: the extended code of `err`.
    exerr: U16 @ 1, None, "exerr", -, "EXERR", |s| s.status.exerr;
    /// The drive's error code (CiA 402 0x603F) while it reports a fault.
    drive_error_code: U16 @ 2, None, "drive_error_code", -, "DriveErrorCode",
        |s| s.a.drive_error_code;
    /// Home Mode (CIP: 0 passive, 1 active, 2 absolute).
    home_mode: Enum<HomeMode> @ 3, None, "home_mode", -, "HomeMode", |s| s.cfg.home_mode;
    /// Home Sequence (CIP numbering).
    home_sequence: Enum<HomeSequence> @ 4, None, "home_sequence", -, "HomeSequence",
        |s| s.cfg.home_sequence;
    /// Home Direction (CIP numbering).
    home_direction: Enum<HomeDirection> @ 5, None, "home_direction", -, "HomeDirection",
        |s| s.cfg.home_direction;
    /// Index of the axis whose failure aborted this axis's home sequence
    /// (65535: none).
    aborted_by: U16 @ 6, None, "aborted_by", -, -,
        |s| s.a.aborted_by.map_or(NO_AXIS, u16::from);
    /// The last operation's id (the answer to its request names it).
    op_id: U32 @ 7, None, "op_id", -, -, |s| s.status.op.id;
    /// ERR of the last operation's refusal (0: accepted).
    op_err: U16 @ 8, None, "op_err", -, -, |s| s.status.op.refused.map_or(0, |r| r.0);
    /// EXERR of the last operation's refusal.
    op_exerr: U16 @ 9, None, "op_exerr", -, -, |s| s.status.op.refused.map_or(0, |r| r.1);
    /// The last operation's kind (`enable`, `jog`, `move`, ...; `none`).
    op_kind: Enum<OpKind> @ 10, None, "op_kind", -, -, |s| s.status.op.kind;
    /// Why the last motion stopped: `none`, `operator`, `lease_expired`,
    /// `soft_limit`, `limit_switch`, `drive_fault`, `feedback_lost`, ...
    last_stop: Enum<StopCause> @ 11, None, "last_stop", -, -, |s| s.status.last_stop;

    /// Axis position under the current reference (with valid feedback).
    position: Maybe @ 0, Units, "position", -, "ActualPosition", |s| s.a.raw.and(s.a.axis);
    /// Raw position: the drive's, in units (with valid feedback).
    raw: Maybe @ 1, Units, "raw", -, "RawPosition", |s| s.a.raw;
    /// Actual velocity (with valid feedback).
    velocity: Maybe @ 2, UnitsPerSecond, "velocity", -, "ActualVelocity",
        |s| s.a.raw.map(|_| s.a.velocity);
    /// Actual torque (with valid feedback).
    torque: Maybe @ 3, Percent, "torque", -, "ActualTorque", |s| s.a.raw.map(|_| s.a.torque);
    /// Raw position of the home event, once found.
    event_raw: Maybe @ 4, Units, "event_raw", -, "EventPosition", |s| s.status.event_raw;
    /// Time in the current (or last) homing.
    elapsed_s: Value @ 5, Seconds, "elapsed_s", -, "HomingElapsed", |s| {
        let end = s.status.finished_ns.unwrap_or(s.now_ns);
        let homed_once = s.a.homes_started > 0;
        if homed_once { Source::seconds(s.status.started_ns, end) } else { 0.0 }
    };
    /// The homing's timeout (`home_timeout`; 0: none).
    timeout_s: Value @ 6, Seconds, "timeout_s", -, -, |s| s.cfg.home_timeout;
    /// Distance travelled in the current (or last) search leg.
    search_travel: Value @ 7, Units, "search_travel", -, -, |s| s.status.search_travel;
    /// The search leg's limit (none: unbounded).
    search_limit: Maybe @ 8, Units, "search_limit", -, -,
        |s| Some(effective_search_limit(s.cfg)).filter(|l| l.is_finite() && *l > 0.0);
    /// With `lost_homed`: seconds after homing ended that HomedStatus was
    /// lost.
    lost_after_s: Value @ 9, Seconds, "lost_after_s", -, -,
        |s| match (s.a.lost_homed_ns, s.status.finished_ns) {
            (Some(lost), Some(ended)) => Source::seconds(ended, lost),
            _ => 0.0,
        };
    /// A gantry side: the largest skew of its gantry's last homing (how far
    /// apart the sides found their events).
    skew: Maybe @ 10, Units, "skew", -, -, |s| s.a.skew;
    /// How long the feedback had been missing when the feedback-loss rule
    /// tripped (ERR 12 / EXERR 40, or HomedStatus lost); 0 otherwise.
    feedback_gap_s: Value @ 11, Seconds, "feedback_gap_s", -, -,
        |s| s.status.lost_after_ns.map_or(0.0, |g| g as f64 * 1e-9);
    /// With `warn_drift` / `warn_switch_drift`: how far from the median of
    /// the recent homings.
    drift: Maybe @ 12, Units, "drift", -, -, |s| Some(s.note.drift);
    /// Switch then marker: the distance from the switch edge to the marker
    /// of the last homing.
    switch_to_marker: Maybe @ 13, Units, "switch_to_marker", -, -,
        |s| s.status.switch_edge_raw.zip(s.status.event_raw).map(|(sw, ev)| (ev - sw).abs());
    /// The position commanded this cycle, axis coordinates (with
    /// `position`: the following error).
    cmd_position: Maybe @ 14, Units, "command", -, "CommandPosition", |s| s.a.cmd_axis;
    /// The negative software travel limit in axis coordinates while it
    /// applies (homed, linear, `travel_limits`): after a redefine position
    /// its number moves with the positions, its place on the machine does
    /// not.
    soft_limit_negative: Maybe @ 16, Units, "soft_limit_negative", -, "SoftLimitNegative",
        |s| s.status.soft_limits.map(|l| l.0);
    /// The positive software travel limit, as `soft_limit_negative`.
    soft_limit_positive: Maybe @ 17, Units, "soft_limit_positive", -, "SoftLimitPositive",
        |s| s.status.soft_limits.map(|l| l.1);
    /// A registration (MAR, `arm`) is armed: the next edge of its input
    /// will be latched.
    registration_armed: Flag @ 36, None, "registration_armed", "r", "RegistrationArmed",
        |s| s.status.registration_armed;
    /// Axis position of the edge the last registration latched (none from
    /// an arming until it latched).
    registration_position: Maybe @ 15, Units, "registration_position", -,
        "RegistrationPosition", |s| s.status.registration_position;
    /// GearingStatus: the axis follows its master (MAG), from the accepted
    /// gear until its stop begins.
    gearing: Flag @ 35, None, "gearing", "G", "GearingStatus", |s| s.status.gearing;
}

/// The rows that say the axis is in motion by an operation (a jog, a
/// move, a stream, a gear); [`motion_mask`] is their bits.
pub const IN_MOTION: &[&str] = &["jogging", "moving", "streaming", "gearing"];

/// The `flags` bits of the rows `names`.
pub fn mask(names: &[&str]) -> u64 {
    ROWS.iter()
        .filter(|r| names.contains(&r.name))
        .fold(0, |m, r| m | 1u64 << r.place)
}

/// The bits of [`IN_MOTION`].
pub fn motion_mask() -> u64 {
    mask(IN_MOTION)
}

/// A row's value in an entry, by the row's type (for the layers that walk
/// the table: OPC UA).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reading {
    Flag(bool),
    /// A number; `None`: no value (a NaN or infinite one is none either).
    Number(Option<f64>),
    /// An integer or an enumeration's number.
    Int(u32),
}

impl AxisStatusEntry {
    /// The value of `row` in this entry.
    pub fn reading(&self, row: &Row) -> Reading {
        let p = row.place as usize;
        match row.ty.area() {
            Area::Flags => Reading::Flag(p < 64 && self.flags >> p & 1 != 0),
            Area::Ints => Reading::Int(self.ints.get(p).copied().unwrap_or(0)),
            Area::Values => Reading::Number(self.values.get(p).copied().filter(|v| v.is_finite())),
        }
    }

    /// An operation moves the axis (a jog, a move or a stream runs).
    pub fn in_motion(&self) -> bool {
        self.flags & motion_mask() != 0
    }

    /// Which operation moves the axis, by its row's name (`jogging`,
    /// `moving`, `streaming`), if one does.
    pub fn in_motion_as(&self) -> Option<&'static str> {
        IN_MOTION
            .iter()
            .copied()
            .find(|n| self.flags & mask(&[n]) != 0)
    }

    /// The row named `name`.
    pub fn row(name: &str) -> Option<&'static Row> {
        ROWS.iter().find(|r| r.name == name)
    }
}
