//! The stored reference of one absolute axis: load and compare at start,
//! restore without motion when its feedback is there, store after every
//! successful homing, invalidate (with the reason, in the file and the
//! record) when it cannot be trusted:
//!
//! | trigger | reason recorded |
//! |---|---|
//! | configuration differs from the stored identity | `axis configuration changed: KEY a → b, ...` |
//! | file unreadable (syntax, owner, size, symlink) | `stored reference unreadable: ...` |
//! | restored position outside the travel limits | `... outside its travel limits ...` |
//! | a position jump the axis cannot make | `position jump: ...` |
//! | invalid feedback (NaN, absurd) | `encoder fault: invalid ...` |
//! | drive fault with a CiA 402 sensor error (0x73xx) | `encoder fault: drive error 0x73..` |
//! | `motionctl unhome` | `operator unhome` |
//!
//! A homing that fails does not invalidate it (the encoder is no less
//! right for it), but it is not re-applied in this run either: the operator
//! asked for a new reference. Loss of feedback or a restarted I/O process
//! clear HomedStatus without casting doubt on the encoder, so the reference
//! is applied again once fresh feedback is back.

use super::append;
use super::identity::identity;
use crate::control_thread::answer;
use crate::shared::{AxisAck, AxisSnap, Refusal, Snapshot};
use motion_config::MachineConfig;
use motion_homing::RestoreRefusal;
use motion_state::reference::{References, FORMAT};
use motion_state::{
    AxisIdentity, HomingRecord, Loaded, RecordEntry, RecordKind, StateDir, StoredReference,
};
use std::time::{Duration, Instant};

/// Wait between restore attempts that the cycle refused for a passing
/// reason (no feedback yet, drive fault, busy).
const RETRY: Duration = Duration::from_millis(200);

pub(super) struct Absolute {
    identity: AxisIdentity,
    /// The reference to keep applying (valid, same identity).
    stored: Option<StoredReference>,
    /// A reference was invalidated (this run or before).
    invalidated: bool,
    /// A homing failed in this run: the stored reference waits for the
    /// next start.
    suspended: bool,
    pending: Option<u32>,
    retry_at: Option<Instant>,
    /// The last passing refusal logged (each is logged once).
    said: Option<String>,
    jumps: u32,
    bad: bool,
    encoder_fault: bool,
}

fn simple(m: &MachineConfig, i: usize, kind: RecordKind, result: &str) -> RecordEntry {
    let (time, unix_ms) = motion_state::now_stamp();
    RecordEntry {
        time,
        unix_ms,
        kind: Some(kind),
        axis: m.axes[i].name.clone(),
        gantry: m.gantry_of(i).map(|g| m.gantries[g].name.clone()),
        result: result.into(),
        ..RecordEntry::default()
    }
}

impl Absolute {
    pub(super) fn load(
        m: &MachineConfig,
        i: usize,
        dir: Option<&StateDir>,
        record: Option<&mut HomingRecord>,
    ) -> Self {
        let name = &m.axes[i].name;
        let mut me = Self {
            identity: identity(m, i),
            stored: None,
            invalidated: false,
            suspended: false,
            pending: None,
            retry_at: None,
            said: None,
            jumps: 0,
            bad: false,
            encoder_fault: false,
        };
        let Some(dir) = dir else {
            return me;
        };
        let refs = References::new(dir.clone());
        match refs.load(name) {
            Loaded::None => log::info!(
                "{name}: absolute axis without a stored reference: home it once \
                 (motionctl home {name}); it is then homed at every start without motion"
            ),
            Loaded::Valid(r) => {
                let diff = r.identity.differences(&me.identity);
                if diff.is_empty() {
                    log::info!(
                        "{name}: stored reference of {} (offset {}): applied without motion \
                         once its feedback arrives",
                        r.homed_at,
                        r.offset
                    );
                    me.stored = Some(r);
                } else {
                    me.stored = Some(r);
                    let why = format!("axis configuration changed: {}", diff.join(", "));
                    me.invalidate(m, i, &why, Some(dir), record);
                }
            }
            Loaded::Invalidated(r) => {
                let why = r.invalidated.as_ref().map_or("", |x| x.reason.as_str());
                log::warn!(
                    "{name}: the stored reference was invalidated earlier ({why}): home the axis"
                );
                me.invalidated = true;
            }
            Loaded::Unreadable(why) => {
                log::error!("{name}: stored reference unreadable, not used: {why}");
                let mut e = simple(m, i, RecordKind::Invalidated, "invalidated");
                e.reason = Some(format!("stored reference unreadable: {why}"));
                append(record, &e);
                me.invalidated = true;
            }
        }
        me
    }

