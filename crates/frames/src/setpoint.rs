//! The supervised setpoint stream's message: a program that owns axes
//! (granted through the control service, which hands it an owner token)
//! publishes [`SetpointFrame`]s on `{prefix}/setpoints`; the supervisor's
//! real-time thread is the only subscriber.
//!
//! The same layout rules as the frames (`frame.rs`): `#[repr(C)]`, only
//! fixed-size integers and floats, padding spelled out, the layout pinned by
//! compile-time asserts and carried in the iceoryx2 type name
//! ([`SETPOINT_FRAME_TYPE_NAME`]), so a client of another layout cannot even
//! open the service. Clients in other languages mirror it field by field
//! (the Python package in `python/` does, with `ctypes`, checked
//! field by field against the description `crates/control/tests/wire_layout.rs`
//! writes).
//!
//! What the supervisor checks before a setpoint reaches an engine
//! ([`SetpointFrame::check`], then the cycle's intake): the layout, the
//! session key, the axis count; then, per frame, that `token` owns the axes
//! it names and that `seq` increases per token. Everything else — finite,
//! inside the travel limits, reachable at `max_speed`, in time order, fresh —
//! is the engine's check of each setpoint, which stops the axis with an
//! error when one fails.

use core::fmt;

#[cfg(feature = "zero-copy")]
use iceoryx2_bb_derive_macros::{PlacementDefault, ZeroCopySend};
#[cfg(feature = "zero-copy")]
use iceoryx2_bb_elementary_traits::{
    placement_default::PlacementDefault, zero_copy_send::ZeroCopySend,
};

use crate::frame::MAX_AXES;

/// Expands to the setpoint layout version as a literal (spliced into the
/// type name with `concat!`: the single source of the number).
macro_rules! setpoint_layout_literal {
    () => {
        1
    };
}

/// Version of the [`SetpointFrame`] layout. Bump it on ANY change.
pub const SETPOINT_LAYOUT: u32 = setpoint_layout_literal!();

/// iceoryx2 type name of [`SetpointFrame`]; contains [`SETPOINT_LAYOUT`].
pub const SETPOINT_FRAME_TYPE_NAME: &str = concat!(
    "motion_frames::SetpointFrame@layout",
    setpoint_layout_literal!()
);

/// [`SetpointAxis::flags`] bit 0: `velocity` is a feed-forward to use (else
/// the supervisor uses the velocity of the interpolated segment).
/// Bits 1..=31 are reserved: sent as 0, ignored by the receiver.
pub const SP_VELOCITY: u32 = 1 << 0;

/// One axis's setpoint.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct SetpointAxis {
    /// Index of the axis in the machine configuration (config order, from
    /// 0), as the stream-acquire answer names it. A gantry is addressed by
    /// its first side; the setpoint moves every side in the same cycle.
    pub axis: u32,
    /// [`SP_VELOCITY`].
    pub flags: u32,
    /// Position in AXIS coordinates (the reference homing established),
    /// position units.
    pub position: f64,
    /// Velocity feed-forward, units/s (with [`SP_VELOCITY`]).
    pub velocity: f64,
}

/// A program → the supervisor, whenever it has new setpoints (every cycle,
/// or less often: the supervisor interpolates linearly between consecutive
/// setpoints of an axis).
///
/// The iceoryx2 type name is [`SETPOINT_FRAME_TYPE_NAME`].
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "zero-copy", derive(PlacementDefault))]
pub struct SetpointFrame {
    /// [`SETPOINT_LAYOUT`].
    pub layout_version: u32,
    /// The supervisor's session id (the domain id of its session file, as
    /// the control service's answers carry it).
    pub session: u32,
    /// The session key from the supervisor's session file, as in every
    /// control request (two u64, the key's first 16 hex digits first).
    pub key: [u64; 2],
    /// The owner token the stream-acquire answer handed out.
    pub token: u64,
    /// Per token, increasing (frames whose `seq` is not above the last one
    /// accepted for the token are refused: replays, reordering).
    pub seq: u64,
    /// Time of these setpoints on the program's own monotonic timeline, ns:
    /// the supervisor interpolates over the difference to the previous
    /// setpoint's time, never over its own clock.
    pub t_ns: u64,
    /// Valid entries of `axes`.
    pub count: u32,
    /// Always 0.
    pub reserved: u32,
    pub axes: [SetpointAxis; MAX_AXES],
}

impl SetpointAxis {
    /// All-zero entry.
    pub const ZERO: Self = Self {
        axis: 0,
        flags: 0,
        position: 0.0,
        velocity: 0.0,
    };

    /// The velocity feed-forward, if the entry carries one.
    pub fn feed_forward(&self) -> Option<f64> {
        (self.flags & SP_VELOCITY != 0).then_some(self.velocity)
    }
}

