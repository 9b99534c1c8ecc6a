//! What the cycle hands over, taken by the control thread: answers to
//! requests, snapshots, histogram sets, trace records; the keeper looks at
//! every new snapshot, and the I/O processes' comings and goings are logged.

use super::ControlThread;
use crate::hub::TRACE_MAX;
use crate::shared::{Ask, Control, Snapshot};
use motion_config::MachineConfig;

impl ControlThread {
    /// Takes over what the cycle handed over.
    pub(super) fn pump(&mut self) {
        while let Some(a) = self.shared.acks.pop() {
            self.acks.push(a);
        }
        // The keeper's restore requests are answered here.
        let (keeper, machine) = (&mut self.keeper, &self.s.machine);
        self.acks.retain(|a| !keeper.ack(machine, a));
        // Acks nobody waits for any more.
        if self.acks.len() > 64 {
            self.acks.drain(..self.acks.len() - 64);
        }
        let mut hub = self.hub.lock();
        let hub = &mut *hub;
        self.shared.latest_snapshot(&mut hub.snapshot);
        self.shared.collect_intervals(|h| {
            hub.since_start.merge(h);
            hub.since_reset.merge(h);
            if let Some(lines) = hub.lines.add(h) {
                if let Some(f) = self.hlog.as_mut() {
                    f.write(lines);
                }
            }
        });
        while let Some(r) = self.shared.trace.pop() {
            if hub.trace.axis == Some(usize::from(r.axis)) && !hub.trace.complete {
                if hub.trace.records.len() < TRACE_MAX {
                    hub.trace.records.push(r);
                }
                hub.trace.complete = r.end;
            }
        }
        if let Some(snap) = hub.snapshot.as_deref() {
            let (shared, next_id) = (&self.shared, &mut self.next_id);
            self.keeper.observe(&self.s.machine, snap, |axis, offset| {
                let id = *next_id;
                *next_id = next_id.wrapping_add(1).max(1);
                shared
                    .send(Control::undated(id, Ask::Restore { axis, offset }))
                    .then_some(id)
            });
            self.ios.watch(&self.s.machine, snap);
            self.trips.watch(&self.s.machine, snap);
        }
    }
}

/// The I/O processes as the last snapshot showed them, to log each change.
pub(super) struct IoWatch {
    attached: Vec<bool>,
    attachments: Vec<u64>,
}

impl IoWatch {
    pub fn new(ios: usize) -> Self {
        Self {
            attached: vec![false; ios],
            attachments: vec![0; ios],
        }
    }

    /// Logs every I/O process that attached, attached again or detached
    /// since the last snapshot.
    fn watch(&mut self, m: &MachineConfig, snap: &Snapshot) {
        for (k, io) in m.ios.iter().enumerate() {
            let now = snap.ios[k].attached;
            // Attachments counted, not just the state seen: a detach and
            // re-attach between two snapshots is reported too.
            let attachments = snap.ios[k].counters.attachments;
            let bounced = now && self.attached[k] && attachments > self.attachments[k];
            self.attachments[k] = attachments;
            if now == self.attached[k] && !bounced {
                continue;
            }
            self.attached[k] = now;
            if now {
                let names: Vec<&str> = (m.axes_of(k).iter())
                    .map(|&i| m.axes[i].name.as_str())
                    .collect();
                if snap.ios[k].counters.attachments > 1 {
                    log::warn!(
                        "I/O process {} attached again (attachment {}, restarts {}): \
                         HomedStatus of {} cleared",
                        io.name,
                        snap.ios[k].counters.attachments,
                        snap.ios[k].counters.incarnations,
                        names.join(", ")
                    );
                } else {
                    log::info!("I/O process {} attached ({})", io.name, names.join(", "));
                }
            } else if snap.exiting {
                log::info!("I/O process {} stopped answering (shutting down)", io.name);
            } else {
                log::warn!(
                    "I/O process {} detached: no fresh feedback for {} cycles; its \
                     axes' homing aborts (ERR 12/40)",
                    io.name,
                    snap.ios[k].counters.gap_cycles
                );
            }
        }
    }
}
