//! What the supervisor keeps across restarts, in `state_dir`:
//!
//! * [`reference`] — the stored reference (raw → axis offset) of every
//!   absolute axis, one small JSON file per axis, written atomically, with
//!   the axis configuration it belongs to and, once it can no longer be
//!   trusted, why;
//! * [`record`] — the homing record: one JSON line per homing outcome,
//!   restore and invalidation, appended;
//! * [`drift`] — the check that compares a homing's event with the recent
//!   events of the same axis.
//!
//! None of this runs in the real-time thread: the control thread reads and
//! writes these files. Everything read back is treated as untrusted input
//! (size-capped, owner-checked, parsed strictly; a file that fails any check
//! is reported and never restored).

pub mod atomic;
pub mod dir;
pub mod drift;
pub mod record;
pub mod reference;

pub use dir::{StateDir, StateError};
pub use drift::{Drift, DriftHistory};
pub use record::{HomingRecord, RecordEntry, RecordKind};
pub use reference::{AxisIdentity, Loaded, StoredReference};

/// Now as RFC 3339 UTC with milliseconds, and as Unix milliseconds.
pub fn now_stamp() -> (String, u64) {
    let now = std::time::SystemTime::now();
    let ms = now
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as u64);
    (humantime::format_rfc3339_millis(now).to_string(), ms)
}
