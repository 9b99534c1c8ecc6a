//! The messages of the control plane, `#[repr(C)]` with explicit padding.
//!
//! Like the frames: only fixed-size integers, floats and byte arrays (no
//! `bool`, no enums, no pointers), every byte written, the layout pinned by
//! compile-time asserts, and [`CONTROL_LAYOUT`] in the iceoryx2 type names,
//! so a client of another layout cannot even open the services. Text
//! (names, messages, report data) is UTF-8, NUL-padded.
//!
//! Any client can speak them: `python/motion_supervisor_client/layout.py`
//! mirrors them with `ctypes`, checked field by field against `layout.json`,
//! which `tests/wire_layout.rs` writes from these types (and fails on when
//! it is stale): a change here is a regenerated description away from a
//! failing Python test.

use iceoryx2::prelude::{PlacementDefault, ZeroCopySend};

/// Layout version of every type in this file. Bump it on ANY change.
pub const CONTROL_LAYOUT: u32 = 3;

/// Bytes of a name (axis, I/O process).
pub const NAME_LEN: usize = 32;
/// Axes a message carries.
pub const MAX_AXES: usize = 64;
/// I/O processes a status frame carries.
pub const MAX_IOS: usize = 16;
/// Bytes of a response's message.
pub const MESSAGE_LEN: usize = 256;
/// Bytes of `IoStatusEntry::start_error`.
pub const START_ERROR_LEN: usize = 128;
/// Bytes of a response's data (a page of a report, a trace or a log).
pub const DATA_LEN: usize = 32 * 1024;
/// Bytes of a phase name.
pub const PHASE_LEN: usize = 16;
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
#[type_name("motion_control::ControlRequest@3")]
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
#[type_name("motion_control::ControlResponse@3")]
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
/// `AxisStatusEntry::bits`.
pub const ST_EN: u16 = 1 << 0;
pub const ST_DN: u16 = 1 << 1;
pub const ST_ER: u16 = 1 << 2;
pub const ST_IP: u16 = 1 << 3;
pub const ST_PC: u16 = 1 << 4;
/// Axis HomingStatus.
pub const ST_HOMING: u16 = 1 << 5;
/// Axis HomedStatus.
pub const ST_HOMED: u16 = 1 << 6;
/// The drive reports enabled.
pub const ST_ENABLED: u16 = 1 << 7;
/// The drive reports a fault.
pub const ST_FAULT: u16 = 1 << 8;
/// The home switch is actuated (logical).
pub const ST_SWITCH: u16 = 1 << 9;
/// A marker passed / the marker latch holds a position.
pub const ST_MARKER: u16 = 1 << 10;
/// `position`, `raw`, `velocity`, `torque` are valid (fresh feedback).
pub const ST_FEEDBACK: u16 = 1 << 11;
/// `event_raw` is valid.
pub const ST_EVENT: u16 = 1 << 12;
/// Decelerating after an abort.
pub const ST_STOPPING: u16 = 1 << 13;
/// A trace of the next homing is armed or recording.
pub const ST_TRACE: u16 = 1 << 14;

/// `AxisStatusEntry::motion`: ServoActionStatus (enable requested and the
/// drive reports enabled).
pub const MS_SERVO_ACTION: u16 = 1 << 0;
/// JogStatus.
pub const MS_JOGGING: u16 = 1 << 1;
/// MoveStatus.
pub const MS_MOVING: u16 = 1 << 2;
/// A setpoint stream commands the axis.
pub const MS_STREAMING: u16 = 1 << 3;
/// The negative / positive hardware overtravel limit switch is tripped.
pub const MS_LIMIT_NEGATIVE: u16 = 1 << 4;
pub const MS_LIMIT_POSITIVE: u16 = 1 << 5;
/// An axis fault is present (ER set by a drive fault, a limit switch, a
/// refused setpoint, lost feedback): only `reset` clears it.
pub const MS_FAULTED: u16 = 1 << 6;
/// `cmd_position` is valid.
pub const MS_COMMAND: u16 = 1 << 7;

