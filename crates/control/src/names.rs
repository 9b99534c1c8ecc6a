//! The numbers of the status frame's operation fields in words: the
//! engine's spellings (`motion_homing::operation`), "?" for a number no
//! spelling has (a frame of a newer supervisor).

use motion_homing::{OpKind, StopCause};

/// `AxisStatusEntry::op_kind` in words.
pub fn op_kind(n: u8) -> &'static str {
    OpKind::from_number(n).map_or("?", OpKind::name)
}

/// `AxisStatusEntry::last_stop` in words.
pub fn stop_cause(n: u8) -> &'static str {
    StopCause::from_number(n).map_or("?", StopCause::name)
}
