//! A homing that ended, as a line of the homing record, with the two checks
//! no single homing can make: drift against the axis's recent events, and
//! the switch-to-marker distance (its drift, and the engine's verdict that
//! the marker was ambiguous); and a redefine position, as a line of its own
//! kind.

use super::{AxisKeep, AxisNote};
use crate::shared::{AxisSnap, Snapshot};
use motion_config::MachineConfig;
use motion_homing::{HomeMode, HomeSequence};
use motion_state::{RecordEntry, RecordKind};
use motion_status::snap::{W_DRIFT, W_SWITCH_DRIFT};

/// Rounds to 1 nm-ish (µunit) so the record reads cleanly.
fn r6(x: f64) -> f64 {
    motion_report::round(x, 6)
}

/// The record entry of axis `i`'s homing that just ended, the note for the
/// status frame; the drift histories learn from it when it succeeded.
pub(super) fn entry(
    m: &MachineConfig,
    i: usize,
    snap: &Snapshot,
    keep: &mut AxisKeep,
) -> (RecordEntry, AxisNote) {
    let cfg = &m.axes[i];
    let e = &cfg.engine;
    let a = &snap.axes[i];
    let s = &a.status;
    let (time, unix_ms) = motion_state::now_stamp();
    let ok = s.pc && s.homed && !s.er;
    let gap_s = s.lost_after_ns.map(|g| g as f64 * 1e-9);
    let error = if let Some(j) = a.aborted_by.filter(|_| s.er) {
        Some(format!(
            "home sequence aborted because axis {} failed: stopped",
            m.axes.get(usize::from(j)).map_or("?", |x| x.name.as_str())
        ))
    } else {
        s.er.then(|| motion_report::codes::describe(s.err, s.exerr, gap_s))
    };
    // Where the event lay in the reference the axis had before: only
    // meaningful for a sequence that searches an event.
    let searched = e.home_sequence != HomeSequence::Immediate && e.home_mode != HomeMode::Absolute;
    let event = match (searched, s.event_raw, s.prior_offset) {
        (true, Some(raw), Some(off)) => Some(r6(raw + off)),
        _ => None,
    };
    let switch_to_marker = match (e.home_sequence, s.switch_edge_raw, s.event_raw) {
        (q, Some(sw), Some(ev)) if q.uses_switch() && q.uses_marker() => Some(r6((ev - sw).abs())),
        _ => None,
    };
    let mut warnings = Vec::new();
    let mut note = AxisNote::default();
    if s.ambiguous_marker {
        warnings.push(format!(
            "ambiguous marker: the marker lay {} from the switch edge, closer than \
             marker_min_distance {} (about two cycles of travel): the next homing may take \
             the marker one revolution away (set refuse_ambiguous_marker = true to fail instead)",
            switch_to_marker.map_or("?".into(), |d| d.to_string()),
            r6(e.marker_min_distance)
        ));
    }
    if ok {
        if let Some(d) = event.and_then(|v| keep.events.check(v, cfg.drift_limit)) {
            warnings.push(format!(
                "drift: the home event lay at {} in the previous reference, {:+} from the \
                 median {} of the last {} homings (drift_limit {}): home switch wear or a \
                 slipping coupling?",
                d.value,
                r6(d.deviation),
                r6(d.median),
                d.over,
                cfg.drift_limit
            ));
            note.warnings |= W_DRIFT;
            note.drift = r6(d.deviation);
        }
        if let Some(d) =
            switch_to_marker.and_then(|v| keep.switch_to_marker.check(v, cfg.drift_limit))
        {
            warnings.push(format!(
                "drift: switch edge to marker {} ({:+} from the median {} of the last {} \
                 homings, drift_limit {}): the home switch has moved or wears",
                d.value,
                r6(d.deviation),
                r6(d.median),
                d.over,
                cfg.drift_limit
            ));
            note.warnings |= W_SWITCH_DRIFT;
            if note.drift.is_nan() {
                note.drift = r6(d.deviation);
            }
        }
        if let Some(v) = event {
            keep.events.push(v);
        }
        if let Some(v) = switch_to_marker {
            keep.switch_to_marker.push(v);
        }
    }
    let result = if s.er {
        "failed"
    } else if ok {
        "homed"
    } else if s.homed {
        "homed_not_at_home_position"
    } else {
        "not_homed"
    };
    let entry = RecordEntry {
        time,
        unix_ms,
        kind: Some(RecordKind::Homing),
        axis: cfg.name.clone(),
        gantry: m.gantry_of(i).map(|g| m.gantries[g].name.clone()),
        mode: e.home_mode.name().into(),
        sequence: e.home_sequence.name().into(),
        direction: e.home_direction.name().into(),
        result: result.into(),
        pc: s.pc,
        homed: s.homed,
        err: s.err,
        exerr: s.exerr,
        error,
        event_raw: s.event_raw.map(r6),
        event,
        switch_to_marker,
        offset: a.offset.filter(|_| s.homed).map(r6),
        duration_s: s
            .finished_ns
            .map(|f| motion_report::round(f.saturating_sub(s.started_ns) as f64 * 1e-9, 4)),
        skew: a.skew.map(r6),
        reason: None,
        warnings,
        ..RecordEntry::default()
    };
    (entry, note)
}

/// The record line of axis `i`'s redefine position (its own kind: no
/// homing ran, nothing moved). `None` when the snapshot shows the axis no
/// longer homed (the reference it shifted is already gone).
pub(super) fn redefined(m: &MachineConfig, i: usize, a: &AxisSnap) -> Option<RecordEntry> {
    let offset = a.offset?;
    let (time, unix_ms) = motion_state::now_stamp();
    Some(RecordEntry {
        time,
        unix_ms,
        kind: Some(RecordKind::Redefined),
        axis: m.axes[i].name.clone(),
        gantry: m.gantry_of(i).map(|g| m.gantries[g].name.clone()),
        result: "redefined".into(),
        pc: a.status.pc,
        homed: true,
        offset: Some(r6(offset)),
        shift: Some(r6(a.status.shift)),
        position: a.cmd_axis.map(r6),
        reason: Some("redefine position: no motion".into()),
        ..RecordEntry::default()
    })
}
