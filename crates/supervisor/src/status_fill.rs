//! A snapshot of the cycle as a status frame (what the status service
//! publishes, and what `status --json` reports).

use crate::keeper::AxisNote;
use crate::shared::{LostCause, Snapshot};
use motion_config::MachineConfig;
use motion_control::*;
use motion_homing::effective_search_limit;

/// Fills `f` (zeroed) from `snap` and the keeper's `notes` (per axis);
/// `uptime_ns` since the supervisor started.
pub fn fill(
    m: &MachineConfig,
    snap: &Snapshot,
    notes: &[AxisNote],
    uptime_ns: u64,
    f: &mut StatusFrame,
) {
    f.cycle = snap.cycle;
    f.uptime_ns = uptime_ns;
    f.cycle_us = m.supervisor.cycle_us;
    let n = snap.axis_count.min(m.axes.len()).min(MAX_AXES);
    f.axis_count = n as u32;
    for (i, (a, e)) in snap.axes[..n].iter().zip(f.axes.iter_mut()).enumerate() {
        let cfg = &m.axes[i];
        let s = &a.status;
        put_str(&mut e.name, &cfg.name);
        put_str(&mut e.phase, s.phase.name());
        e.io = cfg.io as u8;
        let mut bits = 0u16;
        for (on, bit) in [
            (s.en, ST_EN),
            (s.dn, ST_DN),
            (s.er, ST_ER),
            (s.ip, ST_IP),
            (s.pc, ST_PC),
            (s.homing, ST_HOMING),
            (s.homed, ST_HOMED),
            // a lost drive is not "enabled", whatever it last said
            (a.enabled && !s.drive_lost, ST_ENABLED),
            (a.fault, ST_FAULT),
            (a.switch, ST_SWITCH),
            (a.marker, ST_MARKER),
            (a.raw.is_some(), ST_FEEDBACK),
            (s.event_raw.is_some(), ST_EVENT),
            (s.stopping, ST_STOPPING),
            (a.traced, ST_TRACE),
        ] {
            if on {
                bits |= bit;
            }
        }
        e.bits = bits;
        e.err = s.err;
        e.exerr = s.exerr;
        e.drive_error_code = a.drive_error_code;
        e.home_mode = cfg.engine.home_mode as u8;
        e.home_sequence = cfg.engine.home_sequence as u8;
        e.home_direction = cfg.engine.home_direction as u8;
        e.aborted_by = a.aborted_by.unwrap_or(NO_AXIS);
        e.extra = (if a.timed_out { SX_TIMED_OUT } else { 0 })
            | (if a.lost_homed_ns.is_some() {
                SX_LOST_HOMED
            } else {
                0
            })
            | (if a.in_sequence { SX_IN_SEQUENCE } else { 0 })
            | (if a.restored { SX_RESTORED } else { 0 })
            | (if s.drive_lost { SX_DRIVE_LOST } else { 0 })
            | (if a.monitor.is_some() { SX_MONITOR } else { 0 })
            | lost_cause_bits(a.lost_cause);
        let note = notes.get(i).copied().unwrap_or_default();
        e.warnings = note.warnings
            | if s.ambiguous_marker {
                W_AMBIGUOUS_MARKER
            } else {
                0
            };
        e.drift = note.drift;
        e.feedback_gap_s = s.lost_after_ns.map_or(0.0, |g| g as f64 * 1e-9);
        e.switch_to_marker = match (s.switch_edge_raw, s.event_raw) {
            (Some(sw), Some(ev)) => (ev - sw).abs(),
            _ => f64::NAN,
        };
        e.position = a.axis.unwrap_or(0.0);
        e.raw = a.raw.unwrap_or(0.0);
        e.velocity = a.velocity;
        e.torque = a.torque;
        e.event_raw = s.event_raw.unwrap_or(0.0);
        e.elapsed_s = if a.homes_started > 0 {
            s.finished_ns
                .unwrap_or(snap.now_ns)
                .saturating_sub(s.started_ns) as f64
                * 1e-9
        } else {
            0.0
        };
        e.timeout_s = cfg.engine.home_timeout;
        e.search_travel = s.search_travel;
        e.skew = a.skew.unwrap_or(f64::NAN);
        e.lost_after_s = match (a.lost_homed_ns, s.finished_ns) {
            (Some(l), Some(f)) => l.saturating_sub(f) as f64 * 1e-9,
            _ => 0.0,
        };
        let limit = effective_search_limit(&cfg.engine);
        e.search_limit = if limit.is_finite() { limit } else { 0.0 };
        operation(a, e);
    }
    stream(snap, &mut f.stream);
    let k = snap.io_count.min(m.ios.len()).min(MAX_IOS);
    f.io_count = k as u32;
    for (j, (io, e)) in snap.ios[..k].iter().zip(f.ios.iter_mut()).enumerate() {
        put_str(&mut e.name, &m.ios[j].name);
        e.attached = u8::from(io.attached);
        e.frames_received = io.frames_received;
        e.frames_missing = io.frames_missing;
        e.frames_refused = io.frames_refused;
        e.attachments = io.attachments;
        e.gaps = [
            io.gaps.one,
            io.gaps.two_to_three,
            io.gaps.four_to_ten,
            io.gaps.over_ten,
        ];
        e.longest_gap_cycles = io.gaps.longest_cycles;
        e.gap_cycles = io.gap_cycles;
    }
}

