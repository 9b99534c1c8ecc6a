//! The keeper: what outlives a run. It watches the cycle's snapshots from
//! the control thread (never the real-time thread) and
//!
//! * appends every homing's outcome to the homing record, with the drift
//!   and switch-to-marker checks ([`outcome`]);
//! * stores the reference of every absolute axis that homed, restores it
//!   without motion at start-up (and after its I/O process came back), and
//!   invalidates it, with the reason recorded, when it can no longer be
//!   trusted ([`absolute`]).
//!
//! Nothing here can move an axis: a restore is a request to the cycle,
//! which applies it only with fresh, valid, plausible feedback inside the
//! travel limits (`Axis::restore_reference`). A state directory that cannot
//! be used degrades to "no record, absolute axes must be homed", with an
//! error in the log — never a crash.

mod absolute;
mod identity;
mod outcome;

use crate::shared::{Ack, Snapshot};
use absolute::Absolute;
use motion_config::MachineConfig;
use motion_state::{DriftHistory, HomingRecord, RecordEntry, StateDir};
use motion_status::snap::{W_DRIFT, W_SWITCH_DRIFT};

pub use identity::identity;

/// What the keeper says of an axis beyond its engine (warnings, drift):
/// a source of the status table, declared next to it.
pub use motion_status::AxisNote;

/// Per axis: what the keeper remembers between snapshots.
#[derive(Default)]
struct AxisKeep {
    /// `homes_started` of the last homing recorded.
    recorded_homes: u32,
    /// `redefines` of the last redefine position recorded.
    recorded_redefines: u32,
    /// Recent events in the prior reference, and switch-to-marker
    /// distances, of successful homings.
    events: DriftHistory,
    switch_to_marker: DriftHistory,
    absolute: Option<Absolute>,
}

pub struct Keeper {
    record: Option<HomingRecord>,
    dir: Option<StateDir>,
    axes: Vec<AxisKeep>,
    notes: Vec<AxisNote>,
    last_cycle: Option<u64>,
}

impl Keeper {
    /// Opens the state directory, reads the recent events of every axis
    /// from the record and the stored references of the absolute axes
    /// (comparing each with the running configuration).
    pub fn open(m: &MachineConfig) -> Self {
        let dir = match StateDir::open(&m.supervisor.state_dir) {
            Ok(d) => Some(d),
            Err(e) => {
                let absolute: Vec<&str> = m
                    .axes
                    .iter()
                    .filter(|a| a.engine.absolute)
                    .map(|a| a.name.as_str())
                    .collect();
                log::error!(
                    "{e}: no homing record{}",
                    if absolute.is_empty() {
                        String::new()
                    } else {
                        format!(
                            ", and the absolute axes {} cannot be restored without homing",
                            absolute.join(", ")
                        )
                    }
                );
                None
            }
        };
        let mut record = dir.as_ref().map(HomingRecord::new);
        let recent = record
            .as_ref()
            .map(|r| r.recent(motion_state::drift::RECENT))
            .unwrap_or_default();
        let mut axes: Vec<AxisKeep> = Vec::with_capacity(m.axes.len());
        for (i, a) in m.axes.iter().enumerate() {
            let past = recent.get(&a.name).map(Vec::as_slice).unwrap_or_default();
            let mut k = AxisKeep {
                events: DriftHistory::from_values(past.iter().filter_map(|e| e.event)),
                switch_to_marker: DriftHistory::from_values(
                    past.iter().filter_map(|e| e.switch_to_marker),
                ),
                ..AxisKeep::default()
            };
            if a.engine.absolute {
                k.absolute = Some(Absolute::load(m, i, dir.as_ref(), record.as_mut()));
            }
            axes.push(k);
        }
        if let Some(d) = &dir {
            log::info!(
                "state directory {}: homing record {}",
                d.path().display(),
                d.file(motion_state::record::FILE).display()
            );
        }
        Self {
            record,
            dir,
            notes: vec![AxisNote::default(); axes.len()],
            axes,
            last_cycle: None,
        }
    }

