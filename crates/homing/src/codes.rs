//! Error codes reported in the instruction's `ERR` / `EXERR`. Each has a
//! row in [`crate::code_table`] with its meaning, cause and remedy — what
//! `motionctl` prints beside a code and what the manual's error page
//! (`docs/errors.md`, written by `motion-docgen`) lists.
//!
//! The CIP codes (12, 41 and the extended codes 1, 4, 6, 7, 12, 16) are the
//! Motion Axis Home instruction's; 1014 and 1015 are the Home operation
//! wrapper's; the operations around homing use the codes the Logix motion
//! instructions report (3, 5, 9, 13, 16, 20). Codes marked *ours* extend
//! those tables in the same style.
//!
//! Three kinds of report carry a code: a homing that ends without PC
//! (`ER`, the instruction's error), a **refusal** of an operation (answered
//! per axis and in `Status::op.refused`, never setting the axis's ER), and
//! an **axis fault** that ends a motion (ER set, `Status::faulted`, cleared
//! by `Operation::Reset`). A configuration the engine's validation refuses
//! carries its ERR 41 code in `check`'s problem.
//!
//! **Limit switches while homing** (12 / 43): a limit switch tripped in the
//! direction of travel aborts homing, except where the sequence means to be
//! on it: the seek of a limit-switch sequence and the stop on its limit, and
//! the stop at the limit after which `home_reverse_at_limit` reverses the
//! search — each for the limit in Home Direction only. The other limit, and
//! that limit in any other leg (the return, the move home, the second seek
//! after a reversal, the run back past the home switch, which meets the
//! other limit when there is no home switch between the two), still abort
//! with 12 / 43. A unidirectional sequence that reaches a limit also ends
//! with 12 / 43 (it cannot reverse; `home_reverse_at_limit` is refused for
//! it with 41 / 37).
//!
//! To add a code: its constant below, and one row in
//! [`TABLE`](crate::code_table::TABLE).

/// Servo message failure.
pub const ERR_SERVO_MESSAGE: u16 = 12;
/// Illegal homing configuration.
pub const ERR_ILLEGAL_HOMING_CONFIG: u16 = 41;
/// Homing interrupted externally (wrapper).
pub const ERR_INTERRUPTED: u16 = 1014;
/// Home timeout (wrapper).
pub const ERR_TIMEOUT: u16 = 1015;
/// Search leg went farther than the search limit (ours).
pub const ERR_SEARCH_LIMIT: u16 = 1016;
/// Gantry sides' events further apart than `max_skew` (ours; reported by the
/// machine coordinator as a stop code).
pub const ERR_GANTRY_SKEW: u16 = 1017;
/// Marker too close to the switch edge, refused (ours).
pub const ERR_AMBIGUOUS_MARKER: u16 = 1018;

// EXERR under ERR 1016: which search leg went too far.
pub const EX_SEARCH_SEEK: u16 = 2;
pub const EX_SEARCH_RETURN: u16 = 5;
pub const EX_SEARCH_CREEP: u16 = 10;
pub const EX_SEARCH_REVERSE: u16 = 11;

// EXERR under ERR 12.
pub const EX_TERMINATED_ON_REQUEST: u16 = 1;
pub const EX_AXIS_SHUTDOWN: u16 = 12;
pub const EX_DRIVE_FAULT: u16 = 16;
pub const EX_FEEDBACK_LOST: u16 = 40;
pub const EX_FEEDBACK_INVALID: u16 = 41;
pub const EX_ENABLE_TIMEOUT: u16 = 42;
pub const EX_OVERTRAVEL: u16 = 43;
pub const EX_FEEDBACK_IMPLAUSIBLE: u16 = 44;
pub const EX_DRIVE_LOST: u16 = 45;
pub const EX_DRIVE_HOMING_ERROR: u16 = 46;

