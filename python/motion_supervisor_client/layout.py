"""ctypes mirrors of the supervisor's wire structs and their numbers.

The control plane's messages (crates/control/src/message.rs, layout 3) and
the setpoint frame (crates/frames/src/setpoint.rs, layout 1). Every struct,
field and constant here is compared, field by field (name, offset, size,
alignment, type), against `layout.json`, which the Rust side writes from
the Rust types themselves (crates/control/tests/wire_layout.rs) and fails
on when it is stale: see `check.py` and python/tests/test_layout.py.
iceoryx2 itself only compares a type's name, size and alignment when a
service is opened — a swapped pair of fields would pass that.

This module needs nothing but the standard library.
"""

import ctypes

# ---- sizes and versions ---------------------------------------------------
CONTROL_LAYOUT = 3
SETPOINT_LAYOUT = 1
NAME_LEN = 32
MAX_AXES = 64
MAX_IOS = 16
MESSAGE_LEN = 256
START_ERROR_LEN = 128
DATA_LEN = 32 * 1024
PHASE_LEN = 16
NO_INDEX = 0xFFFF
NO_AXIS = 0xFF

# ---- request kinds, flags, results, refusal reasons -----------------------
REQ_HOME, REQ_STOP, REQ_UNHOME, REQ_STATUS = 1, 2, 3, 4
REQ_STATS, REQ_TRACE, REQ_TRACE_FETCH, REQ_HLOG = 5, 6, 7, 8
REQ_ENABLE, REQ_DISABLE, REQ_RESET = 9, 10, 11
REQ_JOG, REQ_JOG_RENEW, REQ_MOVE = 12, 13, 14
REQ_STREAM_ACQUIRE, REQ_STREAM_RELEASE = 15, 16
FLAG_RESET, FLAG_SINCE_RESET, FLAG_PARALLEL = 1, 2, 4
FLAG_RELATIVE, FLAG_SUPERSEDE, FLAG_END = 8, 16, 32
RESULT_ACCEPTED, RESULT_REFUSED, RESULT_BAD_REQUEST = 0, 1, 2
RESULT_FORBIDDEN, RESULT_NOT_READY = 3, 4
REASON_NONE, REASON_UNKNOWN_AXIS, REASON_ALREADY_HOMING = 0, 1, 2
REASON_IO_NOT_ATTACHED, REASON_INSTRUCTION, REASON_EXITING = 3, 4, 5
REASON_GANTRY, REASON_BUSY, REASON_OWNED = 6, 7, 8
REASON_TOKEN, REASON_OPERATION = 9, 10

# ---- status bits -----------------------------------------------------------
ST_EN, ST_DN, ST_ER, ST_IP, ST_PC = 1, 2, 4, 8, 16
ST_HOMING, ST_HOMED, ST_ENABLED, ST_FAULT = 32, 64, 128, 256
ST_SWITCH, ST_MARKER, ST_FEEDBACK, ST_EVENT = 512, 1024, 2048, 4096
ST_STOPPING, ST_TRACE = 8192, 16384
MS_SERVO_ACTION, MS_JOGGING, MS_MOVING, MS_STREAMING = 1, 2, 4, 8
MS_LIMIT_NEGATIVE, MS_LIMIT_POSITIVE, MS_FAULTED, MS_COMMAND = 16, 32, 64, 128
OP_IP, OP_PC, OP_REFUSED = 1, 2, 4
SX_TIMED_OUT, SX_LOST_HOMED, SX_IN_SEQUENCE, SX_LOST_FEEDBACK = 1, 2, 4, 8
SX_LOST_RECONNECT, SX_RESTORED, SX_DRIVE_LOST, SX_MONITOR = 16, 32, 64, 128
W_AMBIGUOUS_MARKER, W_DRIFT, W_SWITCH_DRIFT, W_REFERENCE_INVALIDATED = 1, 2, 4, 8
SP_VELOCITY = 1