    pub(super) fn pending(&self) -> Option<u32> {
        self.pending
    }

    pub(super) fn invalidated(&self) -> bool {
        self.invalidated
    }

    /// Invalidates the stored reference (if there is one) with `why`.
    pub(super) fn invalidate(
        &mut self,
        m: &MachineConfig,
        i: usize,
        why: &str,
        dir: Option<&StateDir>,
        record: Option<&mut HomingRecord>,
    ) {
        let Some(r) = self.stored.take() else {
            return;
        };
        let name = &m.axes[i].name;
        self.invalidated = true;
        log::warn!("{name}: stored reference invalidated: {why}; the axis must be homed");
        if let Some(d) = dir {
            if let Err(e) = References::new(d.clone()).invalidate(r.clone(), why) {
                log::error!(
                    "{name}: could not mark the stored reference invalid ({e}); \
                     it is not used in this run"
                );
            }
        }
        let mut e = simple(m, i, RecordKind::Invalidated, "invalidated");
        e.offset = Some(r.offset);
        e.reason = Some(why.into());
        append(record, &e);
    }

    /// Watches the feedback for what makes the encoder untrustworthy.
    pub(super) fn watch(
        &mut self,
        m: &MachineConfig,
        i: usize,
        snap: &Snapshot,
        dir: Option<&StateDir>,
        record: Option<&mut HomingRecord>,
    ) {
        let a = &snap.axes[i];
        let s = &a.status;
        let jumps = s.implausible.jumps;
        let bad = s.bad_attribute.is_some();
        let encoder_fault = a.fault && (0x7300..=0x73ff).contains(&a.drive_error_code);
        let why = if jumps > self.jumps {
            Some(format!(
                "position jump: the encoder reported a position the axis cannot have reached \
                 ({} refused)",
                jumps - self.jumps
            ))
        } else if bad && !self.bad {
            Some(format!(
                "encoder fault: invalid {}",
                s.bad_attribute.unwrap_or("feedback")
            ))
        } else if encoder_fault && !self.encoder_fault {
            Some(format!(
                "encoder fault: drive error {:#06x} (CiA 402 sensor fault)",
                a.drive_error_code
            ))
        } else {
            None
        };
        self.jumps = jumps;
        self.bad = bad;
        self.encoder_fault = encoder_fault;
        if let Some(why) = why {
            self.invalidate(m, i, &why, dir, record);
        }
    }

    /// A homing of this axis ended: a new reference is stored.
    pub(super) fn homing_ended(
        &mut self,
        m: &MachineConfig,
        i: usize,
        a: &AxisSnap,
        entry: &RecordEntry,
        dir: Option<&StateDir>,
        _record: Option<&mut HomingRecord>,
    ) {
        let name = &m.axes[i].name;
        let (Some(offset), Some(raw), Some(position), true) =
            (a.offset, a.raw, a.axis, entry.succeeded())
        else {
            if self.stored.is_some() {
                self.suspended = true;
                log::warn!(
                    "{name}: homing did not succeed; the stored reference is not re-applied in \
                     this run (it stays valid for the next start): home the axis"
                );
            }
            return;
        };
        let r = StoredReference {
            format: FORMAT,
            axis: name.clone(),
            offset,
            shift: a.status.shift,
            raw,
            position,
            homed_at: entry.time.clone(),
            identity: self.identity.clone(),
            invalidated: None,
        };
        match dir.map(|d| References::new(d.clone()).save(&r)) {
            Some(Ok(())) => log::info!(
                "{name}: reference stored (offset {offset}): the axis is homed at the next \
                 start without motion"
            ),
            Some(Err(e)) => log::error!(
                "{name}: could not store the reference ({e}): the axis must be homed after a \
                 restart"
            ),
            None => {}
        }
        self.stored = Some(r);
        self.invalidated = false;
        self.suspended = false;
        self.said = None;
    }