/// `AxisStatusEntry::op_flags`: the last operation is in process.
pub const OP_IP: u8 = 1 << 0;
/// ... ended as asked (MAM: at its target; a jog or stream: ended normally).
pub const OP_PC: u8 = 1 << 1;
/// ... was refused (`op_err` / `op_exerr` say why).
pub const OP_REFUSED: u8 = 1 << 2;

/// `AxisStatusEntry::aborted_by` when no other axis aborted it.
pub const NO_AXIS: u8 = 0xff;
/// `AxisStatusEntry::extra`: the home sequence's timeout stopped the axis.
pub const SX_TIMED_OUT: u8 = 1 << 0;
/// HomedStatus was lost after the axis last homed successfully.
pub const SX_LOST_HOMED: u8 = 1 << 1;
/// A home sequence will start, or has started, the axis.
pub const SX_IN_SEQUENCE: u8 = 1 << 2;
/// With `SX_LOST_HOMED`: lost because its feedback was lost.
pub const SX_LOST_FEEDBACK: u8 = 1 << 3;
/// With `SX_LOST_HOMED`: lost because its I/O process reconnected.
pub const SX_LOST_RECONNECT: u8 = 1 << 4;
/// HomedStatus comes from the stored reference of an absolute axis,
/// applied without motion (not from a homing run since start-up).
pub const SX_RESTORED: u8 = 1 << 5;
/// The I/O process reports the axis's drive lost (it stopped answering on
/// its fieldbus, left operation, or was power-cycled): not a reading, not
/// enabled.
pub const SX_DRIVE_LOST: u8 = 1 << 6;
/// The cycle monitor stopped the axis (ERR 1021; EXERR names the invariant
/// broken; the value against its bound is in the supervisor's log).
pub const SX_MONITOR: u8 = 1 << 7;

/// `AxisStatusEntry::warnings`: the last homing's marker lay closer to the
/// switch edge than `marker_min_distance` (which marker is taken is a
/// matter of chance).
pub const W_AMBIGUOUS_MARKER: u8 = 1 << 0;
/// The last homing's event lay further than `drift_limit` from the recent
/// events of the axis (`drift`).
pub const W_DRIFT: u8 = 1 << 1;
/// The last homing's switch-to-marker distance lay further than
/// `drift_limit` from the recent ones (`drift`).
pub const W_SWITCH_DRIFT: u8 = 1 << 2;
/// The stored reference of this absolute axis was invalidated (the reason
/// is in the log and the homing record).
pub const W_REFERENCE_INVALIDATED: u8 = 1 << 3;

