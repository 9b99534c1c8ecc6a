//! The layout description of every wire struct a client mirrors — the
//! control plane's messages and the setpoint frame — written from the Rust
//! types themselves (`offset_of!`, `size_of`, `align_of`, the iceoryx2 type
//! names) and checked in as `python/motion_supervisor_client/layout.json`.
//!
//! The Python package compares its `ctypes` mirrors against that file field
//! by field (`python/tests/test_layout.py`, run by `python_tests.rs`). This
//! test fails when the checked-in file differs from what the code produces,
//! so the description can never go stale: change a message, bump its layout,
//! then regenerate it with
//!
//! ```text
//! MOTION_LAYOUT_WRITE=1 cargo test -p motion-control --test wire_layout
//! ```
//!
//! and the Python test names every field the mirrors must follow.

use std::fmt::Write as _;

use iceoryx2::prelude::ZeroCopySend;
use motion_control::*;
use motion_frames::{SetpointAxis, SetpointFrame, SETPOINT_LAYOUT, SP_VELOCITY};

/// Where the description lives, relative to this crate.
const DESCRIPTION: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../python/motion_supervisor_client/layout.json"
);

/// The type of a field as the description spells it: `u8`..`u64`, `f32`,
/// `f64`, `[T; N]`, or the name of a described struct.
trait WireType {
    fn wire_type() -> String;
}

macro_rules! primitive {
    ($($t:ty),*) => {$(
        impl WireType for $t {
            fn wire_type() -> String {
                stringify!($t).to_string()
            }
        }
    )*};
}
primitive!(u8, u16, u32, u64, f32, f64);

/// A described struct is a field type by its name.
macro_rules! by_name {
    ($($s:ident),*) => {$(
        impl WireType for $s {
            fn wire_type() -> String {
                stringify!($s).to_string()
            }
        }
    )*};
}
by_name!(
    ControlRequest,
    AxisAnswer,
    ControlResponse,
    AxisStatusEntry,
    IoStatusEntry,
    StreamStatusEntry,
    StatusFrame,
    SetpointAxis,
    SetpointFrame
);

impl<T: WireType, const N: usize> WireType for [T; N] {
    fn wire_type() -> String {
        format!("[{}; {N}]", T::wire_type())
    }
}

struct Field {
    name: &'static str,
    offset: usize,
    size: usize,
    align: usize,
    ty: String,
}

struct Struct {
    name: &'static str,
    /// The iceoryx2 type name of a service's payload (None: only nested).
    type_name: Option<&'static str>,
    size: usize,
    align: usize,
    fields: Vec<Field>,
}

/// Size, alignment and type of the field `get` reads, without a value of
/// `S` (the closure is never called: only its type is used).
fn field_of<S, F: WireType>(_get: fn(&S) -> &F) -> (usize, usize, String) {
    (
        core::mem::size_of::<F>(),
        core::mem::align_of::<F>(),
        F::wire_type(),
    )
}

/// Describes struct `$s` by its fields. The destructuring pattern without
/// `..` makes leaving a field out (or naming one that is not there) a
/// compile error, so the description always has every field.
macro_rules! describe {
    ($s:ident, $type_name:expr, { $($f:ident),* $(,)? }) => {{
        #[allow(dead_code)]
        fn every_field_is_listed(v: &$s) {
            let $s { $($f: _),* } = v;
        }
        Struct {
            name: stringify!($s),
            type_name: $type_name,
            size: core::mem::size_of::<$s>(),
            align: core::mem::align_of::<$s>(),
            fields: vec![$({
                let (size, align, ty) = field_of(|s: &$s| &s.$f);
                Field {
                    name: stringify!($f),
                    offset: core::mem::offset_of!($s, $f),
                    size,
                    align,
                    ty,
                }
            }),*],
        }
    }};
}

/// The iceoryx2 type name a service of payload `T` is opened with.
fn iox_name<T: ZeroCopySend>() -> Option<&'static str> {
    // SAFETY: only reads the name; the layouts are what this file checks.
    Some(unsafe { <T as ZeroCopySend>::type_name() })
}

