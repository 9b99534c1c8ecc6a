//! `[[axis]]`: what the axis is, how it homes, and what supervises its
//! homing. (Its operations' limits: `operations.rs`; its drive on an
//! EtherCAT bus: `ethercat.rs`.)

use super::{keys, names_of, Key, Kind, Section::Axis};
use crate::limits::*;
use motion_homing::{
    AxisConfiguration as AC, ControlMode as CM, HomeDirection as HD, HomeMode as HM,
    HomeSequence as HS, TravelMode as TM,
};

keys! {
    IDENTITY {
        section: Axis,
        title: "[[axis]]",
        intro: "One table per axis, 1 to 64. Positions are in the axis's units (`counts_per_unit` \
                converts them to the drive's counts); before homing the axis position equals the \
                raw position (the drive's, or the simulated plant's).",
    }
    NAME: Key::new(Axis, "name", Kind::Text)
        .bounded("1..=32 characters of A-Z a-z 0-9 _ . -, unique among axes and gantries")
        .fixed()
        .meaning("The axis's name in commands, the status, the record and OPC UA.")
        .example("\"X\"");
    IO: Key::new(Axis, "io", Kind::Text)
        .unset("the only I/O process; required when there are several")
        .bounded("the name of an `[[io]]`")
        .fixed()
        .meaning("The I/O process that drives this axis.")
        .example("\"bus0\"");
    CONFIGURATION: Key::new(Axis, "configuration", Kind::Choice(|| names_of(AC::NAMES)))
        .text("servo")
        .fixed()
        .meaning("CIP Axis Configuration: `\"servo\"` a drive the supervisor commands; \
                  `\"feedback_only\"` an encoder nothing drives (passive homing only); \
                  `\"virtual\"` no drive at all.")
        .example("\"servo\"");
    CONTROL_MODE: Key::new(Axis, "control_mode", Kind::Choice(|| names_of(CM::NAMES)))
        .text("position")
        .fixed()
        .meaning("CIP Control Mode of the drive; active homing needs position or velocity \
                  control (ERR 41 / EXERR 23 in torque control).")
        .example("\"position\"");
    TRAVEL: Key::new(Axis, "travel", Kind::Choice(|| names_of(TM::NAMES)))
        .text("linear")
        .fixed()
        .meaning("`\"linear\"`, or `\"cyclic\"`: the axis position wraps into [0, `unwind`) (a \
                  rotary table); a cyclic axis has no ends, hence no soft limits.")
        .example("\"cyclic\"");
    UNWIND: Key::new(Axis, "unwind", Kind::Number)
        .num(0.0)
        .range(0.0, POSITION)
        .unit("units")
        .fixed()
        .meaning("Cyclic axes: units per revolution (required above 0: ERR 41 / EXERR 29).")
        .example("360.0");
    COUNTS_PER_UNIT: Key::new(Axis, "counts_per_unit", Kind::Number)
        .num(1.0)
        .range(1e-6, 1e9)
        .unit("counts/unit")
        .note("and `max_position` × `counts_per_unit` ≤ 9e15")
        .fixed()
        .meaning("Conversion constant: drive counts per axis unit. Positions travel as exact \
                  integer counts.")
        .example("1000.0");
    MAX_POSITION: Key::new(Axis, "max_position", Kind::Number)
        .num(1e9)
        .range(1e-3, POSITION)
        .unit("units")
        .meaning("Feedback beyond ±this is corrupt, never a position (ERR 12 / EXERR 41); moves \
                  and setpoints beyond it are refused.")
        .example("10000.0");
    TRAVEL_LIMITS: Key::new(Axis, "travel_limits", Kind::Interval)
        .unset("none: no soft limits, and a search limit derived from them neither")
        .range(-POSITION, POSITION)
        .unit("units")
        .fixed()
        .meaning("Software overtravel while homed (linear axes): moves outside are refused, jogs \
                  come to rest inside, setpoints outside stop the stream. Home Position must lie \
                  inside; the default search limit and a restored reference are judged by them.")
        .example("[-100.0, 100.0]");
    ABSOLUTE: Key::new(Axis, "absolute", Kind::Bool)
        .flag(false)
        .fixed()
        .meaning("The feedback device keeps its position over power cycles (an absolute \
                  encoder): with `home_mode = \"absolute\"` its reference is stored and applied \
                  at start-up without motion.")
        .example("true");
    MARKER: Key::new(Axis, "marker", Kind::Bool)
        .flag(false)
        .fixed()
        .meaning("The feedback device has a marker (index pulse); marker sequences need it \
                  (ERR 41 / EXERR 21).")
        .example("true");
    MARKER_LATCH: Key::new(Axis, "marker_latch", Kind::Bool)
        .flag(true)
        .meaning("The drive latches the position at the marker (touch probe): exact. `false`: it \
                  only reports that an index pulse passed in the last cycle, and the marker is \
                  known to a cycle of travel.")
        .example("false");
    REGISTRATION: Key::new(Axis, "registration", Kind::Bool)
        .flag(false)
        .fixed()
        .meaning("The drive also latches its position on the home switch's edge (or on the limit \
                  switch a limit-switch sequence homes on): the switch event is exact instead of \
                  sampled once per cycle.")
        .example("true");
    HOME_ORDER: Key::new(Axis, "home_order", Kind::Integer)
        .unset("config order, one at a time, when no axis has one; homed only when named when \
                some have one")
        .range(0.0, 1000.0)
        .fixed()
        .meaning("Home-all homes order 0, then 1, …; equal orders start in the same cycle. If one \
                  fails, every axis still homing is stopped and no later order starts.")
        .example("0");
    SIM: Key::new(Axis, "sim", Kind::Table)
        .unset("a plant at raw position 0 with no switch, marker or hard stop")
        .fixed()
        .meaning("The simulated plant behind the axis (`[axis.sim]`), on the `sim` backend and \
                  the EtherCAT emulator of the tests; kept (and ignored) on a real bus.")
        .example("{ start = -50.0 }");
}

