//! What the address space holds, as tables: the variables of an axis, of an
//! I/O process and of the latency statistics, each with its type, unit kind
//! and where its value comes from. [`crate::nodes`] builds the nodes from
//! these tables and [`crate::values`] fills them, so a variable is named
//! once.
//!
//! Node ids are strings in the namespace `urn:motion-supervisor`:
//! `Machine`, `Machine.Axes.X`, `Machine.Axes.X.HomedStatus`,
//! `Machine.Axes.X.Home`, `Machine.IO.bus0.Attached`,
//! `Machine.Latency.WakeUp.P99` — readable in any client, stable across
//! restarts. A `.` in an axis name stands as `%2E` ([`axis_key`]).

use motion_config::AxisEntry;
use motion_control::*;
use opcua::types::{DataTypeId, NodeId, Variant};

/// The namespace of every node of ours (interface.md).
pub const NAMESPACE_URI: &str = "urn:motion-supervisor";

/// `Machine` and below.
pub fn id(ns: u16, path: &str) -> NodeId {
    NodeId::new(ns, path.to_string())
}

/// An axis name as it stands in node ids: `.` (allowed in axis names, and
/// the separator of node ids) as `%2E` — `%` is not allowed in names, so
/// axes `X` and `X.Home` can never share the id `Machine.Axes.X.Home` with
/// a method of `X`. Names without a dot are unchanged.
pub fn axis_key(axis: &str) -> String {
    axis.replace('.', "%2E")
}

/// `Machine.Axes.<axis key>`: the axis object's id, and the prefix of its
/// variables' and methods'.
pub fn axis_path(axis: &str) -> String {
    format!("Machine.Axes.{}", axis_key(axis))
}

pub fn axis_id(ns: u16, axis: &str) -> NodeId {
    id(ns, &axis_path(axis))
}

pub fn axis_var_id(ns: u16, axis: &str, var: &str) -> NodeId {
    id(ns, &format!("{}.{var}", axis_path(axis)))
}

pub fn io_var_id(ns: u16, io: &str, var: &str) -> NodeId {
    id(ns, &format!("Machine.IO.{io}.{var}"))
}

/// What a number measures, for its engineering unit ([`crate::units`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// No unit (booleans, codes, counts, text).
    Plain,
    /// Axis units.
    Position,
    /// Axis units per second.
    Speed,
    /// Axis units per second².
    Acceleration,
    /// % of rated torque.
    Torque,
    /// Seconds.
    Seconds,
    /// Microseconds.
    Micros,
}

/// A CIP enumeration shown as a MultiStateDiscrete variable (its
/// `EnumStrings` give the names).
pub type EnumNames = &'static [&'static str];

pub const HOME_MODES: EnumNames = &["passive", "active", "absolute"];
pub const HOME_SEQUENCES: EnumNames = &[
    "immediate",
    "switch",
    "marker",
    "switch_then_marker",
    "torque",
    "torque_then_marker",
];
pub const HOME_DIRECTIONS: EnumNames = &[
    "unidirectional_forward",
    "bidirectional_forward",
    "unidirectional_reverse",
    "bidirectional_reverse",
];

/// A variable of an axis that follows the status frame. `None` from
/// `read` means "no valid value now" (no fresh feedback): the variable's
/// status turns Bad.
pub struct LiveVar {
    pub name: &'static str,
    pub data_type: DataTypeId,
    pub kind: Kind,
    pub enum_names: Option<EnumNames>,
    pub read: fn(&AxisStatusEntry, &[String]) -> Option<Variant>,
}

fn bit(a: &AxisStatusEntry, b: u16) -> Option<Variant> {
    Some(Variant::from(a.has(b)))
}

fn fb(a: &AxisStatusEntry, x: f64) -> Option<Variant> {
    (a.has(ST_FEEDBACK) && x.is_finite()).then_some(Variant::from(x))
}

macro_rules! live {
    ($name:literal, Boolean, $bit:ident) => {
        LiveVar {
            name: $name,
            data_type: DataTypeId::Boolean,
            kind: Kind::Plain,
            enum_names: None,
            read: |a, _| bit(a, $bit),
        }
    };
    ($name:literal, $dt:ident, $kind:ident, $read:expr) => {
        LiveVar {
            name: $name,
            data_type: DataTypeId::$dt,
            kind: Kind::$kind,
            enum_names: None,
            read: $read,
        }
    };
    ($name:literal, enum $names:ident, $read:expr) => {
        LiveVar {
            name: $name,
            data_type: DataTypeId::Byte,
            kind: Kind::Plain,
            enum_names: Some($names),
            read: $read,
        }
    };
}

