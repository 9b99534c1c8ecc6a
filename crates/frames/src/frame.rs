//! The shared-memory frames exchanged once per cycle between `motion-supervisor`
//! and `motion-io`.
//!
//! # Layout rules
//!
//! Every type here is `#[repr(C)]`, holds only fixed-size integers and floats
//! (no pointers, no `bool`, no enums), and spells its padding out as explicit
//! `reserved` fields, so there is no implicit padding: the byte image is the same
//! in both processes and every byte of a published frame is written (no stale
//! bytes of an earlier sample leak through). The sizes and field offsets are
//! pinned by compile-time asserts at the bottom of this file: changing the
//! layout fails the build until [`LAYOUT_VERSION`] and the asserts are updated
//! together.
//!
//! Writers set `reserved` fields to 0, readers ignore them.
//!
//! # Versioning
//!
//! [`CommandFrame`] and [`FeedbackFrame`] carry an explicit iceoryx2 type name
//! that contains [`LAYOUT_VERSION`] ([`COMMAND_FRAME_TYPE_NAME`],
//! [`FEEDBACK_FRAME_TYPE_NAME`]). iceoryx2 compares type name, size and alignment
//! when a process opens a service, so two binaries built with different layouts
//! cannot connect at all (`motion_ipc::IpcError::LayoutMismatch`). The
//! [`FrameHeader::layout_version`] field is checked again on every received frame
//! ([`FrameHeader::check`]) as defense in depth.
//!
//! The iceoryx2 traits themselves (`ZeroCopySend`, `PlacementDefault`) are
//! derived here and implemented in `zero_copy.rs`, both only with the
//! `zero-copy` feature (see the crate documentation).

use core::fmt;

#[cfg(feature = "zero-copy")]
use iceoryx2_bb_derive_macros::{PlacementDefault, ZeroCopySend};
#[cfg(feature = "zero-copy")]
use iceoryx2_bb_elementary_traits::{
    placement_default::PlacementDefault, zero_copy_send::ZeroCopySend,
};

/// Expands to the layout version as a literal, so it can be spliced into the
/// iceoryx2 type names with `concat!` (the single source of the number).
macro_rules! layout_version_literal {
    () => {
        3
    };
}

/// Version of the frame layout defined in this file. Bump it on ANY change of
/// a frame type (field, order, size, meaning of a bit).
pub const LAYOUT_VERSION: u32 = layout_version_literal!();

/// Maximum number of axes one frame carries.
pub const MAX_AXES: usize = 64;

/// iceoryx2 type name of [`CommandFrame`]; contains [`LAYOUT_VERSION`].
pub const COMMAND_FRAME_TYPE_NAME: &str = concat!(
    "motion_frames::CommandFrame@layout",
    layout_version_literal!()
);

/// iceoryx2 type name of [`FeedbackFrame`]; contains [`LAYOUT_VERSION`].
pub const FEEDBACK_FRAME_TYPE_NAME: &str = concat!(
    "motion_frames::FeedbackFrame@layout",
    layout_version_literal!()
);

/// [`AxisCommand::control_word`] bit 0: request the power stage on.
pub const CW_ENABLE: u16 = 1 << 0;
/// [`AxisCommand::control_word`] bit 1: fault reset (MAFR). Its rising edge
/// asks the drive to clear a fault: CiA 402 control word bit 7 on EtherCAT,
/// the plant's fault in the `sim`. It never enables anything by itself.
pub const CW_FAULT_RESET: u16 = 1 << 1;
/// [`AxisCommand::control_word`] bit 2: the drive homes the axis itself
/// (CiA 402 homing mode on EtherCAT; a `drive_homing` axis's drive-homing
/// leg). Set for the whole request; its fall ends it (the drive halts if it
/// has not attained home, and hands back to cyclic position mode with its
/// set-point taken from its actual position first). A backend that cannot
/// home by the drive answers [`SW_DRIVE_HOMING_ERROR`].
/// Bits 3..=15 are reserved: sent as 0, ignored by the receiver.
pub const CW_DRIVE_HOME: u16 = 1 << 2;