    /// Per axis, for the status frame.
    pub fn notes(&self) -> &[AxisNote] {
        &self.notes
    }

    /// Looks at a new snapshot: records homings that ended, saves,
    /// invalidates or restores references; records every redefine
    /// position (and stores an absolute axis's reference after it).
    /// `restore(axis, offset, shift)` sends a restore request to the cycle
    /// and returns its id.
    pub fn observe(
        &mut self,
        m: &MachineConfig,
        snap: &Snapshot,
        mut restore: impl FnMut(usize, f64, f64) -> Option<u32>,
    ) {
        if self.last_cycle == Some(snap.cycle) {
            return;
        }
        self.last_cycle = Some(snap.cycle);
        let n = snap.axis_count.min(m.axes.len()).min(self.axes.len());
        for i in 0..n {
            let a = &snap.axes[i];
            let keep = &mut self.axes[i];
            if let Some(abs) = keep.absolute.as_mut() {
                abs.watch(m, i, snap, self.dir.as_ref(), self.record.as_mut());
            }
            let ended = a.homes_started != keep.recorded_homes
                && !a.status.ip
                && (a.status.dn || a.status.er);
            if ended {
                keep.recorded_homes = a.homes_started;
                let (entry, note) = outcome::entry(m, i, snap, keep);
                self.notes[i] = note;
                for w in &entry.warnings {
                    log::warn!("{}: {w}", m.axes[i].name);
                }
                if let Some(abs) = keep.absolute.as_mut() {
                    abs.homing_ended(m, i, a, &entry, self.dir.as_ref(), self.record.as_mut());
                }
                append(self.record.as_mut(), &entry);
            }
            if a.status.redefines != keep.recorded_redefines {
                keep.recorded_redefines = a.status.redefines;
                if let Some(e) = outcome::redefined(m, i, a) {
                    if let Some(abs) = keep.absolute.as_mut() {
                        abs.redefined(m, i, a, self.dir.as_ref());
                    }
                    append(self.record.as_mut(), &e);
                }
            }
            if let Some(abs) = keep.absolute.as_mut() {
                abs.maybe_restore(m, i, snap, &mut restore);
                if abs.invalidated() {
                    self.notes[i].warnings |= motion_status::snap::W_REFERENCE_INVALIDATED;
                }
            }
        }
    }

    /// An acknowledgement from the cycle: `true` if it answered one of the
    /// keeper's restore requests (and is consumed).
    pub fn ack(&mut self, m: &MachineConfig, ack: &Ack) -> bool {
        for (i, keep) in self.axes.iter_mut().enumerate() {
            if let Some(abs) = keep.absolute.as_mut() {
                if abs.pending() == Some(ack.id) {
                    abs.answered(m, i, &ack.axes[i], self.dir.as_ref(), self.record.as_mut());
                    return true;
                }
            }
        }
        false
    }

    /// The operator cleared HomedStatus of axis `i`: its stored reference
    /// is no longer the operator's reference either.
    pub fn unhomed(&mut self, m: &MachineConfig, i: usize, how: &str) {
        if let Some(abs) = self.axes.get_mut(i).and_then(|k| k.absolute.as_mut()) {
            abs.invalidate(m, i, how, self.dir.as_ref(), self.record.as_mut());
        }
        if let Some(n) = self.notes.get_mut(i) {
            n.warnings &= !(W_DRIFT | W_SWITCH_DRIFT);
        }
    }
}

/// Appends to the record; a failure is logged (the homing itself stands).
fn append(record: Option<&mut HomingRecord>, e: &RecordEntry) {
    if let Some(r) = record {
        if let Err(err) = r.append(e) {
            log::error!(
                "homing record {}: {err}: the {} entry of axis {} is not recorded",
                r.path().display(),
                e.result,
                e.axis
            );
        }
    }
}

#[cfg(test)]
mod tests;