// EXERR under ERR 41.
pub const EX_SEQUENCE_INCOMPATIBLE: u16 = 4;
pub const EX_HOME_SPEED_ZERO: u16 = 6;
pub const EX_RETURN_SPEED_ZERO: u16 = 7;
pub const EX_ACTIVE_ON_FEEDBACK_ONLY: u16 = 20;
pub const EX_NO_MARKER: u16 = 21;
pub const EX_UNIDIRECTIONAL_TORQUE: u16 = 22;
pub const EX_TORQUE_CONTROL_MODE: u16 = 23;
pub const EX_CYCLIC_HOME_POSITION: u16 = 24;
pub const EX_BAD_NUMBER: u16 = 25;
pub const EX_ACCELERATION_ZERO: u16 = 26;
pub const EX_DECELERATION_ZERO: u16 = 27;
pub const EX_TORQUE_LEVEL: u16 = 28;
pub const EX_UNWIND: u16 = 29;
pub const EX_CONVERSION_CONSTANT: u16 = 30;
pub const EX_HOME_POSITION_LIMITS: u16 = 31;
pub const EX_TRAVEL_LIMITS: u16 = 32;
pub const EX_ABSOLUTE_NOT_ABSOLUTE: u16 = 33;
pub const EX_ABOVE_MAX_SPEED: u16 = 34;

// --- the operations around homing ---------------------------------------

/// Execution collision: another operation runs that this one may not replace.
pub const ERR_EXECUTION_COLLISION: u16 = 3;
/// Servo off state: the drive is not enabled.
pub const ERR_SERVO_OFF: u16 = 5;
/// Overtravel condition: motion towards a tripped limit switch.
pub const ERR_OVERTRAVEL_CONDITION: u16 = 9;
/// Parameter out of range; EXERR names the operand (`EX_PARAM_*`).
pub const ERR_PARAMETER_OUT_OF_RANGE: u16 = 13;
/// Home in process: stop homing first.
pub const ERR_HOME_IN_PROCESS: u16 = 16;
/// Axis in faulted state: reset first.
pub const ERR_AXIS_FAULTED: u16 = 20;
/// A setpoint of the supervised stream was refused; the stream stopped the
/// axis (ours). EXERR: `EX_SETPOINT_*`.
pub const ERR_SETPOINT_REFUSED: u16 = 1019;
/// The jog's lease ran out (ours): a normal stop, only logged.
pub const ERR_JOG_LEASE_EXPIRED: u16 = 1020;

// EXERR under ERR 5.
/// The axis is `feedback_only`: nothing to enable or move.
pub const EX_NOT_SERVO: u16 = 1;

// EXERR under ERR 13: the operand.
pub const EX_PARAM_SPEED: u16 = 1;
pub const EX_PARAM_ACCELERATION: u16 = 2;
pub const EX_PARAM_DECELERATION: u16 = 3;
pub const EX_PARAM_TARGET: u16 = 4;
pub const EX_PARAM_NOT_FINITE: u16 = 5;
pub const EX_PARAM_LEASE: u16 = 6;
/// No speed bound: `max_speed` is not set and the homing derives none
/// (an immediate, absolute or passive homing): nothing may move the axis.
pub const EX_PARAM_NO_MAX_SPEED: u16 = 7;
/// The jerk: negative or not finite (0 is a trapezoid).
pub const EX_PARAM_JERK: u16 = 8;

// EXERR under ERR 3.
/// A change of dynamics (MCD) with no jog or move running to change.
pub const EX_NOTHING_TO_CHANGE: u16 = 1;

// EXERR under ERR 1019.
pub const EX_SETPOINT_NOT_FINITE: u16 = 1;
pub const EX_SETPOINT_OUTSIDE_LIMITS: u16 = 2;
pub const EX_SETPOINT_SPEED: u16 = 3;
pub const EX_SETPOINT_ACCELERATION: u16 = 4;
pub const EX_SETPOINT_STALE: u16 = 5;
pub const EX_SETPOINT_OUT_OF_ORDER: u16 = 6;
pub const EX_SETPOINT_NOT_HOMED: u16 = 7;
pub const EX_LIMIT_UNIDIRECTIONAL: u16 = 35;
pub const EX_LIMIT_OFFSET: u16 = 36;
pub const EX_REVERSE_NOT_APPLICABLE: u16 = 37;
pub const EX_NO_LIMIT_SWITCHES: u16 = 38;