/// [`AxisFeedback::status_word`] bit 0: power stage on and following the command.
pub const SW_ENABLED: u16 = 1 << 0;
/// [`AxisFeedback::status_word`] bit 1: drive fault (following error, overload, ...);
/// the drive no longer follows the command.
pub const SW_FAULT: u16 = 1 << 1;
/// [`AxisFeedback::status_word`] bit 2: the I/O process has no fresh data for
/// this axis this cycle (a fieldbus frame lost, a working-counter mismatch, a
/// SubDevice out of OP). The rest of the entry is the last known state and
/// must not be used as feedback: the supervisor counts the axis as missing
/// feedback, and its loss rule decides.
pub const SW_NO_DATA: u16 = 1 << 2;
/// [`AxisFeedback::status_word`] bit 3: the axis's drive is lost while the
/// I/O process is alive (EtherCAT: its SubDevice does not answer, is out of
/// OP, or was power-cycled), always together with [`SW_NO_DATA`]. The
/// supervisor names the loss after the drive (ERR 12 / EXERR 45), not after
/// the I/O process; the I/O process's log says which device and what to do.
pub const SW_DRIVE_LOST: u16 = 1 << 3;
/// [`AxisFeedback::status_word`] bit 4: the drive's own homing is in force
/// for the [`CW_DRIVE_HOME`] request (homing mode confirmed by the drive),
/// or the drive is still handing back after it: the drive, not the command,
/// moves the axis.
pub const SW_DRIVE_HOMING: u16 = 1 << 4;
/// [`AxisFeedback::status_word`] bit 5: with [`SW_DRIVE_HOMING`], the drive
/// attained home (CiA 402 statusword bits 12 and 10) and redefined its
/// position: its position 0 is the home point.
pub const SW_DRIVE_HOMED: u16 = 1 << 5;
/// [`AxisFeedback::status_word`] bit 6: the drive reports a homing error
/// (CiA 402 statusword bit 13), did not take homing mode within its bound,
/// or cannot home by itself.
/// Bits 7..=15 are reserved: sent as 0, ignored by the receiver.
pub const SW_DRIVE_HOMING_ERROR: u16 = 1 << 6;

/// [`AxisFeedback::digital_inputs`] bit 0: home switch contact closed (electrical level).
pub const DI_HOME_SWITCH: u32 = 1 << 0;
/// [`AxisFeedback::digital_inputs`] bit 1: positive hardware overtravel tripped.
pub const DI_OVERTRAVEL_POSITIVE: u32 = 1 << 1;
/// [`AxisFeedback::digital_inputs`] bit 2: negative hardware overtravel tripped.
/// Bits 3..=31 are reserved: sent as 0, ignored by the receiver.
pub const DI_OVERTRAVEL_NEGATIVE: u32 = 1 << 2;
/// [`AxisFeedback::digital_inputs`] bit 3: an encoder index pulse passed during
/// the last cycle (for drives that cannot latch the marker position).
pub const DI_MARKER_PULSE: u32 = 1 << 3;

/// [`AxisCommand::switch_arm_edge`]: latch on the open → closed transition.
pub const EDGE_RISING: u8 = 0;
/// [`AxisCommand::switch_arm_edge`]: latch on the closed → open transition.
pub const EDGE_FALLING: u8 = 1;

/// Header in front of every frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct FrameHeader {
    /// [`LAYOUT_VERSION`] of the sender. Stamped by the `publish` helpers.
    pub layout_version: u32,
    /// Number of valid entries at the start of the `axes` array (≤ [`MAX_AXES`]).
    pub axis_count: u32,
    /// Per-sender frame counter, starting at 1 (0 = never sent). Stamped by the
    /// `publish` helpers.
    pub sequence: u64,
    /// `CLOCK_MONOTONIC` of the sender, in ns, taken right before the frame was
    /// sent. `CLOCK_MONOTONIC` is system-wide on Linux, so the receiver can
    /// compare it with its own clock (`motion_ipc::monotonic_ns`).
    pub timestamp_ns: u64,
    /// Random per process start of the sender: a new value means the peer
    /// was restarted (its sequence numbers start again at 1, and the
    /// supervisor treats a restarted I/O process as a reconnection).
    pub origin: u64,
    /// The session key of the supervisor this frame belongs to (128 random
    /// bits, per supervisor start, handed over in the owner-only session
    /// file). Both sides refuse frames without it.
    pub key: [u64; 2],
}

