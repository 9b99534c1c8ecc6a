//! Builds the address space from the machine config and the tables of
//! [`crate::space`] and [`crate::methods`]:
//!
//! ```text
//! Objects/Machine                      Connected, Cycle, CycleTime, Uptime; HomeAll, StopAll
//! Objects/Machine/Axes/<axis>          live variables, configured attributes; Home, Stop, Unhome
//! Objects/Machine/IO/<io>              Attached, frames, gaps
//! Objects/Machine/Latency              Cycles, DeadlineMisses, LateReplies
//! Objects/Machine/Latency/<series>     Min, P50, P99, P999, P9999, Max (µs)
//! Types/…/BaseEventType/AxisErrorEventType   ERR, EXERR, Axis
//! ```

use crate::events::AxisErrorEventType;
use crate::methods::{output_args, ArgSpec, Scope, METHODS};
use crate::space::*;
use crate::units;
use motion_config::opcua::OpcuaConfig;
use motion_config::MachineConfig;
use opcua::server::address_space::{
    AccessLevel, AddressSpace, EventNotifier, MethodBuilder, ObjectBuilder, ObjectTypeBuilder,
    VariableBuilder,
};
use opcua::types::{
    Argument, DataTypeId, DataValue, ExtensionObject, LocalizedText, NodeId, ObjectId,
    ObjectTypeId, QualifiedName, StatusCode, UAString, VariableTypeId, Variant,
};

/// Adds every node of the machine.
pub fn build(space: &mut AddressSpace, ns: u16, m: &MachineConfig, cfg: &OpcuaConfig) {
    let machine = id(ns, "Machine");
    ObjectBuilder::new(&machine, QualifiedName::new(ns, "Machine"), "Machine")
        .description("the machine motion-supervisor runs (its axes, I/O processes, latency)")
        .event_notifier(EventNotifier::SUBSCRIBE_TO_EVENTS)
        .organized_by(ObjectId::ObjectsFolder)
        .has_type_definition(ObjectTypeId::BaseObjectType)
        .insert(space);
    for (name, dt) in MACHINE_VARS {
        variable(
            space,
            ns,
            &machine,
            &format!("Machine.{name}"),
            name,
            dt,
            None,
        );
    }
    methods(space, ns, &machine, "Machine", Scope::Machine);
    event_type(space, ns);

    let axes = id(ns, "Machine.Axes");
    folder(space, ns, &axes, "Axes", &machine);
    for a in &m.axes {
        let obj = axis_id(ns, &a.name);
        ObjectBuilder::new(
            &obj,
            QualifiedName::new(ns, a.name.as_str()),
            a.name.as_str(),
        )
        .description(format!(
            "axis {} (I/O process {})",
            a.name, m.ios[a.io].name
        ))
        .event_notifier(EventNotifier::SUBSCRIBE_TO_EVENTS)
        .organized_by(axes.clone())
        .has_type_definition(ObjectTypeId::BaseObjectType)
        .insert(space);
        let unit = cfg.unit_of(&a.name);
        for v in AXIS_LIVE.iter() {
            let vid = axis_var_id(ns, &a.name, v.name);
            variable(space, ns, &obj, &vid_path(&vid), v.name, v.data_type, None);
            if let Some(names) = &v.enum_names {
                enum_strings(space, ns, &vid, names);
            }
            units_of(space, ns, &vid, v.kind, unit);
        }
        for v in AXIS_CONFIG {
            let vid = axis_var_id(ns, &a.name, v.name);
            let value = Variant::from((v.read)(a));
            variable(
                space,
                ns,
                &obj,
                &vid_path(&vid),
                v.name,
                DataTypeId::Double,
                Some(value),
            );
            units_of(space, ns, &vid, v.kind, unit);
        }
        methods(space, ns, &obj, &axis_path(&a.name), Scope::Axis);
    }

    let ios = id(ns, "Machine.IO");
    folder(space, ns, &ios, "IO", &machine);
    for io in &m.ios {
        let obj = id(ns, &format!("Machine.IO.{}", io.name));
        ObjectBuilder::new(
            &obj,
            QualifiedName::new(ns, io.name.as_str()),
            io.name.as_str(),
        )
        .description(format!("I/O process {}", io.name))
        .organized_by(ios.clone())
        .has_type_definition(ObjectTypeId::BaseObjectType)
        .insert(space);
        for v in IO_VARS {
            let vid = io_var_id(ns, &io.name, v.name);
            variable(space, ns, &obj, &vid_path(&vid), v.name, v.data_type, None);
        }
    }

    let lat = id(ns, "Machine.Latency");
    ObjectBuilder::new(&lat, QualifiedName::new(ns, "Latency"), "Latency")
        .description("the cycle's latency since the supervisor started (motionctl stats)")
        .component_of(machine.clone())
        .has_type_definition(ObjectTypeId::BaseObjectType)
        .insert(space);
    for c in LATENCY_COUNTERS {
        variable(
            space,
            ns,
            &lat,
            &format!("Machine.Latency.{c}"),
            c,
            DataTypeId::UInt64,
            None,
        );
    }
    for s in LATENCY_SERIES {
        let obj = id(ns, &format!("Machine.Latency.{s}"));
        ObjectBuilder::new(&obj, QualifiedName::new(ns, s), s)
            .component_of(lat.clone())
            .has_type_definition(ObjectTypeId::BaseObjectType)
            .insert(space);
        for c in LATENCY_COLUMNS {
            let path = format!("Machine.Latency.{s}.{c}");
            variable(space, ns, &obj, &path, c, DataTypeId::Double, None);
            units_of(space, ns, &id(ns, &path), Kind::Micros, None);
        }
    }
}