keys! {
    HOMING {
        section: Axis,
        title: "[[axis]] homing",
        intro: "The Motion Axis Home instruction's attributes. The homing page of the manual \
                shows every sequence with its diagram and a recorded plot.",
    }
    HOME_MODE: Key::new(Axis, "home_mode", Kind::Choice(|| names_of(HM::NAMES)))
        .text("active")
        .fixed()
        .meaning("`\"active\"`: the supervisor moves the axis through the sequence; `\"passive\"`: \
                  something else moves it and the event is detected on the way (`[axis.sim] \
                  external_speed` on the sim); `\"absolute\"`: no motion, sequence `immediate`, \
                  the reference stored (`absolute = true`).")
        .example("\"active\"");
    HOME_DIRECTION: Key::new(Axis, "home_direction", Kind::Choice(|| names_of(HD::NAMES)))
        .text("bidirectional_forward")
        .fixed()
        .meaning("The direction of the search (forward: positive) and whether the event is \
                  approached again from the other side at Home Return Speed (bidirectional) or \
                  found on the way (unidirectional).")
        .example("\"bidirectional_reverse\"");
    HOME_SEQUENCE: Key::new(Axis, "home_sequence", Kind::Choice(|| names_of(HS::NAMES)))
        .text("immediate")
        .fixed()
        .meaning("What the event is: none (`immediate`: the position becomes Home Position), the \
                  home switch, the marker, the switch then the marker, a hard stop (torque), a \
                  hard stop then the marker, or the limit switch in Home Direction (then the \
                  marker).")
        .example("\"switch_then_marker\"");
    HOME_SWITCH_NORMALLY_CLOSED: Key::new(Axis, "home_switch_normally_closed", Kind::Bool)
        .flag(false)
        .fixed()
        .meaning("The home switch is wired normally closed: it reads closed at rest and opens when \
                  actuated (a cut wire reads actuated).")
        .example("true");
    HOME_POSITION: Key::new(Axis, "home_position", Kind::Number)
        .num(0.0)
        .range(-POSITION, POSITION)
        .unit("units")
        .fixed()
        .meaning("The axis position at the end of homing; cyclic axes: in [0, `unwind`).")
        .example("0.0");
    HOME_OFFSET: Key::new(Axis, "home_offset", Kind::Number)
        .num(0.0)
        .range(-POSITION, POSITION)
        .unit("units")
        .fixed()
        .meaning("Where Home Position lies from the event: the axis ends at event + offset, \
                  which reads Home Position. Limit-switch sequences: it must end the axis off the \
                  switch (ERR 41 / EXERR 36).")
        .example("5.0");
    HOME_SPEED: Key::new(Axis, "home_speed", Kind::Number)
        .num(0.0)
        .range(0.0, SPEED)
        .unit("units/s")
        .fixed()
        .meaning("Speed of the search; required by a sequence that moves (ERR 41 / EXERR 6). Also \
                  the default speed of `jog` and `move`, and of `unhomed_speed`.")
        .example("20.0");
    HOME_RETURN_SPEED: Key::new(Axis, "home_return_speed", Kind::Number)
        .num(0.0)
        .range(0.0, SPEED)
        .unit("units/s")
        .fixed()
        .meaning("Speed of the way back onto the event of a bidirectional sequence and of the move \
                  to Home Position (ERR 41 / EXERR 7 when needed and 0); the sampled switch's \
                  error is this speed × half a cycle.")
        .example("2.0");
    HOME_ACCELERATION: Key::new(Axis, "home_acceleration", Kind::Number)
        .num(0.0)
        .range(0.0, ACCELERATION)
        .unit("units/s²")
        .fixed()
        .meaning("Acceleration of homing's moves (ERR 41 / EXERR 26 when needed and 0); also the \
                  default of `jog`/`move --accel`.")
        .example("500.0");
    HOME_DECELERATION: Key::new(Axis, "home_deceleration", Kind::Number)
        .num(0.0)
        .range(0.0, ACCELERATION)
        .unit("units/s²")
        .fixed()
        .meaning("Deceleration of homing's moves and stops (ERR 41 / EXERR 27 when needed and 0); \
                  also the default of `jog`/`move --decel` and of `max_deceleration`.")
        .example("500.0");
    HOME_TORQUE_LEVEL: Key::new(Axis, "home_torque_level", Kind::Number)
        .num(0.0)
        .range(0.0, TORQUE)
        .unit("% rated")
        .fixed()
        .meaning("Torque sequences: the torque limit while pushing into the hard stop (above 0, at \
                  most 100, not below the threshold: ERR 41 / EXERR 28).")
        .example("30.0");
    HOME_TORQUE_THRESHOLD: Key::new(Axis, "home_torque_threshold", Kind::Number)
        .num(0.0)
        .range(0.0, TORQUE)
        .unit("% rated")
        .fixed()
        .meaning("Torque sequences: the hard stop is detected when the torque stays above this for \
                  `home_torque_time`.")
        .example("25.0");
    HOME_TORQUE_TIME: Key::new(Axis, "home_torque_time", Kind::Number)
        .num(0.0)
        .range(0.0, SHORT_TIME_S)
        .unit("s")
        .fixed()
        .meaning("Torque sequences: how long the torque must stay above the threshold.")
        .example("0.05");
    HOME_TIMEOUT: Key::new(Axis, "home_timeout", Kind::Number)
        .num(0.0)
        .range(0.0, TIMEOUT_S)
        .unit("s")
        .fixed()
        .meaning("A homing that takes longer is stopped with ERR 1015; 0: no timeout.")
        .example("30.0");
    HOME_CREEP_SPEED: Key::new(Axis, "home_creep_speed", Kind::Number)
        .num(0.0)
        .range(0.0, SPEED)
        .unit("units/s")
        .meaning("Seek, back off, creep: with `marker_latch = false`, a marker found at speed is \
                  passed, and crept back over at this speed, so it is known to creep speed × \
                  half a cycle (bidirectional active sequences). 0: no creep leg.")
        .example("0.5");
    HOME_REVERSE_AT_LIMIT: Key::new(Axis, "home_reverse_at_limit", Kind::Bool)
        .flag(false)
        .fixed()
        .meaning("A bidirectional `switch` or `switch_then_marker` search that meets the limit \
                  switch in Home Direction before the home switch turns round there, runs back \
                  past the home switch and searches again: the same edge, approached the same \
                  way, from any start (CiA 402 methods 7–14, 23–30). Refused elsewhere (ERR 41 / \
                  EXERR 37).")
        .example("true");
}