/// Why a received frame header is not acceptable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayoutError {
    /// The frame was written by a binary that speaks another layout.
    VersionMismatch {
        /// Layout of this binary ([`LAYOUT_VERSION`]).
        ours: u32,
        /// Layout found in the frame header.
        theirs: u32,
    },
    /// `axis_count` exceeds [`MAX_AXES`].
    TooManyAxes {
        /// The `axis_count` found in the frame header.
        axis_count: u32,
    },
}

impl fmt::Display for LayoutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LayoutError::VersionMismatch { ours, theirs } => write!(
                f,
                "frame layout mismatch: this binary speaks layout {ours}, the frame carries \
                 layout {theirs}; the peer was built with another motion-frames version; \
                 rebuild both from the same tree"
            ),
            LayoutError::TooManyAxes { axis_count } => write!(
                f,
                "frame declares {axis_count} axes but a frame carries at most {MAX_AXES}"
            ),
        }
    }
}

impl std::error::Error for LayoutError {}

impl FrameHeader {
    /// All-zero header (layout 0, no axes, sequence 0).
    pub const ZERO: Self = Self {
        layout_version: 0,
        axis_count: 0,
        sequence: 0,
        timestamp_ns: 0,
        origin: 0,
        key: [0; 2],
    };

    /// Checks the layout version and the axis count of a received frame.
    pub fn check(&self) -> Result<(), LayoutError> {
        if self.layout_version != LAYOUT_VERSION {
            return Err(LayoutError::VersionMismatch {
                ours: LAYOUT_VERSION,
                theirs: self.layout_version,
            });
        }
        if self.axis_count as usize > MAX_AXES {
            return Err(LayoutError::TooManyAxes {
                axis_count: self.axis_count,
            });
        }
        Ok(())
    }

    /// `axis_count` clamped to [`MAX_AXES`] (safe to slice with).
    pub fn axis_count_clamped(&self) -> usize {
        (self.axis_count as usize).min(MAX_AXES)
    }
}

/// One cycle's command for one axis, in drive units (counts).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct AxisCommand {
    /// Raw position set-point, counts.
    pub target_position: i64,
    /// Velocity set-point / feed-forward, counts/s.
    pub target_velocity: f64,
    /// Torque limit in the positive direction, % rated, magnitude.
    pub torque_limit_positive: f32,
    /// Torque limit in the negative direction, % rated, magnitude.
    pub torque_limit_negative: f32,
    /// Position error tolerance, counts (0 = check off).
    pub position_error_tolerance: f64,
    /// Velocity error tolerance, counts/s (0 = check off).
    pub velocity_error_tolerance: f64,
    /// Control bits: bit 0 [`CW_ENABLE`] (request power stage on), bit 1
    /// [`CW_FAULT_RESET`], bit 2 [`CW_DRIVE_HOME`]; bits 3..=15 reserved (0).
    pub control_word: u16,
    /// Marker latch arm request id (0 = disarmed; a new non-zero value re-arms).
    pub marker_arm_id: u8,
    /// Home-switch (registration) latch arm request id (0 = disarmed).
    pub switch_arm_id: u8,
    /// Edge the switch latch takes: [`EDGE_RISING`] (0) or [`EDGE_FALLING`] (1).
    pub switch_arm_edge: u8,
    /// Explicit padding to 8-byte alignment; always 0.
    pub reserved: [u8; 3],
}

/// One cycle's feedback for one axis, in drive units (counts).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "zero-copy", derive(ZeroCopySend, PlacementDefault))]
pub struct AxisFeedback {
    /// Raw actual position, counts.
    pub position: i64,
    /// Actual velocity, counts/s.
    pub velocity: f64,
    /// Actual torque, % rated, signed (positive pushes forward).
    pub torque: f32,
    /// Input bits: [`DI_HOME_SWITCH`] (bit 0, contact closed),
    /// [`DI_OVERTRAVEL_POSITIVE`] (bit 1), [`DI_OVERTRAVEL_NEGATIVE`] (bit 2),
    /// [`DI_MARKER_PULSE`] (bit 3);
    /// bits 3..=31 reserved (0).
    pub digital_inputs: u32,
    /// Status bits: [`SW_ENABLED`] (bit 0), [`SW_FAULT`] (bit 1),
    /// [`SW_NO_DATA`] (bit 2), [`SW_DRIVE_LOST`] (bit 3), [`SW_DRIVE_HOMING`]
    /// (bit 4), [`SW_DRIVE_HOMED`] (bit 5), [`SW_DRIVE_HOMING_ERROR`] (bit 6);
    /// bits 7..=15 reserved (0).
    pub status_word: u16,
    /// Id of the marker arm request this latch state belongs to (0 = disarmed).
    pub marker_latch_id: u8,
    /// 1 = the marker latch holds a position, 0 = not (yet) latched.
    pub marker_latched: u8,
    /// Id of the switch arm request this latch state belongs to (0 = disarmed).
    pub switch_latch_id: u8,
    /// 1 = the switch latch holds a position, 0 = not (yet) latched.
    pub switch_latched: u8,
    /// The drive's own error code while it reports a fault (CiA 402 object
    /// 0x603F), kept for the operator; 0 = none or not known.
    pub error_code: u16,
    /// Raw position of the latched marker edge, counts (valid when `marker_latched`).
    pub marker_latch_position: i64,
    /// Raw position of the latched switch edge, counts (valid when `switch_latched`).
    pub switch_latch_position: i64,
}

