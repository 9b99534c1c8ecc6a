//! A snapshot of the cycle as a status frame (what the status service
//! publishes, and what `status --json` reports). Runs on the control
//! thread (every 10 ms, and for a status request), never in the cycle.
//!
//! What each axis field holds is the status table's (`motion_status::axis`:
//! every row's getter reads the snapshot's axis, its configuration and the
//! keeper's note); here only the frame's own fields, the axis's texts and
//! the I/O processes.

use crate::keeper::AxisNote;
use crate::shared::Snapshot;
use motion_config::MachineConfig;
use motion_control::*;
use motion_status::Source;

/// Fills `f` from `snap` and the keeper's `notes` (per axis); `uptime_ns`
/// since the supervisor started. Allocates nothing.
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
        e.set_identity(&cfg.name, a.status.phase.name(), cfg.io);
        let note = notes.get(i).copied().unwrap_or_default();
        let source = Source::new(a, &cfg.engine, &note, snap.now_ns);
        motion_status::axis::fill(e, &source);
    }
    f.stream = snap.stream;
    let k = snap.io_count.min(m.ios.len()).min(MAX_IOS);
    f.io_count = k as u32;
    for (j, (io, e)) in snap.ios[..k].iter().zip(f.ios.iter_mut()).enumerate() {
        put_str(&mut e.name, &m.ios[j].name);
        e.attached = u8::from(io.attached);
        e.counters = io.counters;
    }
}

/// The owner of each axis by name (`name_of` a token: the control thread's
/// table of owners).
pub fn owners<'a>(snap: &Snapshot, name_of: impl Fn(u64) -> Option<&'a str>, f: &mut StatusFrame) {
    let n = (f.axis_count as usize).min(snap.axis_count);
    for (a, e) in snap.axes[..n].iter().zip(f.axes.iter_mut()) {
        let owner = if a.owner != 0 {
            name_of(a.owner).unwrap_or("?")
        } else {
            ""
        };
        put_str(&mut e.owner, owner);
    }
}
