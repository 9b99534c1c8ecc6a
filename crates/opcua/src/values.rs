//! Status frames and statistics into variable values.
//!
//! Only values that changed are written, each with the source timestamp
//! of the status frame that carried it: when the daemon published it (the
//! frame's uptime), placed on the wall clock by the smallest (arrival −
//! uptime) seen in this daemon session — the fastest a frame ever came,
//! well below a millisecond. The frame holds the snapshot of a cycle at
//! most one status period (10 ms) earlier. Not cycle × cycle time: the
//! cycle counter skips the periods a late wake-up missed, so it falls
//! behind the clock on a noisy host. Monitored items with a sampling
//! interval of 10 ms or less and a queue see every change the status
//! service (100 Hz) carries.
//!
//! An axis's ER going from false to true raises [`crate::events`]'s event.
//! Without the daemon every live value turns `BadNoCommunication` (the last
//! value kept) and `Machine.Connected` false. A reading that has no valid
//! value now (no fresh feedback, no home event yet) is an empty value with
//! `BadNoCommunication`.

use crate::events;
use crate::space::*;
use motion_control::*;
use motion_report::StatsReport;
use opcua::server::node_manager::memory::{InMemoryNodeManager, InMemoryNodeManagerImpl};
use opcua::server::SubscriptionCache;
use opcua::types::{DataValue, DateTime, NodeId, StatusCode, Variant};
use std::collections::HashMap;
use std::sync::Arc;

/// Writes values into the address space and tells the subscriptions.
pub struct Publisher<T: InMemoryNodeManagerImpl> {
    ns: u16,
    manager: Arc<InMemoryNodeManager<T>>,
    subs: Arc<SubscriptionCache>,
    /// What each live node holds now (`None`: a Bad status).
    last: HashMap<NodeId, Option<Variant>>,
    /// Node ids per axis name, in [`AXIS_LIVE`] order.
    axis_ids: HashMap<String, Vec<NodeId>>,
    io_ids: HashMap<String, Vec<NodeId>>,
    /// Daemon session and the wall-clock ticks of its uptime 0.
    anchor: Option<(u32, i64)>,
    /// ER per axis name, to see it rise.
    er: HashMap<String, bool>,
}

impl<T: InMemoryNodeManagerImpl> Publisher<T> {
    pub fn new(
        ns: u16,
        manager: Arc<InMemoryNodeManager<T>>,
        subs: Arc<SubscriptionCache>,
    ) -> Self {
        Self {
            ns,
            manager,
            subs,
            last: HashMap::new(),
            axis_ids: HashMap::new(),
            io_ids: HashMap::new(),
            anchor: None,
            er: HashMap::new(),
        }
    }

    /// The source timestamp of `f`: when the daemon published it.
    fn source_time(&mut self, f: &StatusFrame) -> DateTime {
        let now = DateTime::now().ticks();
        let since_start = i64::try_from(f.uptime_ns / 100).unwrap_or(i64::MAX / 2);
        let seen = now.saturating_sub(since_start);
        let anchor = match self.anchor {
            Some((session, a)) if session == f.session && a <= seen && seen - a < 10_000_000 => a,
            // First frame of a session, a frame faster than any before, or
            // the wall clock stepped by more than a second: re-anchor.
            _ => seen,
        };
        self.anchor = Some((f.session, anchor));
        DateTime::from(anchor + since_start)
    }

    fn put(
        last: &mut HashMap<NodeId, Option<Variant>>,
        out: &mut Vec<(NodeId, DataValue)>,
        id: &NodeId,
        v: Option<Variant>,
        t: DateTime,
    ) {
        if last.get(id) == Some(&v) {
            return;
        }
        // The stack drops the status of a value-less DataValue: an empty
        // Variant carries the Bad status.
        let (value, status) = match &v {
            Some(x) => (x.clone(), StatusCode::Good),
            None => (Variant::Empty, StatusCode::BadNoCommunication),
        };
        out.push((id.clone(), data_value(value, status, t)));
        last.insert(id.clone(), v);
    }

    fn write(&self, out: Vec<(NodeId, DataValue)>) {
        if out.is_empty() {
            return;
        }
        let it = out.iter().map(|(id, dv)| (id, None, dv.clone()));
        if let Err(e) = self.manager.set_values(&self.subs, it) {
            log::warn!("OPC UA: writing {} values: {e}", out.len());
        }
    }

