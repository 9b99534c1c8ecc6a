//! The numbers of the status frame's operation fields in words (the
//! engine's spellings).

/// `AxisStatusEntry::op_kind` in words.
pub fn op_kind(n: u8) -> &'static str {
    // FIXME(ops): the engine's OpKind spellings
    match n {
        0 => "none",
        _ => "?",
    }
}

/// `AxisStatusEntry::last_stop` in words.
pub fn stop_cause(n: u8) -> &'static str {
    // FIXME(ops): the engine's StopCause spellings
    match n {
        0 => "none",
        _ => "?",
    }
}