/// Every live variable of an axis, named after the CIP attributes and bits.
pub const AXIS_LIVE: &[LiveVar] = &[
    live!("HomingStatus", Boolean, ST_HOMING),
    live!("HomedStatus", Boolean, ST_HOMED),
    live!("EN", Boolean, ST_EN),
    live!("DN", Boolean, ST_DN),
    live!("ER", Boolean, ST_ER),
    live!("IP", Boolean, ST_IP),
    live!("PC", Boolean, ST_PC),
    live!("ERR", UInt16, Plain, |a, _| Some(Variant::from(a.err))),
    live!("EXERR", UInt16, Plain, |a, _| Some(Variant::from(a.exerr))),
    live!("Phase", String, Plain, |a, _| Some(Variant::from(get_str(
        &a.phase
    )))),
    live!("ActualPosition", Double, Position, |a, _| fb(a, a.position)),
    live!("RawPosition", Double, Position, |a, _| fb(a, a.raw)),
    live!("ActualVelocity", Double, Speed, |a, _| fb(a, a.velocity)),
    live!("ActualTorque", Double, Torque, |a, _| fb(a, a.torque)),
    live!("HomeSwitch", Boolean, ST_SWITCH),
    live!("Marker", Boolean, ST_MARKER),
    live!("DriveEnabled", Boolean, ST_ENABLED),
    live!("DriveFault", Boolean, ST_FAULT),
    live!("DriveErrorCode", UInt16, Plain, |a, _| Some(Variant::from(
        a.drive_error_code
    ))),
    live!("Stopping", Boolean, ST_STOPPING),
    live!("EventPosition", Double, Position, |a, _| {
        (a.has(ST_EVENT) && a.event_raw.is_finite()).then_some(Variant::from(a.event_raw))
    }),
    live!("HomingElapsed", Double, Seconds, |a, _| Some(
        Variant::from(a.elapsed_s)
    )),
    live!("Restored", Boolean, Plain, |a, _| Some(Variant::from(
        a.extra & SX_RESTORED != 0
    ))),
    live!("Message", String, Plain, |a, names| Some(Variant::from(
        a.error_text(names).unwrap_or_default()
    ))),
    live!("Warnings", String, Plain, |a, _| Some(Variant::from(
        a.warning_texts().join("; ")
    ))),
    live!("HomeMode", enum HOME_MODES, |a, _| Some(Variant::from(a.home_mode))),
    live!("HomeSequence", enum HOME_SEQUENCES, |a, _| Some(Variant::from(a.home_sequence))),
    live!("HomeDirection", enum HOME_DIRECTIONS, |a, _| Some(Variant::from(a.home_direction))),
    // The operations' status (issue 15): MSO/MAJ/MAM's bits, the limit
    // switches, the commanded position.
    live!("ServoActionStatus", Boolean, Plain, |a, _| motion(
        a,
        MS_SERVO_ACTION
    )),
    live!("JogStatus", Boolean, Plain, |a, _| motion(a, MS_JOGGING)),
    live!("MoveStatus", Boolean, Plain, |a, _| motion(a, MS_MOVING)),
    live!("StreamStatus", Boolean, Plain, |a, _| motion(
        a,
        MS_STREAMING
    )),
    live!("AxisFault", Boolean, Plain, |a, _| motion(a, MS_FAULTED)),
    live!("NegativeOvertravel", Boolean, Plain, |a, _| motion(
        a,
        MS_LIMIT_NEGATIVE
    )),
    live!("PositiveOvertravel", Boolean, Plain, |a, _| motion(
        a,
        MS_LIMIT_POSITIVE
    )),
    live!("CommandPosition", Double, Position, |a, _| {
        (a.motion & MS_COMMAND != 0 && a.cmd_position.is_finite())
            .then_some(Variant::from(a.cmd_position))
    }),
];

fn motion(a: &AxisStatusEntry, bit: u16) -> Option<Variant> {
    Some(Variant::from(a.motion & bit != 0))
}

/// A configured attribute of an axis (from the machine config, which the
/// daemon runs with; constant while it runs).
pub struct ConfigVar {
    pub name: &'static str,
    pub kind: Kind,
    pub read: fn(&AxisEntry) -> f64,
}

macro_rules! cfg_var {
    ($name:literal, $kind:ident, $field:ident) => {
        ConfigVar {
            name: $name,
            kind: Kind::$kind,
            read: |a| a.engine.$field,
        }
    };
}

pub const AXIS_CONFIG: &[ConfigVar] = &[
    cfg_var!("HomePosition", Position, home_position),
    cfg_var!("HomeOffset", Position, home_offset),
    cfg_var!("HomeSpeed", Speed, home_speed),
    cfg_var!("HomeReturnSpeed", Speed, home_return_speed),
    cfg_var!("HomeCreepSpeed", Speed, home_creep_speed),
    cfg_var!("HomeAcceleration", Acceleration, home_acceleration),
    cfg_var!("HomeDeceleration", Acceleration, home_deceleration),
    cfg_var!("HomeTorqueLevel", Torque, home_torque_level),
    cfg_var!("HomeTorqueThreshold", Torque, home_torque_threshold),
    cfg_var!("HomeTorqueTime", Seconds, home_torque_time),
    cfg_var!("HomeTimeout", Seconds, home_timeout),
];

