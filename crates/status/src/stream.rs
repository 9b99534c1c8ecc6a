//! The setpoint stream's intake counters, declared once: the cycle's intake
//! counts into [`StreamCounts`], the snapshot copies it, the status frame
//! carries it as it is, and `status --json` shows it as it is.

#[cfg(feature = "zero-copy")]
use iceoryx2_bb_derive_macros::{PlacementDefault, ZeroCopySend};
#[cfg(feature = "zero-copy")]
use iceoryx2_bb_elementary_traits::{
    placement_default::PlacementDefault, zero_copy_send::ZeroCopySend,
};
use serde::{Deserialize, Serialize};

/// Frames taken and refused by why (since start), streams granted and
/// running.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct StreamCounts {
    /// Frames that reached the intake's checks.
    pub frames: u64,
    /// Setpoints handed to engines (a gantry's counts once).
    pub setpoints: u64,
    /// Refused: another layout, without the session key, too many entries,
    /// a token owning none of the axes, a sequence number not above the
    /// last, an entry for an axis the token does not own.
    pub refused_layout: u64,
    pub refused_key: u64,
    pub refused_count: u64,
    pub refused_token: u64,
    pub refused_sequence: u64,
    pub refused_axis: u64,
    /// Streams granted since start.
    pub acquired: u32,
    /// Streams running now (programs owning axes).
    pub owners: u32,
}

const _: () = assert!(core::mem::size_of::<StreamCounts>() == 72);