impl SetpointFrame {
    /// All-zero frame (same bytes as iceoryx2's `PlacementDefault`).
    pub const ZERO: Self = Self {
        layout_version: 0,
        session: 0,
        key: [0; 2],
        token: 0,
        seq: 0,
        t_ns: 0,
        count: 0,
        reserved: 0,
        axes: [SetpointAxis::ZERO; MAX_AXES],
    };

    /// The valid entries (`count`, clamped to [`MAX_AXES`]).
    pub fn entries(&self) -> &[SetpointAxis] {
        &self.axes[..(self.count as usize).min(MAX_AXES)]
    }

    /// Whether a received frame may be looked at any further: this layout,
    /// this session's key, at most [`MAX_AXES`] entries. Nothing else of the
    /// frame is trusted yet. No allocation.
    pub fn check(&self, key: [u64; 2]) -> Result<(), SetpointRefusal> {
        if self.layout_version != SETPOINT_LAYOUT {
            return Err(SetpointRefusal::Layout);
        }
        if self.key != key {
            return Err(SetpointRefusal::Key);
        }
        if self.count as usize > MAX_AXES {
            return Err(SetpointRefusal::Count);
        }
        Ok(())
    }
}

impl Default for SetpointFrame {
    fn default() -> Self {
        Self::ZERO
    }
}

/// Why a setpoint frame (or one entry of it) was refused before any engine
/// saw it. Counted by kind in the supervisor's status.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SetpointRefusal {
    /// Another layout version.
    Layout,
    /// Without this session's key (not from a peer of this supervisor).
    Key,
    /// More entries than a frame has.
    Count,
    /// The token owns none of the axes named, or no axis at all (a stale
    /// or forged token, a released stream).
    Token,
    /// `seq` not above the last accepted frame of the token.
    Sequence,
    /// An entry names an axis the token does not own (or a gantry side
    /// other than the first).
    Axis,
}

impl fmt::Display for SetpointRefusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SetpointRefusal::Layout => "another setpoint layout",
            SetpointRefusal::Key => "without this session's key",
            SetpointRefusal::Count => "more entries than a frame holds",
            SetpointRefusal::Token => "a token that owns no axis",
            SetpointRefusal::Sequence => "a sequence number not above the last one",
            SetpointRefusal::Axis => "an axis the token does not own",
        })
    }
}

const _: () = {
    use core::mem::{align_of, offset_of, size_of};
    assert!(
        SETPOINT_LAYOUT == 1,
        "update the layout asserts together with SETPOINT_LAYOUT"
    );
    assert!(size_of::<SetpointAxis>() == 24);
    assert!(offset_of!(SetpointAxis, flags) == 4);
    assert!(offset_of!(SetpointAxis, position) == 8);
    assert!(offset_of!(SetpointAxis, velocity) == 16);
    assert!(4 + 4 + 8 + 8 == size_of::<SetpointAxis>());

    assert!(align_of::<SetpointFrame>() == 8);
    assert!(offset_of!(SetpointFrame, session) == 4);
    assert!(offset_of!(SetpointFrame, key) == 8);
    assert!(offset_of!(SetpointFrame, token) == 24);
    assert!(offset_of!(SetpointFrame, seq) == 32);
    assert!(offset_of!(SetpointFrame, t_ns) == 40);
    assert!(offset_of!(SetpointFrame, count) == 48);
    assert!(offset_of!(SetpointFrame, reserved) == 52);
    assert!(offset_of!(SetpointFrame, axes) == 56);
    assert!(size_of::<SetpointFrame>() == 56 + 24 * MAX_AXES);
    assert!(size_of::<SetpointFrame>() == 1592);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_type_name_carries_the_layout() {
        assert_eq!(
            SETPOINT_FRAME_TYPE_NAME,
            "motion_frames::SetpointFrame@layout1"
        );
    }

    #[test]
    fn check_refuses_layout_key_and_count() {
        let key = [7, 9];
        let mut f = SetpointFrame {
            layout_version: SETPOINT_LAYOUT,
            key,
            count: 2,
            ..SetpointFrame::ZERO
        };
        assert_eq!(f.check(key), Ok(()));
        assert_eq!(f.entries().len(), 2);
        assert_eq!(f.check([7, 8]), Err(SetpointRefusal::Key));
        f.count = MAX_AXES as u32 + 1;
        assert_eq!(f.check(key), Err(SetpointRefusal::Count));
        assert_eq!(f.entries().len(), MAX_AXES, "clamped, never a panic");
        f.layout_version = 0;
        assert_eq!(f.check(key), Err(SetpointRefusal::Layout));
        let a = SetpointAxis {
            flags: SP_VELOCITY,
            velocity: 2.5,
            ..SetpointAxis::ZERO
        };
        assert_eq!(a.feed_forward(), Some(2.5));
        assert_eq!(SetpointAxis::ZERO.feed_forward(), None);
    }
}