fn vid_path(id: &NodeId) -> String {
    match &id.identifier {
        opcua::types::Identifier::String(s) => s.as_ref().to_string(),
        other => other.to_string(),
    }
}

fn folder(space: &mut AddressSpace, ns: u16, id: &NodeId, name: &str, parent: &NodeId) {
    ObjectBuilder::new(id, QualifiedName::new(ns, name), name)
        .is_folder()
        .component_of(parent.clone())
        .insert(space);
}

/// A read-only variable; without `value` it waits for the daemon
/// (`BadWaitingForInitialData`).
fn variable(
    space: &mut AddressSpace,
    ns: u16,
    parent: &NodeId,
    path: &str,
    name: &str,
    dt: DataTypeId,
    value: Option<Variant>,
) {
    let vid = id(ns, path);
    let mut b = VariableBuilder::new(&vid, QualifiedName::new(ns, name), name)
        .data_type(dt)
        .access_level(AccessLevel::CURRENT_READ)
        .user_access_level(AccessLevel::CURRENT_READ)
        .component_of(parent.clone())
        .has_type_definition(VariableTypeId::BaseDataVariableType);
    if let Some(v) = value.clone() {
        b = b.value(v);
    }
    b.insert(space);
    if value.is_none() {
        if let Some(opcua::server::address_space::NodeType::Variable(v)) = space.find_mut(&vid) {
            // An empty value: the stack drops the status of none.
            v.set_data_value(DataValue {
                value: Some(Variant::Empty),
                status: Some(StatusCode::BadWaitingForInitialData),
                ..DataValue::null()
            });
        }
    }
}

fn property(space: &mut AddressSpace, of: &NodeId, name: &str, dt: DataTypeId, value: Variant) {
    let pid = NodeId::new(of.namespace, format!("{}.{name}", vid_path(of)));
    VariableBuilder::new(&pid, QualifiedName::new(0, name), name)
        .data_type(dt)
        .value(value)
        .access_level(AccessLevel::CURRENT_READ)
        .user_access_level(AccessLevel::CURRENT_READ)
        .property_of(of.clone())
        .has_type_definition(VariableTypeId::PropertyType)
        .insert(space);
}

/// `EngineeringUnits` of a number with a unit.
fn units_of(
    space: &mut AddressSpace,
    _ns: u16,
    of: &NodeId,
    kind: Kind,
    unit: Option<motion_config::opcua::Unit>,
) {
    if let Some(eu) = units::eu(kind, unit) {
        let v = Variant::from(ExtensionObject::from_message(eu));
        property(space, of, "EngineeringUnits", DataTypeId::EUInformation, v);
    }
}

/// `EnumStrings` of a CIP enumeration (its numbers index them).
fn enum_strings(space: &mut AddressSpace, _ns: u16, of: &NodeId, names: &[&str]) {
    let texts: Vec<LocalizedText> = names.iter().map(|n| LocalizedText::new("", n)).collect();
    property(
        space,
        of,
        "EnumStrings",
        DataTypeId::LocalizedText,
        Variant::from(texts),
    );
}

fn argument(a: &ArgSpec) -> Argument {
    Argument {
        name: UAString::from(a.name),
        data_type: a.data_type.into(),
        value_rank: if a.array { 1 } else { -1 },
        array_dimensions: a.array.then(|| vec![0]),
        description: LocalizedText::new("", a.doc),
    }
}

/// The methods of `scope` on `object` (node ids `<path>.<Method>`).
fn methods(space: &mut AddressSpace, ns: u16, object: &NodeId, path: &str, scope: Scope) {
    let outputs: Vec<Argument> = output_args(scope).iter().map(argument).collect();
    for m in METHODS.iter().filter(|m| m.scope == scope) {
        let mid = id(ns, &format!("{path}.{}", m.name));
        let mut b = MethodBuilder::new(&mid, QualifiedName::new(ns, m.name), m.name)
            .description(m.doc)
            .component_of(object.clone())
            .executable(true)
            .user_executable(true);
        if !m.inputs.is_empty() {
            let inputs: Vec<Argument> = m.inputs.iter().map(argument).collect();
            let iid = id(ns, &format!("{path}.{}.InputArguments", m.name));
            b = b.input_args(space, &iid, &inputs);
        }
        let oid = id(ns, &format!("{path}.{}.OutputArguments", m.name));
        b.output_args(space, &oid, &outputs).insert(space);
    }
}

/// `AxisErrorEventType` (subtype of BaseEventType) and its fields.
fn event_type(space: &mut AddressSpace, ns: u16) {
    let t = AxisErrorEventType::event_type_id_from_index(ns);
    ObjectTypeBuilder::new(
        &t,
        QualifiedName::new(ns, "AxisErrorEventType"),
        "AxisErrorEventType",
    )
    .description("an axis went ER: ERR, EXERR and the message say why")
    .is_abstract(false)
    .subtype_of(ObjectTypeId::BaseEventType)
    .insert(space);
    for (name, dt) in [
        ("ERR", DataTypeId::UInt16),
        ("EXERR", DataTypeId::UInt16),
        ("Axis", DataTypeId::String),
    ] {
        let pid = id(ns, &format!("AxisErrorEventType.{name}"));
        VariableBuilder::new(&pid, QualifiedName::new(ns, name), name)
            .data_type(dt)
            .property_of(t.clone())
            .has_type_definition(VariableTypeId::PropertyType)
            .has_modelling_rule(ObjectId::ModellingRule_Mandatory)
            .insert(space);
    }
}