/// Every wire struct, nested ones before the structs that hold them.
fn structs() -> Vec<Struct> {
    vec![
        describe!(ControlRequest, iox_name::<ControlRequest>(), {
            layout_version, kind, key, request_id, flags, axis_count, offset,
            timeout_s, position, speed, accel, decel, token, node_id, lease_ms,
            reserved, owner, axes,
        }),
        describe!(AxisAnswer, None, {
            name, accepted, reason, err, exerr, index, op_id, reserved,
        }),
        describe!(ControlResponse, iox_name::<ControlResponse>(), {
            layout_version, kind, session, result, request_id, axis_count,
            data_len, offset, total, cycle, token, message, axes, data,
        }),
        describe!(AxisStatusEntry, None, {
            name, phase, io, warnings, bits, err, exerr, drive_error_code,
            home_mode, home_sequence, home_direction, aborted_by, extra,
            reserved1, position, raw, velocity, torque, event_raw, elapsed_s,
            timeout_s, search_travel, search_limit, lost_after_s, skew,
            feedback_gap_s, drift, switch_to_marker, cmd_position, op_id,
            op_err, op_exerr, motion, op_kind, op_flags, last_stop, reserved2,
            owner,
        }),
        describe!(IoStatusEntry, None, {
            name, attached, reserved, frames_received, frames_missing,
            frames_refused, attachments, gaps, longest_gap_cycles, gap_cycles,
            spawn_restarts, spawn_retry_s, start_error,
        }),
        describe!(StreamStatusEntry, None, {
            frames, setpoints, refused_layout, refused_key, refused_count,
            refused_token, refused_sequence, refused_axis, acquired, owners,
        }),
        describe!(StatusFrame, iox_name::<StatusFrame>(), {
            layout_version, session, sequence, cycle, uptime_ns, cycle_us,
            axis_count, io_count, reserved, axes, ios, stream,
        }),
        describe!(SetpointAxis, None, { axis, flags, position, velocity }),
        describe!(SetpointFrame, iox_name::<SetpointFrame>(), {
            layout_version, session, key, token, seq, t_ns, count, reserved,
            axes,
        }),
    ]
}

/// The numbers a client needs besides the layouts (kinds, flags, results,
/// reasons, status bits), by their Rust names.
fn constants() -> Vec<(&'static str, u64)> {
    macro_rules! c {
        ($($n:ident),* $(,)?) => { vec![$((stringify!($n), $n as u64)),*] };
    }
    c![
        CONTROL_LAYOUT,
        SETPOINT_LAYOUT,
        NAME_LEN,
        MAX_AXES,
        MAX_IOS,
        MESSAGE_LEN,
        START_ERROR_LEN,
        DATA_LEN,
        PHASE_LEN,
        NO_INDEX,
        NO_AXIS,
        REQ_HOME,
        REQ_STOP,
        REQ_UNHOME,
        REQ_STATUS,
        REQ_STATS,
        REQ_TRACE,
        REQ_TRACE_FETCH,
        REQ_HLOG,
        REQ_ENABLE,
        REQ_DISABLE,
        REQ_RESET,
        REQ_JOG,
        REQ_JOG_RENEW,
        REQ_MOVE,
        REQ_STREAM_ACQUIRE,
        REQ_STREAM_RELEASE,
        FLAG_RESET,
        FLAG_SINCE_RESET,
        FLAG_PARALLEL,
        FLAG_RELATIVE,
        FLAG_SUPERSEDE,
        FLAG_END,
        RESULT_ACCEPTED,
        RESULT_REFUSED,
        RESULT_BAD_REQUEST,
        RESULT_FORBIDDEN,
        RESULT_NOT_READY,
        REASON_NONE,
        REASON_UNKNOWN_AXIS,
        REASON_ALREADY_HOMING,
        REASON_IO_NOT_ATTACHED,
        REASON_INSTRUCTION,
        REASON_EXITING,
        REASON_GANTRY,
        REASON_BUSY,
        REASON_OWNED,
        REASON_TOKEN,
        REASON_OPERATION,
        ST_EN,
        ST_DN,
        ST_ER,
        ST_IP,
        ST_PC,
        ST_HOMING,
        ST_HOMED,
        ST_ENABLED,
        ST_FAULT,
        ST_SWITCH,
        ST_MARKER,
        ST_FEEDBACK,
        ST_EVENT,
        ST_STOPPING,
        ST_TRACE,
        MS_SERVO_ACTION,
        MS_JOGGING,
        MS_MOVING,
        MS_STREAMING,
        MS_LIMIT_NEGATIVE,
        MS_LIMIT_POSITIVE,
        MS_FAULTED,
        MS_COMMAND,
        OP_IP,
        OP_PC,
        OP_REFUSED,
        SX_TIMED_OUT,
        SX_LOST_HOMED,
        SX_IN_SEQUENCE,
        SX_LOST_FEEDBACK,
        SX_LOST_RECONNECT,
        SX_RESTORED,
        SX_DRIVE_LOST,
        SX_MONITOR,
        W_AMBIGUOUS_MARKER,
        W_DRIFT,
        W_SWITCH_DRIFT,
        W_REFERENCE_INVALIDATED,
        SP_VELOCITY,
    ]
}