    /// Redefine position shifted the axis: the stored reference follows
    /// (offset and shift), so after a restart the axis reads the redefined
    /// position and its soft limits are where they were on the machine.
    /// Only a reference this run trusts is rewritten (a suspended or
    /// invalidated one stays as it was).
    pub(super) fn redefined(
        &mut self,
        m: &MachineConfig,
        i: usize,
        a: &AxisSnap,
        dir: Option<&StateDir>,
    ) {
        let name = &m.axes[i].name;
        let (Some(r), Some(offset), Some(raw), Some(position)) =
            (self.stored.as_mut(), a.offset, a.raw, a.axis)
        else {
            return;
        };
        if self.suspended {
            return;
        }
        r.offset = offset;
        r.shift = a.status.shift;
        r.raw = raw;
        r.position = position;
        match dir.map(|d| References::new(d.clone()).save(r)) {
            Some(Ok(())) => log::info!(
                "{name}: position redefined (offset {offset}, shift {}): the stored reference \
                 follows",
                r.shift
            ),
            Some(Err(e)) => log::error!(
                "{name}: could not store the redefined reference ({e}): after a restart the \
                 axis reads its position before the redefine"
            ),
            None => {}
        }
    }

    /// Asks the cycle to apply the stored reference when the axis is not
    /// homed, not homing, and has fresh feedback from an attached process.
    pub(super) fn maybe_restore(
        &mut self,
        m: &MachineConfig,
        i: usize,
        snap: &Snapshot,
        restore: &mut impl FnMut(usize, f64, f64) -> Option<u32>,
    ) {
        let Some(r) = &self.stored else {
            return;
        };
        let a = &snap.axes[i];
        let io_ok = snap.ios.get(m.axes[i].io).is_some_and(|io| io.attached);
        if self.suspended
            || self.pending.is_some()
            || a.status.homed
            || a.status.ip
            || a.in_sequence
            || !a.fresh
            || !io_ok
            || self.retry_at.is_some_and(|t| Instant::now() < t)
        {
            return;
        }
        self.pending = restore(i, r.offset, r.shift);
        self.retry_at = Some(Instant::now() + RETRY);
    }

    /// The cycle's answer to a restore request.
    pub(super) fn answered(
        &mut self,
        m: &MachineConfig,
        i: usize,
        ack: &AxisAck,
        dir: Option<&StateDir>,
        record: Option<&mut HomingRecord>,
    ) {
        self.pending = None;
        let name = &m.axes[i].name;
        let Some(r) = self.stored.clone() else {
            return;
        };
        if ack.accepted() {
            log::info!(
                "{name}: homed from the stored reference of {} (offset {}), without motion",
                r.homed_at,
                r.offset
            );
            self.said = None;
            let mut e = simple(m, i, RecordKind::Restored, "restored");
            e.homed = true;
            e.offset = Some(r.offset);
            e.reason = Some(format!("stored reference of {}", r.homed_at));
            append(record, &e);
            return;
        }
        let passing = match ack {
            AxisAck::Refused(Refusal::Restore(RestoreRefusal::OutsideTravelLimits {
                position,
            })) => {
                let (lo, hi) = m.axes[i].engine.travel_limits.unwrap_or((0.0, 0.0));
                let (lo, hi) = (lo + r.shift, hi + r.shift);
                let why = format!(
                    "the stored reference puts the axis at {position}, outside its travel \
                     limits [{lo}, {hi}]: encoder replaced or mechanics moved"
                );
                self.invalidate(m, i, &why, dir, record);
                return;
            }
            AxisAck::Refused(Refusal::Restore(
                x @ (RestoreRefusal::InvalidOffset | RestoreRefusal::NotAbsolute),
            )) => {
                self.invalidate(m, i, &x.to_string(), dir, record);
                return;
            }
            AxisAck::Refused(Refusal::Restore(x)) => x.to_string(),
            AxisAck::Refused(r) => answer::reason(*r)
                .map_or("refused", |r| r.text())
                .to_string(),
            AxisAck::Accepted | AxisAck::NotNamed => "refused".to_string(),
        };
        if self.said.as_deref() != Some(passing.as_str()) {
            log::info!("{name}: the stored reference waits: {passing}");
            self.said = Some(passing);
        }
    }
}
