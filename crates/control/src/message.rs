//! The messages of the control plane, `#[repr(C)]` with explicit padding.
//!
//! Like the frames: only fixed-size integers, floats and byte arrays (no
//! `bool`, no enums, no pointers), every byte written, the layout pinned by
//! compile-time asserts, and [`CONTROL_LAYOUT`] in the iceoryx2 type names,
//! so a client of another layout cannot even open the services. Text
//! (names, messages, report data) is UTF-8, NUL-padded.
//!
//! Any client can speak them: `tests/wire_layout.rs` writes their layout
//! description, with the status table's rows, to
//! `python/motion_supervisor_client/layout.json` (and fails when it is
//! stale); the Python package builds its `ctypes` classes and a property
//! per status row from that file and checks them against it field by
//! field.

use iceoryx2::prelude::{PlacementDefault, ZeroCopySend};

/// Layout version of every type in this file and of the status entries
/// (`motion-status`). Bump it on any change of a struct, and when a status
/// row moves, is removed or changes its type; a status row added in the
/// room of its area moves nothing and needs no bump (see
/// `motion_status::schema`).
pub const CONTROL_LAYOUT: u32 = 4;

/// Bytes of a name (axis, I/O process) and of a phase name; text fields
/// are written and read with `put_str` / `get_str`.
pub use motion_status::{get_str, put_str, NAME_LEN, PHASE_LEN};
/// Axes a message carries.
pub const MAX_AXES: usize = 64;
/// I/O processes a status frame carries.
pub const MAX_IOS: usize = 16;
/// Bytes of a response's message.
pub const MESSAGE_LEN: usize = 256;
/// Bytes of a response's data (a page of a report, a trace or a log).
pub const DATA_LEN: usize = 32 * 1024;
/// `AxisAnswer::index` of a name that is no axis.
pub const NO_INDEX: u16 = u16::MAX;

// ---- request kinds ----------------------------------------------------
/// Home the named axes (all: every axis, in home order).
pub const REQ_HOME: u32 = 1;
/// Stop (MAS) the named axes (all: every axis).
pub const REQ_STOP: u32 = 2;
/// Clear HomedStatus of the named axes.
pub const REQ_UNHOME: u32 = 3;
/// The status as JSON in `data` (`StatusReport`).
pub const REQ_STATUS: u32 = 4;
/// Latency statistics as JSON in `data` (`StatsReport`), paged by `offset`.
pub const REQ_STATS: u32 = 5;
/// Record every cycle of the next homing of the one named axis.
pub const REQ_TRACE: u32 = 6;
/// The recorded trace as CSV in `data`, paged by `offset`.
pub const REQ_TRACE_FETCH: u32 = 7;
/// The latency histograms as an HdrHistogram log in `data`, paged.
pub const REQ_HLOG: u32 = 8;
/// MSO: enable the drives of the named axes (all: every axis), holding
/// position.
pub const REQ_ENABLE: u32 = 9;
/// MSF: disable the drives of the named axes (all: every axis); a moving
/// axis is stopped first.
pub const REQ_DISABLE: u32 = 10;
/// MAFR: clear the axis fault of the named axes (all: every axis) and ask
/// their drives for a fault reset. Never enables, never moves.
pub const REQ_RESET: u32 = 11;
/// MAJ, hold to run: jog the one named axis (or gantry) at `speed` (its sign
/// is the direction) with `accel`/`decel`, for as long as the client renews
/// the lease (`lease_ms`, 50..=5000) with [`REQ_JOG_RENEW`]. The answer's
/// `token` names this jog.
pub const REQ_JOG: u32 = 12;
/// Renew the lease of the jog `token` on the named axes (none: wherever
/// that jog runs).
pub const REQ_JOG_RENEW: u32 = 13;
/// MAM: a trapezoidal move of the named axes (or gantry) to `position` (with
/// [`FLAG_RELATIVE`]: by `position`) at `speed`, `accel`, `decel`.
pub const REQ_MOVE: u32 = 14;
/// Take the named axes over for the supervised setpoint stream: `owner`
/// names the program, `node_id` its iceoryx2 node (the one that publishes;
/// the supervisor releases the axes when it is gone). The answer's `token`
/// is the owner token every setpoint frame must carry, and its `data` maps
/// each requested name to the axis index setpoints address (JSON, see
/// `crates/control/src/stream.rs`).
pub const REQ_STREAM_ACQUIRE: u32 = 15;
/// Give the axes of owner `token` back: the stream ends normally (the axes
/// stop, nothing else).
pub const REQ_STREAM_RELEASE: u32 = 16;