fn quoted(s: &str) -> String {
    serde_json::to_string(s).expect("a string serializes")
}

/// The description as JSON: one line per field and constant, so a change
/// shows as a readable diff.
fn description() -> String {
    let mut out = String::from("{\n");
    out += "  \"generator\": \"crates/control/tests/wire_layout.rs: \
            MOTION_LAYOUT_WRITE=1 cargo test -p motion-control --test wire_layout\",\n";
    out += "  \"constants\": {\n";
    let constants = constants();
    for (i, (name, value)) in constants.iter().enumerate() {
        let comma = if i + 1 < constants.len() { "," } else { "" };
        let _ = writeln!(out, "    {}: {value}{comma}", quoted(name));
    }
    out += "  },\n  \"structs\": [\n";
    let structs = structs();
    for (i, s) in structs.iter().enumerate() {
        let type_name = s.type_name.map_or("null".to_string(), quoted);
        let _ = writeln!(
            out,
            "    {{\"name\": {}, \"type_name\": {type_name}, \"size\": {}, \"align\": {}, \"fields\": [",
            quoted(s.name),
            s.size,
            s.align
        );
        for (k, f) in s.fields.iter().enumerate() {
            let comma = if k + 1 < s.fields.len() { "," } else { "" };
            let _ = writeln!(
                out,
                "      {{\"name\": {}, \"offset\": {}, \"size\": {}, \"align\": {}, \"type\": {}}}{comma}",
                quoted(f.name),
                f.offset,
                f.size,
                f.align,
                quoted(&f.ty)
            );
        }
        let comma = if i + 1 < structs.len() { "," } else { "" };
        let _ = writeln!(out, "    ]}}{comma}");
    }
    out += "  ]\n}\n";
    out
}

/// The checked-in description is what the code produces (or, with
/// `MOTION_LAYOUT_WRITE=1`, is rewritten to be).
#[test]
fn the_checked_in_layout_description_is_current() {
    let produced = description();
    let _: serde_json::Value = serde_json::from_str(&produced).expect("valid JSON");
    if std::env::var_os("MOTION_LAYOUT_WRITE").is_some() {
        std::fs::write(DESCRIPTION, &produced).expect("write the description");
        eprintln!("wrote {DESCRIPTION}");
        return;
    }
    let checked_in = std::fs::read_to_string(DESCRIPTION).unwrap_or_default();
    if checked_in != produced {
        let first = checked_in
            .lines()
            .zip(produced.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(checked_in.lines().count().min(produced.lines().count()));
        panic!(
            "{DESCRIPTION} is stale: line {} is\n  {}\nbut the Rust types give\n  {}\n\
             regenerate it: MOTION_LAYOUT_WRITE=1 cargo test -p motion-control --test wire_layout \
             (then make the Python mirrors follow it)",
            first + 1,
            checked_in.lines().nth(first).unwrap_or("(end of file)"),
            produced.lines().nth(first).unwrap_or("(end of file)")
        );
    }
}

/// "Padding spelled out": every byte of every wire struct belongs to a
/// field, the fields in declaration order one after the other — so a mirror
/// that matches every field's offset and size matches every byte.
#[test]
fn every_byte_belongs_to_a_field_in_declaration_order() {
    for s in structs() {
        let mut end = 0;
        for f in &s.fields {
            assert_eq!(
                f.offset, end,
                "{}.{}: at {} but the previous field ends at {end} (implicit padding or reordering)",
                s.name, f.name, f.offset
            );
            assert_eq!(f.offset % f.align, 0, "{}.{} misaligned", s.name, f.name);
            end = f.offset + f.size;
        }
        assert_eq!(
            end, s.size,
            "{}: trailing padding after the last field",
            s.name
        );
    }
}
