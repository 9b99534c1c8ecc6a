//! [`TABLE`]: every ERR / EXERR with where it is reported, its meaning,
//! its cause and its remedy — the one place `motionctl`'s words for a code
//! and the manual's error page (`docs/errors.md`, written by
//! `motion-docgen`) come from. The codes themselves are [`crate::codes`].

use crate::codes::*;

/// Where a code is reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Seen {
    /// A homing ended with it (ER, PC not set).
    Homing,
    /// `check` refuses the configuration with it (ERR 41).
    Config,
    /// An operation is refused with it: nothing changes, ER stays clear.
    Refusal,
    /// An axis fault: the motion stopped, ER set, `reset` clears it.
    Fault,
    /// Logged only: a normal end.
    Note,
}

impl Seen {
    pub const fn name(self) -> &'static str {
        match self {
            Seen::Homing => "homing",
            Seen::Config => "configuration",
            Seen::Refusal => "refusal",
            Seen::Fault => "axis fault",
            Seen::Note => "normal end",
        }
    }
}

/// One code as the tools and the docs explain it.
#[derive(Clone, Copy, Debug)]
pub struct Code {
    pub err: u16,
    /// `None`: every EXERR under `err` without a row of its own.
    pub exerr: Option<u16>,
    /// An extension of the Logix tables (not a Logix code).
    pub ours: bool,
    pub seen: &'static [Seen],
    /// One line, as `motionctl` prints it beside the code.
    pub short: &'static str,
    /// What happened and why (Markdown).
    pub cause: &'static str,
    /// What to do (Markdown).
    pub remedy: &'static str,
}

const fn code(err: u16, exerr: u16, seen: &'static [Seen], short: &'static str) -> Code {
    Code {
        err,
        exerr: Some(exerr),
        ours: false,
        seen,
        short,
        cause: "",
        remedy: "",
    }
}

impl Code {
    const fn any(mut self) -> Code {
        self.exerr = None;
        self
    }
    const fn ours(mut self) -> Code {
        self.ours = true;
        self
    }
    const fn cause(mut self, c: &'static str) -> Code {
        self.cause = c;
        self
    }
    const fn remedy(mut self, r: &'static str) -> Code {
        self.remedy = r;
        self
    }
}

use Seen::{Config as C, Fault as F, Homing as H, Note as N, Refusal as R};