/// A variable of an I/O process.
pub struct IoVar {
    pub name: &'static str,
    pub data_type: DataTypeId,
    pub read: fn(&IoStatusEntry) -> Variant,
}

macro_rules! io_var {
    ($name:literal, $read:expr) => {
        IoVar {
            name: $name,
            data_type: DataTypeId::UInt64,
            read: $read,
        }
    };
}

pub const IO_VARS: &[IoVar] = &[
    IoVar {
        name: "Attached",
        data_type: DataTypeId::Boolean,
        read: |i| Variant::from(i.attached != 0),
    },
    io_var!("FramesReceived", |i| Variant::from(i.frames_received)),
    io_var!("FramesMissing", |i| Variant::from(i.frames_missing)),
    io_var!("FramesRefused", |i| Variant::from(i.frames_refused)),
    io_var!("Attachments", |i| Variant::from(i.attachments)),
    io_var!("Gaps1", |i| Variant::from(i.gaps[0])),
    io_var!("Gaps2To3", |i| Variant::from(i.gaps[1])),
    io_var!("Gaps4To10", |i| Variant::from(i.gaps[2])),
    io_var!("GapsOver10", |i| Variant::from(i.gaps[3])),
    io_var!("LongestGapCycles", |i| Variant::from(i.longest_gap_cycles)),
    io_var!("GapCycles", |i| Variant::from(i.gap_cycles)),
];

/// The latency series (`Machine.Latency.<series>.<column>`, µs) and their
/// columns, in the order of `motionctl stats`.
pub const LATENCY_SERIES: [&str; 3] = ["WakeUp", "Compute", "RoundTrip"];
pub const LATENCY_COLUMNS: [&str; 6] = ["Min", "P50", "P99", "P999", "P9999", "Max"];
/// Counters beside them (`Machine.Latency.<name>`).
pub const LATENCY_COUNTERS: [&str; 3] = ["Cycles", "DeadlineMisses", "LateReplies"];

/// Machine-wide variables (`Machine.<name>`).
pub const MACHINE_VARS: [(&str, DataTypeId); 4] = [
    ("Connected", DataTypeId::Boolean),
    ("Cycle", DataTypeId::UInt64),
    ("CycleTime", DataTypeId::UInt32),
    ("Uptime", DataTypeId::Double),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_cover_the_spec() {
        let mut names: Vec<&str> = AXIS_LIVE.iter().map(|v| v.name).collect();
        names.extend(AXIS_CONFIG.iter().map(|v| v.name));
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(n, names.len(), "a variable named twice");
        // interface.md: these names, these types.
        for b in ["HomedStatus", "HomingStatus", "PC", "ER", "EN", "DN", "IP"] {
            let v = AXIS_LIVE.iter().find(|v| v.name == b).unwrap();
            assert_eq!(v.data_type, DataTypeId::Boolean, "{b}");
        }
        for i in ["ERR", "EXERR"] {
            let v = AXIS_LIVE.iter().find(|v| v.name == i).unwrap();
            assert_eq!(v.data_type, DataTypeId::UInt16, "{i}");
        }
        for d in ["ActualPosition", "ActualVelocity"] {
            let v = AXIS_LIVE.iter().find(|v| v.name == d).unwrap();
            assert_eq!(v.data_type, DataTypeId::Double, "{d}");
        }
        assert!(names.contains(&"HomePosition"));
    }

    #[test]
    fn axis_names_with_dots_keep_node_ids_apart() {
        let ns = 2;
        let mut ids = Vec::new();
        for axis in ["X", "X.Home", "X.HomedStatus", "gantry.left", "X.Home.Stop"] {
            ids.push(axis_id(ns, axis));
            for v in AXIS_LIVE.iter().map(|v| v.name) {
                ids.push(axis_var_id(ns, axis, v));
            }
            for m in crate::methods::methods() {
                ids.push(id(ns, &format!("{}.{}", axis_path(axis), m.name)));
            }
        }
        let n = ids.len();
        ids.sort_by_key(|i| i.to_string());
        ids.dedup();
        assert_eq!(n, ids.len(), "two nodes share an id");
        assert_eq!(axis_id(ns, "X").to_string(), "ns=2;s=Machine.Axes.X");
        assert_eq!(
            axis_var_id(ns, "gantry.left", "ER").to_string(),
            "ns=2;s=Machine.Axes.gantry%2Eleft.ER"
        );
    }

    #[test]
    fn feedback_values_need_fresh_feedback() {
        let mut a = AxisStatusEntry {
            position: 1.5,
            ..Default::default()
        };
        let pos = AXIS_LIVE
            .iter()
            .find(|v| v.name == "ActualPosition")
            .unwrap();
        assert!((pos.read)(&a, &[]).is_none());
        a.bits |= ST_FEEDBACK;
        assert_eq!((pos.read)(&a, &[]), Some(Variant::from(1.5)));
        a.position = f64::NAN;
        assert!((pos.read)(&a, &[]).is_none(), "never a NaN reading");
    }
}