// ---- request flags ----------------------------------------------------
/// `REQ_STATS`: reset the "since reset" statistics after answering.
pub const FLAG_RESET: u32 = 1 << 0;
/// `REQ_STATS`, `REQ_HLOG`: since the last reset instead of since start.
pub const FLAG_SINCE_RESET: u32 = 1 << 1;
/// `REQ_HOME`: start every named axis at once, ignoring the home order.
pub const FLAG_PARALLEL: u32 = 1 << 2;
/// `REQ_MOVE`: `position` is a distance from where the move starts.
pub const FLAG_RELATIVE: u32 = 1 << 3;
/// `REQ_MOVE`: replace a running jog or move (without it, ERR 3 Execution
/// Collision). (A jog replaces a running jog by itself and never a move.)
pub const FLAG_SUPERSEDE: u32 = 1 << 4;
/// `REQ_JOG_RENEW`: end the jog now instead (a stop of this jog only: if
/// it no longer runs, nothing is stopped).
pub const FLAG_END: u32 = 1 << 5;

// ---- results ------------------------------------------------------------
/// Done / accepted for every addressed axis.
pub const RESULT_ACCEPTED: u32 = 0;
/// Refused (for at least one axis: see `axes`).
pub const RESULT_REFUSED: u32 = 1;
/// The request itself is malformed (kind, layout, names, offset).
pub const RESULT_BAD_REQUEST: u32 = 2;
/// The request does not carry this session's key: not from a peer of this
/// supervisor. Nothing was done.
pub const RESULT_FORBIDDEN: u32 = 3;
/// Nothing to fetch (no trace recorded yet, or the homing is still running).
pub const RESULT_NOT_READY: u32 = 4;

// ---- per-axis refusal reasons -------------------------------------------
pub const REASON_NONE: u8 = 0;
/// No axis of that name.
pub const REASON_UNKNOWN_AXIS: u8 = 1;
/// Homing is already in process on the axis.
pub const REASON_ALREADY_HOMING: u8 = 2;
/// The axis's I/O process is not attached.
pub const REASON_IO_NOT_ATTACHED: u8 = 3;
/// The Home instruction refuses: `err`/`exerr` say why (ERR 41: illegal
/// homing configuration, e.g. EXERR 20 active homing on a feedback-only axis).
pub const REASON_INSTRUCTION: u8 = 4;
/// The supervisor is shutting down.
pub const REASON_EXITING: u8 = 5;
/// The axis belongs to a gantry: home the gantry's axes together.
pub const REASON_GANTRY: u8 = 6;
/// Another home sequence is running on this axis.
pub const REASON_BUSY: u8 = 7;
/// A program owns the axis (setpoint stream): ERR 3 Execution Collision.
pub const REASON_OWNED: u8 = 8;
/// The token names no jog or stream of this axis (renew, release).
pub const REASON_TOKEN: u8 = 9;
/// The operation's instruction refuses: `err`/`exerr` say why (Logix
/// motion error codes: 5 servo off, 13 parameter out of range, 16 home in
/// process, 20 axis faulted, ...).
pub const REASON_OPERATION: u8 = 10;

/// Words for a refusal reason.
pub fn reason_text(reason: u8) -> &'static str {
    match reason {
        REASON_NONE => "accepted",
        REASON_UNKNOWN_AXIS => "unknown axis",
        REASON_ALREADY_HOMING => "already homing",
        REASON_IO_NOT_ATTACHED => "its I/O process is not attached",
        REASON_INSTRUCTION => "refused by the Home instruction",
        REASON_EXITING => "the supervisor is shutting down",
        REASON_GANTRY => "part of a gantry: name every side",
        REASON_BUSY => "another home sequence is running on it",
        REASON_OWNED => "a program owns it (setpoint stream)",
        REASON_TOKEN => "no jog or stream of this token runs on it",
        REASON_OPERATION => "refused by the instruction",
        _ => "refused",
    }
}