/// The cycle monitor stopped the axis: a command broke one of its
/// invariants (ours). EXERR: `EX_MONITOR_*`.
pub const ERR_MONITOR: u16 = 1021;

// EXERR under ERR 1021: the invariant the cycle monitor found broken.
pub const EX_MONITOR_VELOCITY: u16 = 1;
pub const EX_MONITOR_ACCELERATION: u16 = 2;
pub const EX_MONITOR_STEP: u16 = 3;
pub const EX_MONITOR_SOFT_LIMIT: u16 = 4;
pub const EX_MONITOR_ENABLE: u16 = 5;
pub const EX_MONITOR_GANTRY: u16 = 6;
pub const EX_MONITOR_NOT_FINITE: u16 = 7;

// --- redefine position (MRP) ----------------------------------------------
/// The EXERR that marks a refusal of redefine position under the Logix
/// codes it shares (3 in motion, 16 homing, 20 faulted).
pub const EX_REDEFINE: u16 = 25;
/// Redefine position refused (ours); EXERR: `EX_REDEFINE_*`.
pub const ERR_REDEFINE_REFUSED: u16 = 1023;
/// The axis is not homed: there is no reference to redefine.
pub const EX_REDEFINE_NOT_HOMED: u16 = 1;
/// The redefined position, shift or soft limits would not be finite, or
/// would lie beyond ±`max_position`.
pub const EX_REDEFINE_NOT_FINITE: u16 = 2;
/// The axis is geared, as slave or as master: the gear follows its
/// positions (refused by the cycle, which sees both ends of a gear).
pub const EX_REDEFINE_GEARED: u16 = 3;
/// A registration (MAR, `Operation::Arm`) was refused (ours): nothing was
/// armed. EXERR: `EX_REGISTRATION_*`. (Homing in process refuses it with
/// ERR 16 as every operation.)
pub const ERR_REGISTRATION_REFUSED: u16 = 1022;
// EXERR under ERR 1022.
/// A virtual axis: no feedback device, no inputs to latch.
pub const EX_REGISTRATION_NO_FEEDBACK_DEVICE: u16 = 1;
/// `--input marker` on an axis whose feedback has no marker (`marker = false`).
pub const EX_REGISTRATION_NO_MARKER: u16 = 2;
/// The window's bounds are not finite numbers.
pub const EX_REGISTRATION_WINDOW_NOT_FINITE: u16 = 3;
/// The window's LO lies above its HI.
pub const EX_REGISTRATION_WINDOW_EMPTY: u16 = 4;

// --- gearing (MAG) -------------------------------------------------------

/// Gearing (ours): a geared slave stopped with an error, or a gear refused
/// for what only gearing has (EXERR: `EX_GEAR_*`).
pub const ERR_GEARING: u16 = 1025;
/// The slave, going on, could no longer stop inside its travel limits at
/// `max_deceleration`: it stops (ending inside) and its master stops too.
pub const EX_GEAR_SOFT_LIMIT: u16 = 1;
/// The slave lags the geared position further than it can catch up within
/// its speed cap and acceleration bound.
pub const EX_GEAR_CANNOT_FOLLOW: u16 = 2;
/// The master faulted (or is faulted at the start): the slave stops.
pub const EX_GEAR_MASTER_FAULTED: u16 = 3;
/// The master is the slave itself.
pub const EX_GEAR_SELF: u16 = 4;
/// The master's position is not available (no valid actual position with
/// `--actual`, or the cycle has nothing of the master).
pub const EX_GEAR_MASTER_UNAVAILABLE: u16 = 5;
/// Chained gearing: the master is itself geared, or the slave is the
/// master of a geared axis.
pub const EX_GEAR_CHAINED: u16 = 6;

// EXERR under ERR 13, for gearing.
/// A gear ratio that is not finite or is 0.
pub const EX_PARAM_RATIO: u16 = 9;