/// One axis of the status frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, ZeroCopySend, PlacementDefault)]
pub struct AxisStatusEntry {
    pub name: [u8; NAME_LEN],
    /// Homing phase by name (`idle`, `seek`, ...), NUL-padded.
    pub phase: [u8; PHASE_LEN],
    /// Index of its I/O process in `StatusFrame::ios`.
    pub io: u8,
    /// `W_*`: warnings of the last homing (it did not fail because of them).
    pub warnings: u8,
    /// `ST_*`.
    pub bits: u16,
    pub err: u16,
    pub exerr: u16,
    /// The drive's error code (CiA 402 0x603F) while it reports a fault.
    pub drive_error_code: u16,
    /// CIP numbers: Home Mode (0 passive, 1 active, 2 absolute), Home
    /// Sequence (0..=5), Home Direction (0..=3).
    pub home_mode: u8,
    pub home_sequence: u8,
    pub home_direction: u8,
    /// Index of the axis whose failure aborted this axis's home sequence
    /// (`NO_AXIS`: none).
    pub aborted_by: u8,
    /// `SX_*`.
    pub extra: u8,
    pub reserved1: u8,
    /// Axis position (current reference), raw position, units; velocity
    /// units/s; torque % rated (valid with `ST_FEEDBACK`).
    pub position: f64,
    pub raw: f64,
    pub velocity: f64,
    pub torque: f64,
    /// Raw position of the home event (valid with `ST_EVENT`).
    pub event_raw: f64,
    /// Time in the current (or last) homing and its timeout (0 = none), s.
    pub elapsed_s: f64,
    pub timeout_s: f64,
    /// Distance travelled in the current search leg and the limit (0 =
    /// unbounded), units.
    pub search_travel: f64,
    pub search_limit: f64,
    /// With `SX_LOST_HOMED`: seconds after homing ended that HomedStatus
    /// was lost.
    pub lost_after_s: f64,
    /// A gantry side: the largest skew of its gantry's last homing (how far
    /// apart the sides found their events), units; NaN otherwise.
    pub skew: f64,
    /// How long the feedback had been missing when the feedback-loss rule
    /// tripped (ERR 12 / EXERR 40, or HomedStatus lost), s; 0 otherwise.
    pub feedback_gap_s: f64,
    /// With `W_DRIFT` / `W_SWITCH_DRIFT`: how far from the median of the
    /// recent events, units; NaN otherwise.
    pub drift: f64,
    /// Switch then marker: the distance from the switch edge to the marker
    /// of the last homing, units; NaN otherwise.
    pub switch_to_marker: f64,
    /// The position commanded this cycle, axis coordinates, units (valid
    /// with `MS_COMMAND`): with `position`, the following error.
    pub cmd_position: f64,
    /// The last operation (enable, disable, reset, jog, move, stream, stop):
    /// its id, the ERR / EXERR of a refusal, its kind (`OpKind` number).
    pub op_id: u32,
    pub op_err: u16,
    pub op_exerr: u16,
    /// `MS_*`.
    pub motion: u16,
    pub op_kind: u8,
    /// `OP_*`.
    pub op_flags: u8,
    /// Why the last motion stopped (`StopCause` number, 0 none).
    pub last_stop: u8,
    pub reserved2: [u8; 3],
    /// The program that owns the axis (setpoint stream), NUL-padded; empty:
    /// none.
    pub owner: [u8; NAME_LEN],
}

/// One I/O process of the status frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, ZeroCopySend, PlacementDefault)]
pub struct IoStatusEntry {
    pub name: [u8; NAME_LEN],
    /// 1 = fresh feedback arrives (within the feedback-loss rule).
    pub attached: u8,
    pub reserved: [u8; 7],
    pub frames_received: u64,
    pub frames_missing: u64,
    /// Refused: bad layout, wrong axis count, wrong session key.
    pub frames_refused: u64,
    /// Times it attached (the first included).
    pub attachments: u64,
    /// Gaps by length: 1, 2–3, 4–10, > 10 cycles.
    pub gaps: [u64; 4],
    pub longest_gap_cycles: u64,
    /// Cycles without a fresh answer right now.
    pub gap_cycles: u64,
    /// A spawned I/O process: times the supervisor started it again.
    pub spawn_restarts: u32,
    /// A spawned I/O process: seconds until its next start (0: running).
    pub spawn_retry_s: f32,
    /// A spawned I/O process: the error it ended with at its last failed
    /// start (its first line), NUL-padded; empty when none.
    pub start_error: [u8; START_ERROR_LEN],
}

impl Default for IoStatusEntry {
    /// All zero (every field is an integer, a float or a byte array).
    fn default() -> Self {
        Self {
            name: [0; NAME_LEN],
            attached: 0,
            reserved: [0; 7],
            frames_received: 0,
            frames_missing: 0,
            frames_refused: 0,
            attachments: 0,
            gaps: [0; 4],
            longest_gap_cycles: 0,
            gap_cycles: 0,
            spawn_restarts: 0,
            spawn_retry_s: 0.0,
            start_error: [0; START_ERROR_LEN],
        }
    }
}

