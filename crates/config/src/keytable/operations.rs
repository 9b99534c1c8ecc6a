//! `[[axis]]`: the limits of the operations around homing (jog, move,
//! stream, the stops). `travel_limits` and `max_speed` are in `axis.rs`.

use super::{keys, Key, Kind, Section::Axis};
use crate::limits::{ACCELERATION, SPEED};

keys! {
    GROUP {
        section: Axis,
        title: "[[axis]] operations",
        intro: "Limits of the operations after homing: jog, move, the supervised setpoint stream \
                and their stops. A number left out is derived from the homing keys (by the \
                engine, so `check`, the engine and the control plane agree); a number given must \
                be above 0.",
    }
    UNHOMED_SPEED: Key::new(Axis, "unhomed_speed", Kind::Number)
        .derived("`home_speed`")
        .above_zero(SPEED)
        .unit("units/s")
        .fixed()
        .meaning("Speed cap of jogs, moves and streams while the axis is not homed (no soft limit \
                  protects it then): above it ERR 13 / EXERR 1 (a setpoint: ERR 1019 / EXERR 3); \
                  a jog running when HomedStatus is lost slows to it.")
        .example("10.0");
    LIMIT_SWITCHES: Key::new(Axis, "limit_switches", Kind::Bool)
        .flag(true)
        .fixed()
        .meaning("The axis has overtravel limit switches: motion towards a tripped one is stopped \
                  at `max_deceleration` (ERR 12 / EXERR 43) and refused (ERR 9). `false`: the \
                  inputs are ignored (an EtherCAT drive then need not map 0x60FD bits 0/1); the \
                  limit-switch sequences and `home_reverse_at_limit` need them.")
        .example("true");
    MAX_DECELERATION: Key::new(Axis, "max_deceleration", Kind::Number)
        .derived("`home_deceleration`")
        .above_zero(ACCELERATION)
        .unit("units/s²")
        .meaning("Logix Maximum Deceleration: of the stops of faults and limit switches (a \
                  stream's stops: at least `stream_acceleration`); no jog or move may ask for \
                  more (ERR 13 / EXERR 3).")
        .example("2000.0");
    STREAM_ACCELERATION: Key::new(Axis, "stream_acceleration", Kind::Number)
        .derived("10 × `home_acceleration`")
        .above_zero(ACCELERATION)
        .unit("units/s²")
        .meaning("The largest change of velocity of a setpoint stream: of its segments on the \
                  program's timeline (ERR 1019 / EXERR 4 above it), and of the command between \
                  two cycles, whatever the setpoints' timestamps say.")
        .example("5000.0");
    STREAM_TIMEOUT_MS: Key::new(Axis, "stream_timeout_ms", Kind::Number)
        .num(50.0)
        // Longer than a second is no supervision.
        .range(1.0, 1000.0)
        .unit("ms")
        .meaning("A stream with no new setpoint this long after the last one arrived (however \
                  far ahead it lay) stops the axis (ERR 1019 / EXERR 5): a program that dies or \
                  hangs stops its axes.")
        .example("50");
    STREAM_UNHOMED: Key::new(Axis, "stream_unhomed", Kind::Bool)
        .flag(false)
        .meaning("The setpoint stream may drive the axis while it is not homed (without soft \
                  limits); otherwise a stream needs HomedStatus (ERR 1019 / EXERR 7).")
        .example("false");
}