impl AxisCommand {
    /// All-zero command (disabled, everything 0).
    pub const ZERO: Self = Self {
        target_position: 0,
        target_velocity: 0.0,
        torque_limit_positive: 0.0,
        torque_limit_negative: 0.0,
        position_error_tolerance: 0.0,
        velocity_error_tolerance: 0.0,
        control_word: 0,
        marker_arm_id: 0,
        switch_arm_id: 0,
        switch_arm_edge: EDGE_RISING,
        reserved: [0; 3],
    };
}

impl AxisFeedback {
    /// All-zero feedback.
    pub const ZERO: Self = Self {
        position: 0,
        velocity: 0.0,
        torque: 0.0,
        digital_inputs: 0,
        status_word: 0,
        marker_latch_id: 0,
        marker_latched: 0,
        switch_latch_id: 0,
        switch_latched: 0,
        error_code: 0,
        marker_latch_position: 0,
        switch_latch_position: 0,
    };
}

/// Supervisor → motion-io, once per cycle.
///
/// The iceoryx2 type name is [`COMMAND_FRAME_TYPE_NAME`] (implemented by hand
/// in `zero_copy.rs` instead of `#[derive(ZeroCopySend)]`, because the derive's
/// `#[type_name("..")]` only takes a plain literal and could drift from
/// [`LAYOUT_VERSION`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "zero-copy", derive(PlacementDefault))]
pub struct CommandFrame {
    pub header: FrameHeader,
    /// The first `header.axis_count` entries are valid.
    pub axes: [AxisCommand; MAX_AXES],
}

/// motion-io → supervisor, once per received command.
///
/// The iceoryx2 type name is [`FEEDBACK_FRAME_TYPE_NAME`].
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "zero-copy", derive(PlacementDefault))]
pub struct FeedbackFrame {
    pub header: FrameHeader,
    /// `header.sequence` of the [`CommandFrame`] this feedback answers
    /// (0 = none received yet).
    pub answers_sequence: u64,
    /// `CLOCK_MONOTONIC` ns at which motion-io took that command.
    pub io_received_ns: u64,
    /// The first `header.axis_count` entries are valid.
    pub axes: [AxisFeedback; MAX_AXES],
}

impl CommandFrame {
    /// All-zero frame (same bytes as [`Default`] and iceoryx2's `PlacementDefault`).
    pub const ZERO: Self = Self {
        header: FrameHeader::ZERO,
        axes: [AxisCommand::ZERO; MAX_AXES],
    };

    /// The valid axes (`header.axis_count`, clamped to [`MAX_AXES`]).
    pub fn active_axes(&self) -> &[AxisCommand] {
        &self.axes[..self.header.axis_count_clamped()]
    }
}

impl FeedbackFrame {
    /// All-zero frame (same bytes as [`Default`] and iceoryx2's `PlacementDefault`).
    pub const ZERO: Self = Self {
        header: FrameHeader::ZERO,
        answers_sequence: 0,
        io_received_ns: 0,
        axes: [AxisFeedback::ZERO; MAX_AXES],
    };

    /// The valid axes (`header.axis_count`, clamped to [`MAX_AXES`]).
    pub fn active_axes(&self) -> &[AxisFeedback] {
        &self.axes[..self.header.axis_count_clamped()]
    }
}