/// Every code, by ERR then EXERR.
pub const TABLE: &[Code] = &[
    code(
        ERR_EXECUTION_COLLISION,
        0,
        &[R, H],
        "execution collision: the axis runs an operation this one may not replace",
    )
    .any()
    .cause(
        "The axis runs an operation this one may not replace: a move on a jogging or \
         moving axis without `supersede`, a jog on a moving axis, anything but a stop on \
         a streaming axis, a stream start on an axis in motion, a home on an axis that \
         jogs, moves or streams.",
    )
    .remedy(
        "Stop the running operation first (`motionctl stop AXIS`), or give `move \
         --supersede`. A program's stream owns its axes until it releases them.",
    ),
    code(
        ERR_SERVO_OFF,
        EX_NOT_SERVO,
        &[R],
        "not a servo axis: nothing to enable or move",
    )
    .ours()
    .cause(
        "Enable, jog, move or stream on an axis configured `feedback_only` or `virtual` \
         without a drive to command.",
    )
    .remedy("Nothing to do on that axis; check `configuration` if it should have a drive."),
    code(
        ERR_SERVO_OFF,
        0,
        &[R],
        "servo off state: the drive is not enabled",
    )
    .any()
    .cause(
        "Jog, move or stream on an axis whose drive is not enabled (ServoActionStatus \
         false), or while a disable is under way.",
    )
    .remedy("`motionctl enable AXIS` first (nothing is ever enabled by itself)."),
    code(
        ERR_OVERTRAVEL_CONDITION,
        0,
        &[R],
        "overtravel condition: motion towards a tripped limit switch",
    )
    .any()
    .cause("Jog or move towards a limit switch that is actuated.")
    .remedy(
        "Move away from the limit (allowed after `reset`); check why the axis got \
         there.",
    ),
    code(
        ERR_SERVO_MESSAGE,
        EX_TERMINATED_ON_REQUEST,
        &[H],
        "homing terminated by a stop or disable",
    )
    .cause(
        "The homing was stopped: `stop`, `disable`, the supervisor shutting down, or \
         another axis of the same home-all or gantry failed (the message names it).",
    )
    .remedy("Home again; if another axis failed, fix that one first."),
    code(
        ERR_SERVO_MESSAGE,
        EX_AXIS_SHUTDOWN,
        &[H, R],
        "axis in shutdown",
    )
    .cause(
        "The axis is in shutdown: the supervisor is ending, or a shutdown was requested \
         at the start of or during homing.",
    )
    .remedy("Wait for the supervisor to restart, then home or operate again."),
    code(ERR_SERVO_MESSAGE, EX_DRIVE_FAULT, &[H, F], "drive fault")
        .cause(
            "The drive faulted or dropped its power stage (STO, an error of its own) during \
             homing, a motion, or at rest. The status shows the drive's error code \
             (CiA 402 0x603F).",
        )
        .remedy(
            "Find the drive's fault (its error code, its display); `motionctl reset AXIS` \
             (a homing is refused with ERR 20 until then), then `enable` or home again.",
        ),
    code(
        ERR_SERVO_MESSAGE,
        EX_FEEDBACK_LOST,
        &[H, R, F],
        "feedback lost (I/O process silent or gone)",
    )
    .ours()
    .cause(
        "The feedback-loss rule tripped: missing feedback added up to more than \
         `feedback_timeout_ms` (the message says how long it was missing) — the I/O \
         process ended, hangs, or its frames were lost too often. As a refusal: there is \
         no valid feedback to start from.",
    )
    .remedy(
        "Check the I/O process (`motionctl status`: its row, `attached`; its log: \
         `journalctl -u motion-io@NAME`), restart it if needed; then home again \
         (HomedStatus was cleared). Frequent short gaps: see the troubleshooting page.",
    ),
    code(
        ERR_SERVO_MESSAGE,
        EX_FEEDBACK_INVALID,
        &[H, F],
        "invalid feedback (non-finite or absurd)",
    )
    .ours()
    .cause(
        "A feedback value was not finite or lay beyond ±`max_position` (a broken \
         encoder, a wrong `counts_per_unit`, a corrupt frame); the status names the \
         attribute.",
    )
    .remedy(
        "Check the encoder and `counts_per_unit`/`max_position`; `reset`, then home \
         again.",
    ),
    code(
        ERR_SERVO_MESSAGE,
        EX_ENABLE_TIMEOUT,
        &[H, F],
        "drive did not enable in time",
    )
    .ours()
    .cause(
        "The drive did not report enabled within `enable_timeout` after an enable or an \
         active homing's start: no power stage (STO, mains), a fault, or a slow drive.",
    )
    .remedy(
        "Check the drive's power and safety circuit; raise `enable_timeout` for a drive \
         that takes longer; `reset`, then `enable` again.",
    ),
    code(
        ERR_SERVO_MESSAGE,
        EX_OVERTRAVEL,
        &[H, F],
        "hardware overtravel: a limit switch was hit",
    )
    .ours()
    .cause(
        "A limit switch tripped in the direction of travel (during homing, outside the \
         legs that mean to be on it), or a jog, move or stream moved towards a tripped \
         one; the axis was stopped at `max_deceleration`.",
    )
    .remedy(
        "`reset`, then jog or move away from the limit (allowed); check the travel \
         limits, the homing's direction and the switch's wiring.",
    ),
    code(
        ERR_SERVO_MESSAGE,
        EX_FEEDBACK_IMPLAUSIBLE,
        &[H, F],
        "implausible feedback: a position the axis cannot have reached (never a home event)",
    )
    .ours()
    .cause(
        "A position further than `max_speed` allows from where the axis was last seen or \
         commanded since: a forged or corrupt frame, an encoder glitch, or a `max_speed` \
         below the axis's real speed.",
    )
    .remedy(
        "Check `max_speed` (default: twice the fastest homing speed) against the \
         machine, the encoder and its cable; `reset`, then home again.",
    ),
    code(
        ERR_SERVO_MESSAGE,
        EX_DRIVE_LOST,
        &[H, F],
        "drive lost: it stopped answering on its bus, left operation or was power-cycled \
         (its I/O process is alive; its log names the drive and what to do)",
    )
    .ours()
    .cause(
        "The I/O process is alive but reports the axis's drive gone: on EtherCAT its \
         SubDevice stopped answering (power, cable, the SubDevice before it), left OP \
         or was power-cycled.",
    )
    .remedy(
        "Read `motion-io`'s log (it names the SubDevice and says what to do); once the \
         drive is back it stays disabled: `reset`, then `enable` or home again.",
    ),
    code(
        ERR_SERVO_MESSAGE,
        EX_DRIVE_HOMING_ERROR,
        &[H],
        "the drive's own homing failed: it reported a homing error or did not take homing \
         mode",
    )
    .ours()
    .cause(
        "A `drive_homing` axis's drive reported a homing error (statusword bit 13), \
         refused homing mode, or left it before attaining home.",
    )
    .remedy(
        "Check the method (`drive_homing_method`, the drive's 0x60E3 list, `motion-io \
         scan`) and the drive's homing parameters in its manual; or home \
         controller-side (`drive_homing = false`).",
    ),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_SPEED,
        &[R],
        "parameter out of range: speed",
    )
    .cause(
        "A speed that is not finite, not above zero, above `max_speed`, or (not homed) \
         above `unhomed_speed`; a stream start without any speed bound (no `max_speed` \
         and no homing speed to derive one).",
    )
    .remedy(
        "Ask for less, or raise the limit in the configuration if the machine allows \
         it; home the axis to leave the unhomed cap.",
    ),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_ACCELERATION,
        &[R],
        "parameter out of range: acceleration",
    )
    .cause("An acceleration that is not finite or not above zero.")
    .remedy("Give a positive `--accel`, or set `home_acceleration` (its default)."),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_DECELERATION,
        &[R],
        "parameter out of range: deceleration",
    )
    .cause(
        "A deceleration that is not finite, not above zero, or above `max_deceleration`; \
         a stream start without a deceleration to stop with.",
    )
    .remedy("Ask for less, or set `max_deceleration` / `home_deceleration`."),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_TARGET,
        &[R],
        "parameter out of range: target outside the travel limits",
    )
    .cause(
        "A target outside `travel_limits` (homed, linear) or beyond ±`max_position`, a \
         jog towards a travel limit already reached, or a motion that could not stop \
         inside the travel limits from where the axis is.",
    )
    .remedy("Choose a target inside the limits, or move away from the limit first."),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_NOT_FINITE,
        &[R],
        "parameter out of range: target not finite",
    )
    .cause("The target is NaN or infinite.")
    .remedy("Send a finite target."),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_LEASE,
        &[R],
        "parameter out of range: jog lease",
    )
    .cause("A jog lease outside 50 ms ..= 5 s (a client of the control service).")
    .remedy("Ask for a lease in range and renew it well inside it."),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_NO_MAX_SPEED,
        &[R],
        "no speed bound: max_speed is not set and the homing derives none",
    )
    .ours()
    .cause(
        "A jog, move or stream on an axis without `max_speed` whose homing derives no \
         speed (immediate, absolute or passive homing): nothing may move it without a \
         bound. Homing itself still works.",
    )
    .remedy("Set `max_speed` for the axis (`check` warns about it)."),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        0,
        &[R],
        "parameter out of range",
    )
    .any()
    .cause("An operand of the operation is out of range.")
    .remedy("See the EXERR's row."),
    code(
        ERR_HOME_IN_PROCESS,
        0,
        &[R],
        "home in process: stop homing first",
    )
    .any()
    .cause("Enable, reset, jog, move or stream on an axis that is homing.")
    .remedy(
        "Wait for the homing to end or `stop` it; `disable` and `stop` are always \
         accepted.",
    ),
    code(
        ERR_AXIS_FAULTED,
        0,
        &[R, H],
        "axis in faulted state: reset first",
    )
    .any()
    .cause(
        "Home, enable, jog, move or stream while the axis has an axis fault (ER set by a \
         fault of a motion or a drive fault); the fault's own code stays in the status.",
    )
    .remedy("See the fault's code, remove its cause, then `motionctl reset AXIS`."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_SEQUENCE_INCOMPATIBLE,
        &[C],
        "illegal homing configuration: sequence incompatible with the mode or axis",
    )
    .cause(
        "The home sequence does not fit the home mode or the axis: a passive torque \
         sequence, a moving sequence on a virtual axis, absolute mode with a sequence \
         other than `immediate`, a limit-switch sequence homed passively.",
    )
    .remedy("Choose a sequence the mode can run (`home_sequence`, `home_mode`)."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_HOME_SPEED_ZERO,
        &[C],
        "illegal homing configuration: home speed zero",
    )
    .cause("A sequence that moves with `home_speed` 0.")
    .remedy("Set `home_speed`."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_RETURN_SPEED_ZERO,
        &[C],
        "illegal homing configuration: home return speed zero",
    )
    .cause(
        "A bidirectional sequence (or one with a move to Home Position) with \
         `home_return_speed` 0.",
    )
    .remedy("Set `home_return_speed`."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_ACTIVE_ON_FEEDBACK_ONLY,
        &[C],
        "illegal homing configuration: active homing on a feedback-only axis",
    )
    .ours()
    .cause("`home_mode = \"active\"` on a `feedback_only` axis, which nothing drives.")
    .remedy("Home it passively, or make it a servo axis."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_NO_MARKER,
        &[C],
        "illegal homing configuration: marker sequence without a marker",
    )
    .ours()
    .cause("A marker sequence on an axis whose feedback has no marker (`marker = false`).")
    .remedy("Set `marker = true` if the encoder has one, or choose a sequence without it."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_UNIDIRECTIONAL_TORQUE,
        &[C],
        "illegal homing configuration: unidirectional torque sequence",
    )
    .ours()
    .cause(
        "A torque (hard stop) sequence with a unidirectional direction: the axis must \
         come back off the stop.",
    )
    .remedy("Use a bidirectional `home_direction`."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_TORQUE_CONTROL_MODE,
        &[C],
        "illegal homing configuration: active homing in torque control mode",
    )
    .ours()
    .cause("Active homing with `control_mode = \"torque\"`.")
    .remedy("Home in position or velocity control."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_CYCLIC_HOME_POSITION,
        &[C],
        "illegal homing configuration: cyclic home position outside [0, unwind)",
    )
    .ours()
    .cause("A cyclic axis whose `home_position` lies outside [0, `unwind`).")
    .remedy("Give a Home Position inside one revolution."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_BAD_NUMBER,
        &[C],
        "illegal homing configuration: a negative or non-finite number",
    )
    .ours()
    .cause("A number the engine needs non-negative and finite is not.")
    .remedy("Fix the key the problem names."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_ACCELERATION_ZERO,
        &[C],
        "illegal homing configuration: home acceleration zero",
    )
    .ours()
    .cause("An active sequence that moves with `home_acceleration` 0.")
    .remedy("Set `home_acceleration`."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_DECELERATION_ZERO,
        &[C],
        "illegal homing configuration: home deceleration zero",
    )
    .ours()
    .cause("An active sequence that moves with `home_deceleration` 0.")
    .remedy("Set `home_deceleration`."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_TORQUE_LEVEL,
        &[C],
        "illegal homing configuration: torque level",
    )
    .ours()
    .cause(
        "A torque sequence whose `home_torque_level` is zero, above 100 %, or below \
         `home_torque_threshold`: the hard stop could never be detected.",
    )
    .remedy("Set the level above the threshold and at most 100 % rated."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_UNWIND,
        &[C],
        "illegal homing configuration: cyclic axis without a positive unwind",
    )
    .ours()
    .cause("`travel = \"cyclic\"` with `unwind` 0.")
    .remedy("Set `unwind` to the units of one revolution."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_CONVERSION_CONSTANT,
        &[C],
        "illegal homing configuration: conversion constant not positive",
    )
    .ours()
    .cause("`counts_per_unit` is not above zero.")
    .remedy("Set the drive's counts per axis unit."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_HOME_POSITION_LIMITS,
        &[C],
        "illegal homing configuration: home position outside the travel limits",
    )
    .ours()
    .cause("`home_position` lies outside `travel_limits`.")
    .remedy("Move Home Position inside, or widen the limits."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_TRAVEL_LIMITS,
        &[C],
        "illegal homing configuration: travel limits empty or reversed",
    )
    .ours()
    .cause("`travel_limits` with low not below high.")
    .remedy("Give `[low, high]` with low < high."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_ABSOLUTE_NOT_ABSOLUTE,
        &[C],
        "illegal homing configuration: absolute home mode needs an absolute feedback device",
    )
    .ours()
    .cause("`home_mode = \"absolute\"` on an axis without `absolute = true`.")
    .remedy(
        "Set `absolute = true` if the encoder keeps its position over power cycles; \
         otherwise home actively.",
    ),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_ABOVE_MAX_SPEED,
        &[C],
        "illegal homing configuration: a homing speed above max_speed",
    )
    .ours()
    .cause(
        "A speed the sequence commands (`home_speed`, `home_return_speed`, \
         `home_creep_speed`) is above `max_speed`.",
    )
    .remedy("Lower the homing speed or raise `max_speed`."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_LIMIT_UNIDIRECTIONAL,
        &[C],
        "illegal homing configuration: a limit switch sequence must be bidirectional",
    )
    .ours()
    .cause(
        "A limit-switch sequence with a unidirectional direction: the axis must come \
         back off the limit it seeks.",
    )
    .remedy(
        "Use `bidirectional_forward` (positive limit) or `bidirectional_reverse` \
         (negative limit).",
    ),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_LIMIT_OFFSET,
        &[C],
        "illegal homing configuration: home_offset would leave the axis on the limit switch",
    )
    .ours()
    .cause(
        "A limit-switch sequence whose `home_offset` does not end the axis off the \
         switch: `limit_switch`'s must point away from the limit, into the travel, by \
         more than one cycle of travel at Home Return Speed; \
         `limit_switch_then_marker`'s (which rests on its marker, found after the switch \
         cleared) must be 0 or point away from the limit.",
    )
    .remedy(
        "Give an offset into the travel that also covers the switch's repeatability \
         and hysteresis (typically a millimetre or more).",
    ),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_REVERSE_NOT_APPLICABLE,
        &[C],
        "illegal homing configuration: this sequence cannot reverse at a limit",
    )
    .ours()
    .cause(
        "`home_reverse_at_limit` on a sequence other than bidirectional `switch` or \
         `switch_then_marker`, or on a gantry's side.",
    )
    .remedy("Remove the key, or use one of those sequences."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        EX_NO_LIMIT_SWITCHES,
        &[C],
        "illegal homing configuration: the axis has no limit switches",
    )
    .ours()
    .cause(
        "A limit-switch sequence or `home_reverse_at_limit` on an axis without limit \
         switches (`limit_switches = false`, or a cyclic axis).",
    )
    .remedy("Wire and enable the limit switches, or choose a sequence without them."),
    code(
        ERR_ILLEGAL_HOMING_CONFIG,
        0,
        &[C],
        "illegal homing configuration",
    )
    .any()
    .cause("The engine's validation refused the homing configuration.")
    .remedy("See the EXERR's row and the key `check` names."),
    code(ERR_INTERRUPTED, 0, &[H], "homing interrupted externally")
        .any()
        .cause(
            "The Home operation wrapper's code, kept for tools that map it; this engine \
             reports every interruption more precisely (12 / 1, 12 / 12, 12 / 40).",
        )
        .remedy("See those codes."),
    code(ERR_TIMEOUT, 0, &[H], "home timeout exceeded")
        .any()
        .cause("The homing took longer than `home_timeout`.")
        .remedy(
            "Check why (a switch that never comes, a slow search); raise `home_timeout` if \
             the search is simply long.",
        ),
    code(
        ERR_SEARCH_LIMIT,
        EX_SEARCH_REVERSE,
        &[H],
        "the run back past the home switch after a limit went beyond the search limit",
    )
    .ours()
    .cause(
        "With `home_reverse_at_limit`, the run back from the limit travelled farther \
         than `search_limit` without passing the home switch.",
    )
    .remedy(
        "Check the home switch (wiring, `home_switch_normally_closed`) and the search \
         limit.",
    ),
    code(
        ERR_SEARCH_LIMIT,
        0,
        &[H],
        "search travelled beyond the search limit",
    )
    .any()
    .ours()
    .cause(
        "A search leg travelled farther than `search_limit` from where it began; the \
         EXERR names the leg: 2 seek, 5 return, 10 creep, 11 the run back after a \
         limit.",
    )
    .remedy(
        "Check the switch or marker the leg looks for (wiring, NO/NC, the marker \
         setting) and `search_limit` (default 1.1 × the travel span).",
    ),
    code(
        ERR_GANTRY_SKEW,
        0,
        &[H],
        "gantry sides latched their events further apart than max_skew",
    )
    .any()
    .ours()
    .cause(
        "The sides of a gantry found their events further apart than `max_skew`: both \
         fail together, nothing is squared.",
    )
    .remedy(
        "Check the sides' switches and mechanics (a racked gantry, a moved switch), or \
         raise `max_skew` if the skew is expected.",
    ),
    code(
        ERR_AMBIGUOUS_MARKER,
        0,
        &[H],
        "the marker lies too close to the switch edge to tell which one is meant",
    )
    .any()
    .ours()
    .cause(
        "Switch then marker: the marker lay closer than `marker_min_distance` to the \
         switch edge and `refuse_ambiguous_marker` is set (the axis stopped, not homed).",
    )
    .remedy(
        "Move the home switch (or the encoder's index) by about half a marker spacing, \
         so the marker is clearly on one side.",
    ),
    code(
        ERR_SETPOINT_REFUSED,
        EX_SETPOINT_NOT_FINITE,
        &[F],
        "setpoint refused: not finite",
    )
    .ours()
    .cause(
        "A setpoint's position or velocity was not finite; the stream stopped the axis \
         at the larger of `max_deceleration` and `stream_acceleration`.",
    )
    .remedy("Fix the program; `reset`, then stream again."),
    code(
        ERR_SETPOINT_REFUSED,
        EX_SETPOINT_OUTSIDE_LIMITS,
        &[F],
        "setpoint refused: outside the travel limits",
    )
    .ours()
    .cause("A setpoint outside `travel_limits` (homed, linear) or beyond ±`max_position`.")
    .remedy("Keep the program's path inside the limits; `reset`."),
    code(
        ERR_SETPOINT_REFUSED,
        EX_SETPOINT_SPEED,
        &[F],
        "setpoint refused: faster than max_speed (unhomed: unhomed_speed)",
    )
    .ours()
    .cause(
        "A step between setpoints faster than the speed cap (`max_speed`; \
         `unhomed_speed` while not homed), a velocity feed-forward above it, or a \
         command the cap holds back further than it can follow.",
    )
    .remedy("Slow the program down, or raise `max_speed` if the machine allows it."),
    code(
        ERR_SETPOINT_REFUSED,
        EX_SETPOINT_ACCELERATION,
        &[F],
        "setpoint refused: change of velocity above stream_acceleration",
    )
    .ours()
    .cause(
        "The change of segment velocity asked for more than `stream_acceleration`, or \
         the command is held back by that acceleration further than it can follow — \
         judged on the cycle's timeline, whatever the setpoints' timestamps say.",
    )
    .remedy("Smooth the program's path, or raise `stream_acceleration`."),
    code(
        ERR_SETPOINT_REFUSED,
        EX_SETPOINT_STALE,
        &[F],
        "stream silent: no setpoint for stream_timeout_ms since the last one arrived",
    )
    .ours()
    .cause(
        "No new setpoint arrived for `stream_timeout_ms`, however far ahead the last one \
         lay: the program died, hangs, or publishes too rarely.",
    )
    .remedy("Publish more often than the timeout (or raise it, up to 1 s); `reset`."),
    code(
        ERR_SETPOINT_REFUSED,
        EX_SETPOINT_OUT_OF_ORDER,
        &[F],
        "setpoint out of order: its time is not after the previous one's",
    )
    .ours()
    .cause("A setpoint whose time is not after the previous one's.")
    .remedy("Stamp setpoints with an increasing monotonic time."),
    code(
        ERR_SETPOINT_REFUSED,
        EX_SETPOINT_NOT_HOMED,
        &[F, R],
        "stream stopped: the axis is not homed (stream_unhomed is false)",
    )
    .ours()
    .cause(
        "The axis is not homed (or lost HomedStatus while streaming) and \
         `stream_unhomed` is false.",
    )
    .remedy(
        "Home the axis first, or set `stream_unhomed = true` where streaming unhomed \
         is safe.",
    ),
    code(ERR_SETPOINT_REFUSED, 0, &[F], "setpoint refused")
        .any()
        .ours()
        .cause("A setpoint was refused and the stream stopped the axis.")
        .remedy("See the EXERR's row; `reset`."),
    code(
        ERR_JOG_LEASE_EXPIRED,
        0,
        &[N],
        "jog lease expired: the jog stopped (hold to run)",
    )
    .any()
    .ours()
    .cause(
        "A jog's client stopped renewing its lease (it ended, hangs, or lost its \
         connection): the jog stopped normally, ER stays clear.",
    )
    .remedy("Nothing, if the client ended; otherwise check the client and its link."),
    code(ERR_MONITOR, EX_MONITOR_VELOCITY, &[F], "cycle monitor: commanded velocity above its bound")
        .ours()
        .cause("The independent cycle monitor found a command's velocity above the speed bound that applies (the cap: `max_speed`, `unhomed_speed` while not homed, the operation's own speed, the homing speeds; after a stop, the bound decaying at the stop's deceleration). The monitor stopped the axis itself: category 1 from the last command it passed, then the power stage off.")
        .remedy("A defect in whatever planned that command: keep the log line (it has the values) and report it; `reset` to continue."),
    code(ERR_MONITOR, EX_MONITOR_ACCELERATION, &[F], "cycle monitor: commanded acceleration above its bound")
        .ours()
        .cause("The second difference of the commanded positions over the cycle exceeded the acceleration bound (the operation's acceleration or deceleration, `stream_acceleration`, the homing accelerations; a stop at least `max_deceleration`).")
        .remedy("As for 1021 / 1: keep the log line, report it; `reset`."),
    code(ERR_MONITOR, EX_MONITOR_STEP, &[F], "cycle monitor: a set-point step larger than the speed bound allows")
        .ours()
        .cause("Two consecutive command positions lay further apart than the speed bound allows over the time between them.")
        .remedy("As for 1021 / 1: keep the log line, report it; `reset`."),
    code(ERR_MONITOR, EX_MONITOR_SOFT_LIMIT, &[F], "cycle monitor: commanded position beyond a travel limit")
        .ours()
        .cause("A homed linear axis was commanded outside `travel_limits`, or further out than the command before it once outside.")
        .remedy("Move back inside the limits after `reset`; report the planner's defect with the log line."),
    code(ERR_MONITOR, EX_MONITOR_ENABLE, &[F], "cycle monitor: the power stage asked on without a request")
        .ours()
        .cause("The power stage was asked on after a drive fault, a dropped power stage, a lost drive, a new I/O process, a shutdown, or a disable that had come to rest, without an explicit enable, home, jog, move or stream since.")
        .remedy("`reset`, then `enable` explicitly; report the defect with the log line."),
    code(ERR_MONITOR, EX_MONITOR_GANTRY, &[F], "cycle monitor: the gantry's sides moved apart")
        .ours()
        .cause("The sides of a gantry moved apart by more than `max_skew` from where they were at rest together.")
        .remedy("Inspect the mechanics; `reset`, and home the gantry again if the skew is real."),
    code(ERR_MONITOR, EX_MONITOR_NOT_FINITE, &[F], "cycle monitor: a command that is not a number")
        .ours()
        .cause("A command position or velocity was not finite: the monitor stopped the axis from the last command it passed (category 1; category 0 where the power stage was already off).")
        .remedy("Report the defect with the log line; `reset`."),
    code(ERR_MONITOR, 0, &[F], "cycle monitor: a command broke an invariant")
        .any()
        .ours()
        .cause("The cycle monitor stopped the axis: a command broke one of its invariants.")
        .remedy("See the EXERR's row; `reset`."),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_JERK,
        &[R],
        "parameter out of range: jerk",
    )
    .ours()
    .cause(
        "A jog, move or change asked for a negative or infinite jerk (0 plans a trapezoid, \
         above 0 an S-curve).",
    )
    .remedy("Give a jerk of 0 or more units/s³, or leave it out for the axis's `jerk`."),
    code(
        ERR_EXECUTION_COLLISION,
        EX_NOTHING_TO_CHANGE,
        &[R],
        "change: no jog or move runs on the axis",
    )
    .ours()
    .cause(
        "A change of dynamics (MCD) on an axis that neither jogs nor moves: at rest, \
         stopping, or homing's abort coming to rest. (Homing itself refuses with 16, a \
         stream with 3 / 0.)",
    )
    .remedy("Change a motion while it runs; start a new jog or move with the dynamics instead."),

    code(
        ERR_EXECUTION_COLLISION,
        EX_REDEFINE,
        &[R],
        "redefine refused: the axis is not at rest (a jog, move, stream or stop runs)",
    )
    .cause(
        "Redefine position on an axis whose command is not at rest: a jog, move or \
         stream runs, or a stop or an enable is under way. Redefining under motion would \
         move the reference of a profile in flight.",
    )
    .remedy("Stop the axis (`motionctl stop AXIS`), wait for it to be at rest, redefine."),
    code(
        ERR_HOME_IN_PROCESS,
        EX_REDEFINE,
        &[R],
        "redefine refused: homing in process",
    )
    .cause("Redefine position while the axis homes: homing establishes the reference itself.")
    .remedy("Wait for the homing to end (or `stop` it), then redefine."),
    code(
        ERR_AXIS_FAULTED,
        EX_REDEFINE,
        &[R],
        "redefine refused: axis in faulted state",
    )
    .cause("Redefine position while the axis has an axis fault (ER set).")
    .remedy("See the fault's code, remove its cause, `motionctl reset AXIS`, redefine."),
    code(
        ERR_REDEFINE_REFUSED,
        EX_REDEFINE_NOT_HOMED,
        &[R],
        "redefine refused: the axis is not homed",
    )
    .ours()
    .cause(
        "Redefine position on an axis without HomedStatus: there is no machine reference \
         to shift (before homing, the axis position is the raw position).",
    )
    .remedy("Home the axis (or let an absolute axis restore its reference), then redefine."),
    code(
        ERR_REDEFINE_REFUSED,
        EX_REDEFINE_NOT_FINITE,
        &[R],
        "redefine refused: the position or shift is not a usable number",
    )
    .ours()
    .cause(
        "The new position or the shift is not finite, or so large that the axis's \
         position, its offset or its soft limits would lie beyond ±`max_position`.",
    )
    .remedy("Give a finite position (`--position P`) or shift (`--by D`) of a sane size."),
    code(
        ERR_REDEFINE_REFUSED,
        EX_REDEFINE_GEARED,
        &[R],
        "redefine refused: the axis is geared (master or slave)",
    )
    .ours()
    .cause(
        "Redefine position on an axis that follows a master, or that another axis \
         follows: the gear follows its positions, so redefining them would move the \
         slave.",
    )
    .remedy("Stop the gearing (`motionctl stop SLAVE`), then redefine."),
    code(ERR_REDEFINE_REFUSED, 0, &[R], "redefine position refused")
        .any()
        .ours()
        .cause("Redefine position was refused; the EXERR says why.")
        .remedy("See the EXERR's row."),
    code(
        ERR_REGISTRATION_REFUSED,
        EX_REGISTRATION_NO_FEEDBACK_DEVICE,
        &[R],
        "registration refused: a virtual axis has no inputs",
    )
    .ours()
    .cause(
        "`arm` on a `virtual` axis: it has no feedback device, no switch and no marker to latch.",
    )
    .remedy("Arm the registration on an axis with a drive or a feedback device."),
    code(
        ERR_REGISTRATION_REFUSED,
        EX_REGISTRATION_NO_MARKER,
        &[R],
        "registration refused: the axis has no marker",
    )
    .ours()
    .cause(
        "`arm --input marker` on an axis whose feedback device has no marker (`marker = false`).",
    )
    .remedy("Latch the home switch input instead, or set `marker = true` if the encoder has one."),
    code(
        ERR_REGISTRATION_REFUSED,
        EX_REGISTRATION_WINDOW_NOT_FINITE,
        &[R],
        "registration refused: the window is not a pair of numbers",
    )
    .ours()
    .cause("A bound of `--window LO HI` is not finite.")
    .remedy("Give two finite axis positions, or no window."),
    code(
        ERR_REGISTRATION_REFUSED,
        EX_REGISTRATION_WINDOW_EMPTY,
        &[R],
        "registration refused: the window's LO lies above its HI",
    )
    .ours()
    .cause("`--window LO HI` with LO > HI: no position lies inside it.")
    .remedy("Give the lower bound first."),
    code(ERR_REGISTRATION_REFUSED, 0, &[R], "registration refused")
        .any()
        .ours()
        .cause("A registration was refused; nothing was armed.")
        .remedy("See the EXERR's row."),
    code(
        ERR_GEARING,
        EX_GEAR_SOFT_LIMIT,
        &[F],
        "gearing stopped: the slave would pass a travel limit",
    )
    .ours()
    .cause(
        "A geared slave (homed, linear, `travel_limits`) could no longer have stopped \
         inside its travel limits at `max_deceleration` had it gone on following: it \
         stopped, ending inside, and its master was stopped too.",
    )
    .remedy("Move the master back so the slave's path stays inside its limits; `reset`."),
    code(
        ERR_GEARING,
        EX_GEAR_CANNOT_FOLLOW,
        &[F],
        "gearing stopped: the slave cannot follow its master",
    )
    .ours()
    .cause(
        "The geared position ran ahead of the slave further than it can catch up: the \
         master × ratio is faster than the slave's speed cap (`max_speed`; \
         `unhomed_speed` while not homed), or changes speed harder than the slave may \
         (its `stream_acceleration`).",
    )
    .remedy("Lower the ratio or the master's speed and acceleration; `reset`."),
    code(
        ERR_GEARING,
        EX_GEAR_MASTER_FAULTED,
        &[F, R],
        "gearing: the master is faulted",
    )
    .ours()
    .cause("The master faulted while the slave followed it (or was faulted at the start).")
    .remedy("Clear the master's fault (`reset` both axes), then gear again."),
    code(
        ERR_GEARING,
        EX_GEAR_SELF,
        &[R],
        "gearing refused: the master is the slave",
    )
    .ours()
    .cause("`gear` named the slave as its own master.")
    .remedy("Name another axis with `--master`."),
    code(
        ERR_GEARING,
        EX_GEAR_MASTER_UNAVAILABLE,
        &[F, R],
        "gearing: the master's position is not available",
    )
    .ours()
    .cause(
        "With `--actual`, the master has no valid actual position (its feedback is lost \
         or not yet there); or the cycle could not read the master.",
    )
    .remedy("Restore the master's feedback, or gear on its command (without `--actual`)."),
    code(
        ERR_GEARING,
        EX_GEAR_CHAINED,
        &[R],
        "gearing refused: chained gearing",
    )
    .ours()
    .cause(
        "The master is itself geared to another axis, or the slave is the master of a \
         geared axis: gearing is one level deep.",
    )
    .remedy("Gear every slave to the first master directly (ratios multiply)."),
    code(ERR_GEARING, 0, &[F, R], "gearing refused or stopped")
        .any()
        .ours()
        .cause("A gear was refused, or a geared slave stopped with an error.")
        .remedy("See the EXERR's row; `reset` after a fault."),
    code(
        ERR_PARAMETER_OUT_OF_RANGE,
        EX_PARAM_RATIO,
        &[R],
        "parameter out of range: gear ratio",
    )
    .cause("A gear ratio that is not finite, or is 0.")
    .remedy("Give a finite, non-zero `--ratio` (negative: the opposite direction)."),
];