/// A request to the control service. Zero it, set `kind`, `flags`, the axes
/// and `offset`; the client sets `layout_version`, `key` and `request_id`.
/// The operation parameters (`position` .. `owner`) are read only by the
/// kinds that name them; an `f64` parameter that is NaN means "the axis's
/// default" (`speed`: `home_speed`, `accel`: `home_acceleration`, `decel`:
/// `home_deceleration`; a jog's `speed` and a move's `position` have none).
#[repr(C)]
#[derive(Clone, Copy, Debug, ZeroCopySend, PlacementDefault)]
#[type_name("motion_control::ControlRequest@4")]
pub struct ControlRequest {
    pub layout_version: u32,
    /// `REQ_*`.
    pub kind: u32,
    /// The session key from the supervisor's session file.
    pub key: [u64; 2],
    /// Chosen by the client, echoed in the response.
    pub request_id: u64,
    /// `FLAG_*`.
    pub flags: u32,
    /// Number of valid names in `axes`; 0 = every axis.
    pub axis_count: u32,
    /// Byte offset of the page asked for (`REQ_STATS`, `REQ_TRACE_FETCH`, `REQ_HLOG`).
    pub offset: u64,
    /// Optional: seconds `REQ_HOME` may take before the axes are stopped
    /// (0 = the axes' own `home_timeout` only).
    pub timeout_s: f64,
    /// `REQ_MOVE`: target in axis coordinates, units (with `FLAG_RELATIVE`:
    /// the distance).
    pub position: f64,
    /// `REQ_JOG`: signed speed (the sign is the direction); `REQ_MOVE`: the
    /// speed's magnitude; units/s. NaN (move): `home_speed`.
    pub speed: f64,
    /// `REQ_JOG`, `REQ_MOVE`: acceleration and deceleration, units/s²;
    /// NaN: `home_acceleration` / `home_deceleration`.
    pub accel: f64,
    pub decel: f64,
    /// `REQ_JOG_RENEW`: the jog's token (from the `REQ_JOG` answer);
    /// `REQ_STREAM_RELEASE`: the owner token.
    pub token: u64,
    /// `REQ_STREAM_ACQUIRE`: the publishing program's iceoryx2 node id
    /// (`UniqueNodeId::value()`, a u128): `[low 64 bits, high 64 bits]`.
    pub node_id: [u64; 2],
    /// `REQ_JOG`: the hold-to-run lease, ms (50..=5000): the jog stops when
    /// no renewal came for this long.
    pub lease_ms: u32,
    pub reserved: u32,
    /// `REQ_STREAM_ACQUIRE`: the program's name (shown in the status as the
    /// axes' owner), UTF-8, NUL-padded.
    pub owner: [u8; NAME_LEN],
    pub axes: [[u8; NAME_LEN]; MAX_AXES],
}

/// One axis of a response.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, ZeroCopySend, PlacementDefault)]
pub struct AxisAnswer {
    pub name: [u8; NAME_LEN],
    /// 1 = accepted.
    pub accepted: u8,
    /// `REASON_*` when refused.
    pub reason: u8,
    /// The instruction's ERR / EXERR, where it has one.
    pub err: u16,
    pub exerr: u16,
    /// The axis's index in the configuration (config order, from 0: what a
    /// setpoint frame addresses); [`NO_INDEX`] for a name that is no axis.
    pub index: u16,
    /// The operation id the engine gave an accepted jog, move, enable,
    /// disable, reset or stream (the status's `op_id` shows it while it
    /// runs and how it ended); 0 otherwise.
    pub op_id: u32,
    pub reserved: u32,
}