/// The setpoint stream's intake as the status frame shows it: frames taken,
/// and refused by why (counted since start).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, ZeroCopySend, PlacementDefault)]
pub struct StreamStatusEntry {
    /// Frames that reached the intake's checks.
    pub frames: u64,
    /// Setpoints handed to engines.
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
    /// Streams granted since start, and running now.
    pub acquired: u32,
    pub owners: u32,
}

/// The status service's frame, published at 100 Hz.
#[repr(C)]
#[derive(Clone, Copy, Debug, ZeroCopySend, PlacementDefault)]
#[type_name("motion_control::StatusFrame@3")]
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
    pub stream: StreamStatusEntry,
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

/// Writes `s` NUL-padded into `buf`, cut at a character boundary.
pub fn put_str(buf: &mut [u8], s: &str) {
    buf.fill(0);
    let mut n = s.len().min(buf.len());
    while !s.is_char_boundary(n) {
        n -= 1;
    }
    buf[..n].copy_from_slice(&s.as_bytes()[..n]);
}

/// The text of a NUL-padded field (invalid UTF-8 replaced, never a panic).
pub fn get_str(buf: &[u8]) -> String {
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

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
        CONTROL_LAYOUT == 3,
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

    assert!(size_of::<AxisStatusEntry>() == 232);
    assert!(offset_of!(AxisStatusEntry, cmd_position) == 176);
    assert!(offset_of!(AxisStatusEntry, op_id) == 184);
    assert!(offset_of!(AxisStatusEntry, motion) == 192);
    assert!(offset_of!(AxisStatusEntry, op_kind) == 194);
    assert!(offset_of!(AxisStatusEntry, last_stop) == 196);
    assert!(offset_of!(AxisStatusEntry, owner) == 200);
    assert!(offset_of!(AxisStatusEntry, io) == 48);
    assert!(offset_of!(AxisStatusEntry, bits) == 50);
    assert!(offset_of!(AxisStatusEntry, drive_error_code) == 56);
    assert!(offset_of!(AxisStatusEntry, home_mode) == 58);
    assert!(offset_of!(AxisStatusEntry, extra) == 62);
    assert!(offset_of!(AxisStatusEntry, position) == 64);
    assert!(offset_of!(AxisStatusEntry, search_limit) == 128);

    assert!(size_of::<IoStatusEntry>() == 256);
    assert!(offset_of!(IoStatusEntry, frames_received) == 40);
    assert!(offset_of!(IoStatusEntry, gaps) == 72);
    assert!(offset_of!(IoStatusEntry, gap_cycles) == 112);
    assert!(offset_of!(IoStatusEntry, spawn_restarts) == 120);
    assert!(offset_of!(IoStatusEntry, spawn_retry_s) == 124);
    assert!(offset_of!(IoStatusEntry, start_error) == 128);

    assert!(size_of::<StreamStatusEntry>() == 72);
    assert!(offset_of!(StreamStatusEntry, acquired) == 64);

    assert!(offset_of!(StatusFrame, axes) == 48);
    assert!(offset_of!(StatusFrame, ios) == 48 + 232 * MAX_AXES);
    assert!(offset_of!(StatusFrame, stream) == 48 + 232 * MAX_AXES + 256 * MAX_IOS);
    assert!(size_of::<StatusFrame>() == 48 + 232 * MAX_AXES + 256 * MAX_IOS + 72);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_are_bounded_and_never_panic() {
        let mut b = [0u8; 4];
        put_str(&mut b, "Xä€");
        assert_eq!(get_str(&b), "Xä"); // cut at a character boundary
        assert_eq!(get_str(&[0xff, 0xfe, 0]), "\u{fffd}\u{fffd}");
        let mut r = ControlRequest::zeroed();
        assert!(r.set_axes(&["X", "Y"]));
        assert_eq!(r.axis_names(), ["X", "Y"]);
        assert!(!r.set_axes(&["x".repeat(33)]));
        r.axis_count = u32::MAX; // hostile: clamped, no panic
        assert_eq!(r.axis_names().len(), MAX_AXES);
    }
}