    /// A new status frame.
    pub fn frame(&mut self, f: &StatusFrame) {
        let t = self.source_time(f);
        let ns = self.ns;
        let mut out = Vec::new();
        let names = f.axis_names();
        for (a, name) in f.axes().iter().zip(&names) {
            let ids = self.axis_ids.entry(name.clone()).or_insert_with(|| {
                AXIS_LIVE
                    .iter()
                    .map(|v| axis_var_id(ns, name, v.name))
                    .collect()
            });
            for (v, id) in AXIS_LIVE.iter().zip(ids.iter()) {
                Self::put(&mut self.last, &mut out, id, v.read(a, &names), t);
            }
            let er = a.er();
            let was = self.er.insert(name.clone(), er).unwrap_or(er);
            if er && !was {
                let msg = a.error_text(&names).unwrap_or_else(|| "ER".into());
                let ev = events::axis_error(ns, name, a.err(), a.exerr(), &msg, t);
                events::raise(&self.subs, ns, name, &ev);
            }
        }
        for io in f.ios() {
            let name = get_str(&io.name);
            let ids = self.io_ids.entry(name.clone()).or_insert_with(|| {
                IO_VARS
                    .iter()
                    .map(|v| io_var_id(ns, &name, v.name))
                    .collect()
            });
            for (v, id) in IO_VARS.iter().zip(ids.iter()) {
                Self::put(&mut self.last, &mut out, id, Some((v.read)(io)), t);
            }
        }
        for (name, v) in [
            ("Connected", Variant::from(true)),
            ("Cycle", Variant::from(f.cycle)),
            ("CycleTime", Variant::from(f.cycle_us)),
            ("Uptime", Variant::from(f.uptime_ns as f64 / 1e9)),
        ] {
            Self::put(
                &mut self.last,
                &mut out,
                &id(ns, &format!("Machine.{name}")),
                Some(v),
                t,
            );
        }
        // Nodes the daemon does not know (another config?) fail the whole
        // write: keep only ours.
        let space = self.manager.address_space().clone();
        {
            let s = space.read();
            out.retain(|(id, _)| s.find(id).is_some());
        }
        self.write(out);
    }

    /// New latency statistics (since the daemon started).
    pub fn stats(&mut self, r: &StatsReport) {
        let t = DateTime::now();
        let ns = self.ns;
        let mut out = Vec::new();
        let l = &r.latency;
        for (name, v) in [
            ("Cycles", l.cycles),
            ("DeadlineMisses", l.deadline_misses),
            ("LateReplies", l.late_replies),
        ] {
            Self::put(
                &mut self.last,
                &mut out,
                &id(ns, &format!("Machine.Latency.{name}")),
                Some(v.into()),
                t,
            );
        }
        for (series, p) in
            LATENCY_SERIES
                .iter()
                .zip([&l.wakeup_us, &l.compute_us, &l.io_roundtrip_us])
        {
            for (col, v) in LATENCY_COLUMNS.iter().zip(p.values()) {
                let nid = id(ns, &format!("Machine.Latency.{series}.{col}"));
                Self::put(&mut self.last, &mut out, &nid, Some(v.into()), t);
            }
        }
        self.write(out);
    }

    /// The daemon went away: every live value keeps its last value with
    /// `BadNoCommunication`; `Connected` turns false.
    pub fn lost(&mut self) {
        let t = DateTime::now();
        let connected = id(self.ns, "Machine.Connected");
        let mut out: Vec<(NodeId, DataValue)> = self
            .last
            .drain()
            .filter(|(nid, _)| *nid != connected)
            .map(|(nid, v)| {
                let dv = data_value(
                    v.unwrap_or(Variant::Empty),
                    StatusCode::BadNoCommunication,
                    t,
                );
                (nid, dv)
            })
            .collect();
        // `last` is empty now: the first frame after a reconnect writes
        // every value again.
        Self::put(&mut self.last, &mut out, &connected, Some(false.into()), t);
        self.anchor = None;
        self.er.clear();
        self.write(out);
    }
}

fn data_value(value: Variant, status: StatusCode, t: DateTime) -> DataValue {
    DataValue {
        value: Some(value),
        status: Some(status),
        source_timestamp: Some(t),
        server_timestamp: Some(DateTime::now()),
        ..DataValue::null()
    }
}