/// The answer to a [`ControlRequest`].
#[repr(C)]
#[derive(Clone, Copy, Debug, ZeroCopySend, PlacementDefault)]
#[type_name("motion_control::ControlResponse@4")]
pub struct ControlResponse {
    pub layout_version: u32,
    /// The request's kind.
    pub kind: u32,
    /// The supervisor's session id (the domain id of its session file).
    pub session: u32,
    /// `RESULT_*`.
    pub result: u32,
    pub request_id: u64,
    /// Valid entries of `axes`.
    pub axis_count: u32,
    /// Valid bytes of `data`.
    pub data_len: u32,
    /// Offset of this page of the data, and the data's whole length.
    pub offset: u64,
    pub total: u64,
    /// The real-time cycle in which the request took effect (home, stop,
    /// unhome, trace): status frames of this cycle or later show its effect.
    pub cycle: u64,
    /// `REQ_JOG`: the jog's token (for `REQ_JOG_RENEW`);
    /// `REQ_STREAM_ACQUIRE`: the owner token (for every setpoint frame and
    /// `REQ_STREAM_RELEASE`); random, never 0 when accepted.
    pub token: u64,
    /// Why, in words (UTF-8), when refused or bad.
    pub message: [u8; MESSAGE_LEN],
    pub axes: [AxisAnswer; MAX_AXES],
    /// A page of JSON / CSV / HdrHistogram log text.
    pub data: [u8; DATA_LEN],
}

// ---- status -------------------------------------------------------------
// The entries of the status frame are `motion-status`'s: the axis entry is
// its table's flags word and value areas (each field's place is a row of
// that table), the I/O process and stream entries its one declaration of
// those counters.
pub use motion_status::{
    AxisStatusEntry, GapCounts, IoCounters, IoStatusEntry, StreamCounts, NO_AXIS, START_ERROR_LEN,
};

/// The status service's frame, published at 100 Hz.
#[repr(C)]
#[derive(Clone, Copy, Debug, ZeroCopySend, PlacementDefault)]
#[type_name("motion_control::StatusFrame@4")]
pub struct StatusFrame {
    pub layout_version: u32,
    /// The supervisor's session id.
    pub session: u32,
    /// Status frames published so far (this one included).
    pub sequence: u64,
    /// Real-time cycles run.
    pub cycle: u64,
    /// Time since the supervisor started, ns.
    pub uptime_ns: u64,
    pub cycle_us: u32,
    pub axis_count: u32,
    pub io_count: u32,
    pub reserved: u32,
    pub axes: [AxisStatusEntry; MAX_AXES],
    pub ios: [IoStatusEntry; MAX_IOS],
    pub stream: StreamCounts,
}

macro_rules! zeroed {
    ($t:ty) => {
        impl $t {
            /// All zero: every field of this type is an integer, a float or
            /// a byte array, for which all-zero bytes are a valid value.
            pub fn zeroed() -> Box<Self> {
                // SAFETY: see above; allocated zeroed on the heap (the type
                // may be too large for a small thread stack).
                unsafe {
                    let layout = std::alloc::Layout::new::<Self>();
                    let p = std::alloc::alloc_zeroed(layout) as *mut Self;
                    if p.is_null() {
                        std::alloc::handle_alloc_error(layout);
                    }
                    Box::from_raw(p)
                }
            }
        }
    };
}
zeroed!(ControlRequest);
zeroed!(ControlResponse);
zeroed!(StatusFrame);

impl ControlRequest {
    /// The named axes (empty: every axis).
    pub fn axis_names(&self) -> Vec<String> {
        let n = (self.axis_count as usize).min(MAX_AXES);
        self.axes[..n].iter().map(|a| get_str(a)).collect()
    }

    /// Sets the axes by name; false if there are more than [`MAX_AXES`] or a
    /// name is longer than [`NAME_LEN`].
    pub fn set_axes<S: AsRef<str>>(&mut self, names: &[S]) -> bool {
        if names.len() > MAX_AXES || names.iter().any(|n| n.as_ref().len() > NAME_LEN) {
            return false;
        }
        self.axis_count = names.len() as u32;
        for (slot, n) in self.axes.iter_mut().zip(names) {
            put_str(slot, n.as_ref());
        }
        true
    }
}