keys! {
    SUPERVISION {
        section: Axis,
        title: "[[axis]] supervision of homing",
        intro: "Bounds that end a homing that goes wrong, the drive's normal limits restored \
                around a torque sequence, and the checks of the homing record.",
    }
    SEARCH_LIMIT: Key::new(Axis, "search_limit", Kind::Number)
        .derived("1.1 × the span of `travel_limits`, two revolutions on a cyclic axis, else none \
                  (`check` warns)")
        .range(0.0, 2.0 * POSITION)
        .unit("units")
        .meaning("The longest distance one search leg may travel from where it began (ERR 1016, \
                  the EXERR naming the leg). 0: the default.")
        .example("250.0");
    MAX_SPEED: Key::new(Axis, "max_speed", Kind::Number)
        .derived("2 × the fastest homing speed the sequence commands; none when the homing \
                  commands no motion (passive, immediate, absolute)")
        .range(0.0, SPEED)
        .unit("units/s")
        .meaning("The fastest the axis can move: feedback implying more is implausible, never an \
                  event (ERR 12 / EXERR 44); no jog, move or setpoint may go faster (ERR 13 / \
                  EXERR 1, ERR 1019 / EXERR 3). It is the speed bound of jog, move and stream: \
                  an axis with none set or derived refuses them all (ERR 13 / EXERR 7; `check` \
                  says so) and still homes. 0: the default.")
        .example("100.0");
    TORQUE_LIMIT: Key::new(Axis, "torque_limit", Kind::Number)
        .num(100.0)
        .range(0.0, TORQUE)
        .unit("% rated")
        .meaning("The drive's normal torque limit, restored after a torque sequence.")
        .example("100.0");
    POSITION_ERROR_TOLERANCE: Key::new(Axis, "position_error_tolerance", Kind::Number)
        .num(0.0)
        .range(0.0, POSITION)
        .unit("units")
        .meaning("The drive's normal following-error tolerance, switched off while pushing into a \
                  hard stop and restored after; 0: off.")
        .example("1.0");
    VELOCITY_ERROR_TOLERANCE: Key::new(Axis, "velocity_error_tolerance", Kind::Number)
        .num(0.0)
        .range(0.0, SPEED)
        .unit("units/s")
        .meaning("The drive's normal velocity-error tolerance, handled like \
                  `position_error_tolerance`; 0: off.")
        .example("5.0");
    ENABLE_TIMEOUT: Key::new(Axis, "enable_timeout", Kind::Number)
        .num(1.0)
        .range(1e-3, SHORT_TIME_S)
        .unit("s")
        .meaning("Time the drive gets to report enabled after an enable or an active homing's \
                  start (ERR 12 / EXERR 42 after it).")
        .example("1.0");
    MARKER_MIN_DISTANCE: Key::new(Axis, "marker_min_distance", Kind::Number)
        .derived("two cycles of travel at `home_return_speed`")
        .range(0.0, POSITION)
        .unit("units")
        .meaning("Switch then marker: a marker closer than this to the switch edge is ambiguous \
                  (it may be the one before or after the intended one): a warning, or ERR 1018 \
                  with `refuse_ambiguous_marker`. 0: no check.")
        .example("0.5");
    REFUSE_AMBIGUOUS_MARKER: Key::new(Axis, "refuse_ambiguous_marker", Kind::Bool)
        .flag(false)
        .meaning("An ambiguous marker fails homing with ERR 1018 instead of a warning.")
        .example("true");
    DRIFT_LIMIT: Key::new(Axis, "drift_limit", Kind::Number)
        .num(0.0)
        .range(0.0, POSITION)
        .unit("units")
        .meaning("Warn when a home event lands further than this from the median of the axis's \
                  last five events, or the switch-to-marker distance moves that far from its \
                  median (a slipping coupling, a loose or worn switch); 0: off.")
        .example("0.05");
}