/// The operation part of an axis's entry: motion bits, the last
/// operation, why the last motion stopped, the command position.
fn operation(a: &crate::shared::AxisSnap, e: &mut AxisStatusEntry) {
    let s = &a.status;
    let mut m = 0u16;
    for (on, bit) in [
        (s.servo_action, MS_SERVO_ACTION),
        (s.jogging, MS_JOGGING),
        (s.moving, MS_MOVING),
        (s.streaming, MS_STREAMING),
        (s.limit_negative, MS_LIMIT_NEGATIVE),
        (s.limit_positive, MS_LIMIT_POSITIVE),
        (s.faulted, MS_FAULTED),
        (a.cmd_axis.is_some(), MS_COMMAND),
    ] {
        if on {
            m |= bit;
        }
    }
    e.motion = m;
    e.cmd_position = a.cmd_axis.unwrap_or(0.0);
    e.op_id = s.op.id;
    e.op_kind = s.op.kind as u8;
    e.op_flags = (if s.op.ip { OP_IP } else { 0 })
        | (if s.op.pc { OP_PC } else { 0 })
        | (if s.op.refused.is_some() {
            OP_REFUSED
        } else {
            0
        });
    (e.op_err, e.op_exerr) = s.op.refused.unwrap_or((0, 0));
    e.last_stop = s.last_stop as u8;
}

/// The setpoint stream's intake counters.
fn stream(snap: &Snapshot, e: &mut StreamStatusEntry) {
    let c = &snap.stream;
    *e = StreamStatusEntry {
        frames: c.frames,
        setpoints: c.setpoints,
        refused_layout: c.refused_layout,
        refused_key: c.refused_key,
        refused_count: c.refused_count,
        refused_token: c.refused_token,
        refused_sequence: c.refused_sequence,
        refused_axis: c.refused_axis,
        acquired: c.acquired,
        owners: snap.owners,
    };
}

/// The owner of each axis by name (`name_of` a token: the control thread's
/// table of owners).
pub fn owners<'a>(snap: &Snapshot, name_of: impl Fn(u64) -> Option<&'a str>, f: &mut StatusFrame) {
    let n = (f.axis_count as usize).min(snap.axis_count);
    for (a, e) in snap.axes[..n].iter().zip(f.axes.iter_mut()) {
        if a.owner != 0 {
            put_str(&mut e.owner, name_of(a.owner).unwrap_or("?"));
        }
    }
}

/// Why HomedStatus was lost, as the status frame's `SX_LOST_*` bit.
fn lost_cause_bits(c: LostCause) -> u8 {
    match c {
        LostCause::Other => 0,
        LostCause::Feedback => SX_LOST_FEEDBACK,
        LostCause::Reconnect => SX_LOST_RECONNECT,
    }
}
