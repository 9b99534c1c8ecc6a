//! The event raised when an axis goes ER.
//!
//! async-opcua 0.19 has the Alarms & Conditions *types* but no condition
//! machinery: a client's Acknowledge (a method of the core namespace)
//! would reach the stack's core node manager, which does not support it.
//! So this is a plain event of our own type, `AxisErrorEventType`
//! (subtype of `BaseEventType`, namespace `urn:motion-supervisor`) with
//! the fields `ERR`, `EXERR` and `Axis`; `Message` is the error in words,
//! `SourceNode`/`SourceName` the axis, `Severity` 800. It is emitted by
//! the Server object (what clients subscribe to by default), `Machine`
//! and the axis's own object.

use crate::space::{axis_id, NAMESPACE_URI};
use opcua::nodes::{BaseEventType, Event};
use opcua::server::SubscriptionCache;
use opcua::types::{ByteString, DateTime, NodeId, ObjectId, UAString};

#[derive(opcua::Event)]
#[opcua(
    identifier = "s=AxisErrorEventType",
    namespace = "urn:motion-supervisor"
)]
pub struct AxisErrorEventType {
    base: BaseEventType,
    own_namespace_index: u16,
    #[opcua(rename = "ERR")]
    err: u16,
    #[opcua(rename = "EXERR")]
    exerr: u16,
    axis: UAString,
}

/// Severity of an axis error (OPC UA: 601–800 "medium high").
pub const SEVERITY: u16 = 800;

/// Builds the event of `axis` going ER at `time`.
pub fn axis_error(
    ns: u16,
    axis: &str,
    err: u16,
    exerr: u16,
    message: &str,
    time: DateTime,
) -> AxisErrorEventType {
    debug_assert!(!NAMESPACE_URI.is_empty());
    let mut id = [0u8; 16];
    let _ = getrandom::fill(&mut id);
    AxisErrorEventType {
        base: BaseEventType::new(
            AxisErrorEventType::event_type_id_from_index(ns),
            ByteString::from(id.to_vec()),
            message.to_string(),
            time,
        )
        .set_source_node(axis_id(ns, axis))
        .set_source_name(UAString::from(axis))
        .set_severity(SEVERITY),
        own_namespace_index: ns,
        err,
        exerr,
        axis: UAString::from(axis),
    }
}

/// Emits `event` from the Server object, `Machine` and the axis.
pub fn raise(subs: &SubscriptionCache, ns: u16, axis: &str, event: &AxisErrorEventType) {
    let server: NodeId = ObjectId::Server.into();
    let machine = crate::space::id(ns, "Machine");
    let own = axis_id(ns, axis);
    subs.notify_events(
        [
            (event as &dyn Event, &server),
            (event as &dyn Event, &machine),
            (event as &dyn Event, &own),
        ]
        .into_iter(),
    );
}