impl ControlResponse {
    pub fn message_text(&self) -> String {
        get_str(&self.message)
    }

    /// The valid part of `data`.
    pub fn data_bytes(&self) -> &[u8] {
        &self.data[..(self.data_len as usize).min(DATA_LEN)]
    }

    pub fn answers(&self) -> &[AxisAnswer] {
        &self.axes[..(self.axis_count as usize).min(MAX_AXES)]
    }
}

impl StatusFrame {
    pub fn axes(&self) -> &[AxisStatusEntry] {
        &self.axes[..(self.axis_count as usize).min(MAX_AXES)]
    }

    pub fn ios(&self) -> &[IoStatusEntry] {
        &self.ios[..(self.io_count as usize).min(MAX_IOS)]
    }
}

const _: () = {
    use core::mem::{align_of, offset_of, size_of};
    assert!(
        CONTROL_LAYOUT == 4,
        "update the layout asserts together with CONTROL_LAYOUT"
    );
    assert!(size_of::<ControlRequest>() == 152 + MAX_AXES * NAME_LEN);
    assert!(offset_of!(ControlRequest, key) == 8);
    assert!(offset_of!(ControlRequest, request_id) == 24);
    assert!(offset_of!(ControlRequest, offset) == 40);
    assert!(offset_of!(ControlRequest, timeout_s) == 48);
    assert!(offset_of!(ControlRequest, position) == 56);
    assert!(offset_of!(ControlRequest, speed) == 64);
    assert!(offset_of!(ControlRequest, accel) == 72);
    assert!(offset_of!(ControlRequest, decel) == 80);
    assert!(offset_of!(ControlRequest, token) == 88);
    assert!(offset_of!(ControlRequest, node_id) == 96);
    assert!(offset_of!(ControlRequest, lease_ms) == 112);
    assert!(offset_of!(ControlRequest, owner) == 120);
    assert!(offset_of!(ControlRequest, axes) == 152);
    assert!(align_of::<ControlRequest>() == 8);

    assert!(size_of::<AxisAnswer>() == 48);
    assert!(offset_of!(AxisAnswer, err) == 34);
    assert!(offset_of!(AxisAnswer, index) == 38);
    assert!(offset_of!(AxisAnswer, op_id) == 40);

    assert!(offset_of!(ControlResponse, request_id) == 16);
    assert!(offset_of!(ControlResponse, offset) == 32);
    assert!(offset_of!(ControlResponse, cycle) == 48);
    assert!(offset_of!(ControlResponse, token) == 56);
    assert!(offset_of!(ControlResponse, message) == 64);
    assert!(offset_of!(ControlResponse, axes) == 64 + MESSAGE_LEN);
    assert!(offset_of!(ControlResponse, data) == 64 + MESSAGE_LEN + 48 * MAX_AXES);
    assert!(size_of::<ControlResponse>() == 64 + MESSAGE_LEN + 48 * MAX_AXES + DATA_LEN);

    const AXIS: usize = size_of::<AxisStatusEntry>();
    const IO: usize = size_of::<IoStatusEntry>();
    assert!(AXIS == 448 && IO == 272 && size_of::<StreamCounts>() == 72);
    assert!(offset_of!(StatusFrame, axes) == 48);
    assert!(offset_of!(StatusFrame, ios) == 48 + AXIS * MAX_AXES);
    assert!(offset_of!(StatusFrame, stream) == 48 + AXIS * MAX_AXES + IO * MAX_IOS);
    assert!(size_of::<StatusFrame>() == 48 + AXIS * MAX_AXES + IO * MAX_IOS + 72);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn request_names_are_bounded_and_never_panic() {
        let mut r = ControlRequest::zeroed();
        assert!(r.set_axes(&["X", "Y"]));
        assert_eq!(r.axis_names(), ["X", "Y"]);
        assert!(!r.set_axes(&["x".repeat(33)]));
        r.axis_count = u32::MAX; // hostile: clamped, no panic
        assert_eq!(r.axis_names().len(), MAX_AXES);
    }
}
