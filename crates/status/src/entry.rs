//! The wire entry of one axis in the status frame: its identity as text,
//! then the table's three areas — one `flags` word, `ints` and `values` —
//! each with room to spare (see [`crate::schema`] for the rule). The rows
//! of [`crate::axis`] say what each bit and slot holds; their accessors
//! (`entry.homed()`, `entry.position()`) are generated there.
//!
//! `#[repr(C)]`, only integers, floats and byte arrays, no implicit padding
//! (asserted below), so any language can read it from the layout
//! description `motion-control` writes.

#[cfg(feature = "zero-copy")]
use iceoryx2_bb_derive_macros::{PlacementDefault, ZeroCopySend};
#[cfg(feature = "zero-copy")]
use iceoryx2_bb_elementary_traits::{
    placement_default::PlacementDefault, zero_copy_send::ZeroCopySend,
};

use crate::schema::{INT_SLOTS, VALUE_SLOTS};
use crate::text::{get_str, put_str, NAME_LEN, PHASE_LEN};

/// One axis of the status frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct AxisStatusEntry {
    pub name: [u8; NAME_LEN],
    /// Homing phase by name (`idle`, `seek`, ...), NUL-padded.
    pub phase: [u8; PHASE_LEN],
    /// The program that owns the axis (setpoint stream), NUL-padded;
    /// empty: none.
    pub owner: [u8; NAME_LEN],
    /// Index of its I/O process in the frame's `ios`.
    pub io: u32,
    pub reserved: u32,
    /// The table's flag rows, one bit each.
    pub flags: u64,
    /// The table's integer and enumeration rows.
    pub ints: [u32; INT_SLOTS],
    /// The table's number rows (NaN: no value).
    pub values: [f64; VALUE_SLOTS],
}

impl Default for AxisStatusEntry {
    /// No name, no flags, integers 0, no values (NaN).
    fn default() -> Self {
        Self {
            name: [0; NAME_LEN],
            phase: [0; PHASE_LEN],
            owner: [0; NAME_LEN],
            io: 0,
            reserved: 0,
            flags: 0,
            ints: [0; INT_SLOTS],
            values: [f64::NAN; VALUE_SLOTS],
        }
    }
}

impl AxisStatusEntry {
    pub fn name_text(&self) -> String {
        get_str(&self.name)
    }

    pub fn phase_text(&self) -> String {
        get_str(&self.phase)
    }

    /// The owning program's name, if a program owns the axis.
    pub fn owner_text(&self) -> Option<String> {
        Some(get_str(&self.owner)).filter(|o| !o.is_empty())
    }

    /// Sets the texts of the entry (name, phase) and its I/O process.
    pub fn set_identity(&mut self, name: &str, phase: &str, io: usize) {
        put_str(&mut self.name, name);
        put_str(&mut self.phase, phase);
        self.io = io as u32;
    }
}

const _: () = {
    use core::mem::{align_of, offset_of, size_of};
    assert!(offset_of!(AxisStatusEntry, io) == 80);
    assert!(offset_of!(AxisStatusEntry, flags) == 88);
    assert!(offset_of!(AxisStatusEntry, ints) == 96);
    assert!(offset_of!(AxisStatusEntry, values) == 96 + 4 * INT_SLOTS);
    assert!(size_of::<AxisStatusEntry>() == 96 + 4 * INT_SLOTS + 8 * VALUE_SLOTS);
    assert!(align_of::<AxisStatusEntry>() == 8);
};