class ControlRequest(ctypes.Structure):
    _fields_ = [
        ("layout_version", ctypes.c_uint32),
        ("kind", ctypes.c_uint32),
        ("key", ctypes.c_uint64 * 2),
        ("request_id", ctypes.c_uint64),
        ("flags", ctypes.c_uint32),
        ("axis_count", ctypes.c_uint32),
        ("offset", ctypes.c_uint64),
        ("timeout_s", ctypes.c_double),
        ("position", ctypes.c_double),
        ("speed", ctypes.c_double),
        ("accel", ctypes.c_double),
        ("decel", ctypes.c_double),
        ("token", ctypes.c_uint64),
        ("node_id", ctypes.c_uint64 * 2),
        ("lease_ms", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("owner", ctypes.c_uint8 * NAME_LEN),
        ("axes", (ctypes.c_uint8 * NAME_LEN) * MAX_AXES),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_control::ControlRequest@3"


class AxisAnswer(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_uint8 * NAME_LEN),
        ("accepted", ctypes.c_uint8),
        ("reason", ctypes.c_uint8),
        ("err", ctypes.c_uint16),
        ("exerr", ctypes.c_uint16),
        ("index", ctypes.c_uint16),
        ("op_id", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
    ]


class ControlResponse(ctypes.Structure):
    _fields_ = [
        ("layout_version", ctypes.c_uint32),
        ("kind", ctypes.c_uint32),
        ("session", ctypes.c_uint32),
        ("result", ctypes.c_uint32),
        ("request_id", ctypes.c_uint64),
        ("axis_count", ctypes.c_uint32),
        ("data_len", ctypes.c_uint32),
        ("offset", ctypes.c_uint64),
        ("total", ctypes.c_uint64),
        ("cycle", ctypes.c_uint64),
        ("token", ctypes.c_uint64),
        ("message", ctypes.c_uint8 * MESSAGE_LEN),
        ("axes", AxisAnswer * MAX_AXES),
        ("data", ctypes.c_uint8 * DATA_LEN),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_control::ControlResponse@3"


class AxisStatusEntry(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_uint8 * NAME_LEN),
        ("phase", ctypes.c_uint8 * PHASE_LEN),
        ("io", ctypes.c_uint8),
        ("warnings", ctypes.c_uint8),
        ("bits", ctypes.c_uint16),
        ("err", ctypes.c_uint16),
        ("exerr", ctypes.c_uint16),
        ("drive_error_code", ctypes.c_uint16),
        ("home_mode", ctypes.c_uint8),
        ("home_sequence", ctypes.c_uint8),
        ("home_direction", ctypes.c_uint8),
        ("aborted_by", ctypes.c_uint8),
        ("extra", ctypes.c_uint8),
        ("reserved1", ctypes.c_uint8),
        ("position", ctypes.c_double),
        ("raw", ctypes.c_double),
        ("velocity", ctypes.c_double),
        ("torque", ctypes.c_double),
        ("event_raw", ctypes.c_double),
        ("elapsed_s", ctypes.c_double),
        ("timeout_s", ctypes.c_double),
        ("search_travel", ctypes.c_double),
        ("search_limit", ctypes.c_double),
        ("lost_after_s", ctypes.c_double),
        ("skew", ctypes.c_double),
        ("feedback_gap_s", ctypes.c_double),
        ("drift", ctypes.c_double),
        ("switch_to_marker", ctypes.c_double),
        ("cmd_position", ctypes.c_double),
        ("op_id", ctypes.c_uint32),
        ("op_err", ctypes.c_uint16),
        ("op_exerr", ctypes.c_uint16),
        ("motion", ctypes.c_uint16),
        ("op_kind", ctypes.c_uint8),
        ("op_flags", ctypes.c_uint8),
        ("last_stop", ctypes.c_uint8),
        ("reserved2", ctypes.c_uint8 * 3),
        ("owner", ctypes.c_uint8 * NAME_LEN),
    ]


class IoStatusEntry(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_uint8 * NAME_LEN),
        ("attached", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8 * 7),
        ("frames_received", ctypes.c_uint64),
        ("frames_missing", ctypes.c_uint64),
        ("frames_refused", ctypes.c_uint64),
        ("attachments", ctypes.c_uint64),
        ("gaps", ctypes.c_uint64 * 4),
        ("longest_gap_cycles", ctypes.c_uint64),
        ("gap_cycles", ctypes.c_uint64),
        ("spawn_restarts", ctypes.c_uint32),
        ("spawn_retry_s", ctypes.c_float),
        ("start_error", ctypes.c_uint8 * START_ERROR_LEN),
    ]


class StreamStatusEntry(ctypes.Structure):
    _fields_ = [
        ("frames", ctypes.c_uint64),
        ("setpoints", ctypes.c_uint64),
        ("refused_layout", ctypes.c_uint64),
        ("refused_key", ctypes.c_uint64),
        ("refused_count", ctypes.c_uint64),
        ("refused_token", ctypes.c_uint64),
        ("refused_sequence", ctypes.c_uint64),
        ("refused_axis", ctypes.c_uint64),
        ("acquired", ctypes.c_uint32),
        ("owners", ctypes.c_uint32),
    ]


class StatusFrame(ctypes.Structure):
    _fields_ = [
        ("layout_version", ctypes.c_uint32),
        ("session", ctypes.c_uint32),
        ("sequence", ctypes.c_uint64),
        ("cycle", ctypes.c_uint64),
        ("uptime_ns", ctypes.c_uint64),
        ("cycle_us", ctypes.c_uint32),
        ("axis_count", ctypes.c_uint32),
        ("io_count", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("axes", AxisStatusEntry * MAX_AXES),
        ("ios", IoStatusEntry * MAX_IOS),
        ("stream", StreamStatusEntry),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_control::StatusFrame@3"


class SetpointAxis(ctypes.Structure):
    _fields_ = [
        ("axis", ctypes.c_uint32),
        ("flags", ctypes.c_uint32),
        ("position", ctypes.c_double),
        ("velocity", ctypes.c_double),
    ]


class SetpointFrame(ctypes.Structure):
    _fields_ = [
        ("layout_version", ctypes.c_uint32),
        ("session", ctypes.c_uint32),
        ("key", ctypes.c_uint64 * 2),
        ("token", ctypes.c_uint64),
        ("seq", ctypes.c_uint64),
        ("t_ns", ctypes.c_uint64),
        ("count", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("axes", SetpointAxis * MAX_AXES),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_frames::SetpointFrame@layout1"


#: Every mirror (each ctypes struct of this module), named like its Rust type.
MIRRORS = tuple(v for v in list(globals().values()) if isinstance(v, type) and issubclass(v, ctypes.Structure))


def text(arr) -> str:
    """The text of a NUL-padded byte field (invalid UTF-8 replaced)."""
    return bytes(arr).split(b"\0", 1)[0].decode("utf-8", "replace")


def put_text(arr, s: str) -> None:
    """Writes `s` NUL-padded into the byte field `arr` (cut to fit, at a
    character boundary, like the Rust side's `put_str`)."""
    raw = s.encode()[: len(arr)]
    while raw:
        try:
            raw.decode()
            break
        except UnicodeDecodeError:
            raw = raw[:-1]
    ctypes.memset(arr, 0, len(arr))
    ctypes.memmove(arr, raw, len(raw))