impl Default for CommandFrame {
    fn default() -> Self {
        Self::ZERO
    }
}

impl Default for FeedbackFrame {
    fn default() -> Self {
        Self::ZERO
    }
}

/// What both frame types share; lets the port helpers stamp headers
/// generically (`motion-ipc` adds iceoryx2's traits to the bound).
pub trait Frame: fmt::Debug + Copy + Default + 'static {
    /// Human-readable name used in error messages.
    const NAME: &'static str;
    /// The iceoryx2 type name (equal to `ZeroCopySend::type_name()` with the
    /// `zero-copy` feature).
    const TYPE_NAME: &'static str;
    fn header(&self) -> &FrameHeader;
    fn header_mut(&mut self) -> &mut FrameHeader;
}

impl Frame for CommandFrame {
    const NAME: &'static str = "command frame";
    const TYPE_NAME: &'static str = COMMAND_FRAME_TYPE_NAME;
    fn header(&self) -> &FrameHeader {
        &self.header
    }
    fn header_mut(&mut self) -> &mut FrameHeader {
        &mut self.header
    }
}

impl Frame for FeedbackFrame {
    const NAME: &'static str = "feedback frame";
    const TYPE_NAME: &'static str = FEEDBACK_FRAME_TYPE_NAME;
    fn header(&self) -> &FrameHeader {
        &self.header
    }
    fn header_mut(&mut self) -> &mut FrameHeader {
        &mut self.header
    }
}

// ---------------------------------------------------------------------------
// Compile-time layout pins. Any accidental change of a frame type fails here.
// ---------------------------------------------------------------------------

const _: () = {
    use core::mem::{align_of, offset_of, size_of};

    assert!(
        LAYOUT_VERSION == 3,
        "update the layout asserts together with LAYOUT_VERSION"
    );

    assert!(size_of::<FrameHeader>() == 48);
    assert!(align_of::<FrameHeader>() == 8);
    assert!(offset_of!(FrameHeader, layout_version) == 0);
    assert!(offset_of!(FrameHeader, axis_count) == 4);
    assert!(offset_of!(FrameHeader, sequence) == 8);
    assert!(offset_of!(FrameHeader, timestamp_ns) == 16);
    assert!(offset_of!(FrameHeader, origin) == 24);
    assert!(offset_of!(FrameHeader, key) == 32);

    assert!(size_of::<AxisCommand>() == 48);
    assert!(align_of::<AxisCommand>() == 8);
    assert!(offset_of!(AxisCommand, target_position) == 0);
    assert!(offset_of!(AxisCommand, target_velocity) == 8);
    assert!(offset_of!(AxisCommand, torque_limit_positive) == 16);
    assert!(offset_of!(AxisCommand, torque_limit_negative) == 20);
    assert!(offset_of!(AxisCommand, position_error_tolerance) == 24);
    assert!(offset_of!(AxisCommand, velocity_error_tolerance) == 32);
    assert!(offset_of!(AxisCommand, control_word) == 40);
    assert!(offset_of!(AxisCommand, marker_arm_id) == 42);
    assert!(offset_of!(AxisCommand, switch_arm_id) == 43);
    assert!(offset_of!(AxisCommand, switch_arm_edge) == 44);
    assert!(offset_of!(AxisCommand, reserved) == 45);
    // no implicit padding: the fields add up to the size
    assert!(8 + 8 + 4 + 4 + 8 + 8 + 2 + 1 + 1 + 1 + 3 == size_of::<AxisCommand>());

    assert!(size_of::<AxisFeedback>() == 48);
    assert!(align_of::<AxisFeedback>() == 8);
    assert!(offset_of!(AxisFeedback, position) == 0);
    assert!(offset_of!(AxisFeedback, velocity) == 8);
    assert!(offset_of!(AxisFeedback, torque) == 16);
    assert!(offset_of!(AxisFeedback, digital_inputs) == 20);
    assert!(offset_of!(AxisFeedback, status_word) == 24);
    assert!(offset_of!(AxisFeedback, marker_latch_id) == 26);
    assert!(offset_of!(AxisFeedback, marker_latched) == 27);
    assert!(offset_of!(AxisFeedback, switch_latch_id) == 28);
    assert!(offset_of!(AxisFeedback, switch_latched) == 29);
    assert!(offset_of!(AxisFeedback, error_code) == 30);
    assert!(offset_of!(AxisFeedback, marker_latch_position) == 32);
    assert!(offset_of!(AxisFeedback, switch_latch_position) == 40);
    assert!(8 + 8 + 4 + 4 + 2 + 1 + 1 + 1 + 1 + 2 + 8 + 8 == size_of::<AxisFeedback>());

    assert!(size_of::<CommandFrame>() == 48 + MAX_AXES * 48);
    assert!(size_of::<CommandFrame>() == 3120);
    assert!(align_of::<CommandFrame>() == 8);
    assert!(offset_of!(CommandFrame, header) == 0);
    assert!(offset_of!(CommandFrame, axes) == 48);

    assert!(size_of::<FeedbackFrame>() == 48 + 8 + 8 + MAX_AXES * 48);
    assert!(size_of::<FeedbackFrame>() == 3136);
    assert!(align_of::<FeedbackFrame>() == 8);
    assert!(offset_of!(FeedbackFrame, header) == 0);
    assert!(offset_of!(FeedbackFrame, answers_sequence) == 48);
    assert!(offset_of!(FeedbackFrame, io_received_ns) == 56);
    assert!(offset_of!(FeedbackFrame, axes) == 64);
};

