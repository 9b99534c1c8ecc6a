//! What the address space holds, as tables: the variables of an axis (its
//! live ones are the status table's rows that have an OPC UA name, from
//! `motion_status::axis`), of an I/O process and of the latency
//! statistics, each with its type, unit kind and where its value comes
//! from. [`crate::nodes`] builds the nodes from these tables and
//! [`crate::values`] fills them, so a variable is named once.
//!
//! Node ids are strings in the namespace `urn:motion-supervisor`:
//! `Machine`, `Machine.Axes.X`, `Machine.Axes.X.HomedStatus`,
//! `Machine.Axes.X.Home`, `Machine.IO.bus0.Attached`,
//! `Machine.Latency.WakeUp.P99` — readable in any client, stable across
//! restarts. A `.` in an axis name stands as `%2E` ([`axis_key`]).

use motion_config::AxisEntry;
use motion_control::*;
use motion_status::axis::Reading;
use motion_status::{Row, Type, Unit};
use opcua::types::{DataTypeId, NodeId, Variant};
use std::sync::LazyLock;

/// The namespace of every node of ours (fixed: clients browse by it; docs/opcua.md).
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

/// A variable of an axis that follows the status frame. `None` from
/// [`LiveVar::read`] means "no valid value now" (no fresh feedback, nothing
/// latched): the variable's status turns Bad.
pub struct LiveVar {
    pub name: &'static str,
    pub data_type: DataTypeId,
    pub kind: Kind,
    /// A CIP enumeration shown as a MultiStateDiscrete variable: its
    /// `EnumStrings`, indexed by its number.
    pub enum_names: Option<Vec<&'static str>>,
    source: Source,
}

/// Where a live variable's value comes from.
enum Source {
    /// A row of the status table.
    Row(&'static Row),
    /// A text made from the entry (`names`: every axis's name).
    Text(fn(&AxisStatusEntry, &[String]) -> String),
}

impl LiveVar {
    /// The variable of a status table row.
    fn row(r: &'static Row) -> Option<Self> {
        let (data_type, enum_names) = match r.ty {
            Type::Flag => (DataTypeId::Boolean, None),
            Type::Value | Type::Maybe => (DataTypeId::Double, None),
            Type::U16 => (DataTypeId::UInt16, None),
            Type::U32 => (DataTypeId::UInt32, None),
            Type::Enum(_) => (DataTypeId::Byte, Some(r.ty.enum_names())),
        };
        let kind = match r.unit {
            Unit::None => Kind::Plain,
            Unit::Units => Kind::Position,
            Unit::UnitsPerSecond => Kind::Speed,
            Unit::Percent => Kind::Torque,
            Unit::Seconds => Kind::Seconds,
        };
        Some(Self {
            name: r.opcua?,
            data_type,
            kind,
            enum_names,
            source: Source::Row(r),
        })
    }

    fn text(name: &'static str, read: fn(&AxisStatusEntry, &[String]) -> String) -> Self {
        Self {
            name,
            data_type: DataTypeId::String,
            kind: Kind::Plain,
            enum_names: None,
            source: Source::Text(read),
        }
    }

    /// The value in entry `a` (`names`: every axis's name).
    pub fn read(&self, a: &AxisStatusEntry, names: &[String]) -> Option<Variant> {
        match &self.source {
            Source::Text(f) => Some(Variant::from(f(a, names))),
            Source::Row(r) => match (a.reading(r), r.ty) {
                (Reading::Flag(b), _) => Some(Variant::from(b)),
                (Reading::Number(x), _) => x.map(Variant::from),
                (Reading::Int(n), Type::U16) => Some(Variant::from(n as u16)),
                (Reading::Int(n), Type::Enum(_)) => Some(Variant::from(n as u8)),
                (Reading::Int(n), _) => Some(Variant::from(n)),
            },
        }
    }
}

/// Every live variable of an axis: each status table row with an OPC UA
/// name (named after the CIP attributes and bits), then the texts.
pub static AXIS_LIVE: LazyLock<Vec<LiveVar>> = LazyLock::new(|| {
    let rows = motion_status::axis::ROWS.iter().filter_map(LiveVar::row);
    rows.chain([
        LiveVar::text("Phase", |a, _| a.phase_text()),
        LiveVar::text("Message", |a, names| {
            a.error_text(names).unwrap_or_default()
        }),
        LiveVar::text("Warnings", |a, _| a.warning_texts().join("; ")),
    ])
    .collect()
});

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
    io_var!("FramesReceived", |i| Variant::from(
        i.counters.frames_received
    )),
    io_var!("FramesMissing", |i| Variant::from(
        i.counters.frames_missing
    )),
    io_var!("FramesRefused", |i| Variant::from(
        i.counters.frames_refused
    )),
    io_var!("Attachments", |i| Variant::from(i.counters.attachments)),
    io_var!("Gaps1", |i| Variant::from(i.counters.gaps.one)),
    io_var!("Gaps2To3", |i| Variant::from(i.counters.gaps.two_to_three)),
    io_var!("Gaps4To10", |i| Variant::from(i.counters.gaps.four_to_ten)),
    io_var!("GapsOver10", |i| Variant::from(i.counters.gaps.over_ten)),
    io_var!("LongestGapCycles", |i| Variant::from(
        i.counters.gaps.longest_cycles
    )),
    io_var!("GapCycles", |i| Variant::from(i.counters.gap_cycles)),
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
        let published = motion_status::axis::ROWS
            .iter()
            .filter(|r| r.opcua.is_some());
        assert_eq!(
            AXIS_LIVE.len(),
            published.count() + 3,
            "every named row, and the texts"
        );
        names.extend(AXIS_CONFIG.iter().map(|v| v.name));
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(n, names.len(), "a variable named twice");
        // The fixed names and types clients rely on (docs/opcua.md).
        for b in ["HomedStatus", "HomingStatus", "PC", "ER", "EN", "DN", "IP"] {
            let v = AXIS_LIVE.iter().find(|v| v.name == b).unwrap();
            assert_eq!(v.data_type, DataTypeId::Boolean, "{b}");
        }
        for i in ["ERR", "EXERR"] {
            let v = AXIS_LIVE.iter().find(|v| v.name == i).unwrap();
            assert_eq!(v.data_type, DataTypeId::UInt16, "{i}");
        }
        let modes = AXIS_LIVE.iter().find(|v| v.name == "HomeMode").unwrap();
        assert_eq!(
            modes.enum_names.as_deref(),
            Some(&["passive", "active", "absolute"][..])
        );
        for t in ["Phase", "Message", "Warnings"] {
            let v = AXIS_LIVE.iter().find(|v| v.name == t).unwrap();
            assert_eq!(v.data_type, DataTypeId::String, "{t}");
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
        let mut a = AxisStatusEntry::default();
        let pos = AXIS_LIVE
            .iter()
            .find(|v| v.name == "ActualPosition")
            .unwrap();
        assert!(pos.read(&a, &[]).is_none(), "no feedback: no value");
        let slot = AxisStatusEntry::row("position").unwrap().place as usize;
        a.values[slot] = 1.5;
        assert_eq!(pos.read(&a, &[]), Some(Variant::from(1.5)));
        a.values[slot] = f64::INFINITY;
        assert!(pos.read(&a, &[]).is_none(), "never a non-finite reading");
        let homed = AXIS_LIVE.iter().find(|v| v.name == "HomedStatus").unwrap();
        assert_eq!(homed.read(&a, &[]), Some(Variant::from(false)));
        a.flags = motion_status::axis::mask(&["homed"]);
        assert_eq!(homed.read(&a, &[]), Some(Variant::from(true)));
    }
}