/// The row of `(err, exerr)`: its own, else the one for any EXERR of `err`.
pub fn lookup(err: u16, exerr: u16) -> Option<&'static Code> {
    TABLE
        .iter()
        .find(|c| c.err == err && c.exerr == Some(exerr))
        .or_else(|| TABLE.iter().find(|c| c.err == err && c.exerr.is_none()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One row per code, each explained; every EXERR of a family has a
    /// fallback row for its ERR where the ERR has several.
    #[test]
    fn every_row_is_complete_and_once() {
        for (i, c) in TABLE.iter().enumerate() {
            let id = format!("{} / {:?}", c.err, c.exerr);
            assert!(!c.short.is_empty() && !c.cause.is_empty(), "{id}");
            assert!(!c.remedy.is_empty() && !c.seen.is_empty(), "{id}");
            assert!(
                !TABLE[..i]
                    .iter()
                    .any(|o| o.err == c.err && o.exerr == c.exerr),
                "{id} twice"
            );
        }
        assert_eq!(
            lookup(ERR_SEARCH_LIMIT, EX_SEARCH_SEEK).unwrap().exerr,
            None
        );
        assert_eq!(
            lookup(ERR_SERVO_MESSAGE, EX_DRIVE_LOST).unwrap().exerr,
            Some(EX_DRIVE_LOST)
        );
        assert!(lookup(ERR_SERVO_MESSAGE, 999).is_none());
    }
}