#[cfg(test)]
mod tests {
    use super::*;

    fn bytes_of<T: Copy>(v: &T) -> &[u8] {
        // SAFETY: the frame types have no implicit padding (asserted above), so
        // every byte is initialized.
        unsafe { core::slice::from_raw_parts((v as *const T).cast::<u8>(), size_of::<T>()) }
    }

    #[test]
    fn type_names_carry_the_layout_version() {
        let v = format!("@layout{LAYOUT_VERSION}");
        assert!(COMMAND_FRAME_TYPE_NAME.ends_with(&v));
        assert!(FEEDBACK_FRAME_TYPE_NAME.ends_with(&v));
        assert_ne!(COMMAND_FRAME_TYPE_NAME, FEEDBACK_FRAME_TYPE_NAME);
        // Other processes and the Python client open the services by these
        // very strings: the crate's name in them stays what it was.
        assert_eq!(
            COMMAND_FRAME_TYPE_NAME,
            "motion_frames::CommandFrame@layout3"
        );
        assert_eq!(
            FEEDBACK_FRAME_TYPE_NAME,
            "motion_frames::FeedbackFrame@layout3"
        );
    }

    #[test]
    fn default_is_all_zero_bytes() {
        assert!(bytes_of(&CommandFrame::default()).iter().all(|&b| b == 0));
        assert!(bytes_of(&FeedbackFrame::default()).iter().all(|&b| b == 0));
    }

    #[test]
    fn header_check_names_both_versions() {
        let mut h = FrameHeader {
            layout_version: LAYOUT_VERSION,
            axis_count: 3,
            ..FrameHeader::ZERO
        };
        assert_eq!(h.check(), Ok(()));
        h.layout_version = LAYOUT_VERSION + 1;
        let e = h.check().unwrap_err();
        assert_eq!(
            e,
            LayoutError::VersionMismatch {
                ours: LAYOUT_VERSION,
                theirs: LAYOUT_VERSION + 1
            }
        );
        let msg = e.to_string();
        assert!(msg.contains("layout mismatch"), "{msg}");
        assert!(msg.contains(&format!("layout {LAYOUT_VERSION}")), "{msg}");
        assert!(
            msg.contains(&format!("layout {}", LAYOUT_VERSION + 1)),
            "{msg}"
        );

        h.layout_version = LAYOUT_VERSION;
        h.axis_count = MAX_AXES as u32 + 1;
        assert_eq!(
            h.check(),
            Err(LayoutError::TooManyAxes {
                axis_count: MAX_AXES as u32 + 1
            })
        );
        assert_eq!(h.axis_count_clamped(), MAX_AXES);
    }

    #[test]
    fn active_axes_is_clamped() {
        let mut f = CommandFrame::default();
        f.header.axis_count = 2;
        assert_eq!(f.active_axes().len(), 2);
        f.header.axis_count = u32::MAX;
        assert_eq!(f.active_axes().len(), MAX_AXES);
        let mut g = FeedbackFrame::default();
        g.header.axis_count = 5;
        assert_eq!(g.active_axes().len(), 5);
    }
}
