//! Error codes reported in the instruction's `ERR` / `EXERR`.
//!
//! The CIP codes (12, 41 and the extended codes 1, 4, 6, 7, 12, 16) are the
//! Motion Axis Home instruction's; 1014 and 1015 are the Home operation
//! wrapper's. Codes marked *ours* extend those tables in the same style; each
//! one is listed here and nowhere else.
//!
//! | ERR  | EXERR | meaning |
//! |------|-------|---------|
//! | 12   | 1     | process terminated on request: a stop during homing |
//! | 12   | 12    | axis in shutdown (at start or during homing) |
//! | 12   | 16    | device in wrong state: drive fault during homing |
//! | 12   | 40    | *ours* feedback lost: the leaky bucket of missing-feedback time went above `feedback_timeout_ns` (I/O process gone, or frames lost too often); `Status::lost_after_ns` holds the gap |
//! | 12   | 41    | *ours* feedback invalid: non-finite or absurd value (the status names the attribute) |
//! | 12   | 42    | *ours* drive did not report enabled within `enable_timeout` |
//! | 12   | 43    | *ours* hardware overtravel input tripped during homing |
//! | 12   | 44    | *ours* feedback implausible: a position further than `max_speed` allows from where the axis was last seen or has been commanded since (a forged or corrupt frame; never an event) |
//! | 12   | 45    | *ours* drive lost: the I/O process is alive but reports the axis's drive gone (EtherCAT: its SubDevice stopped answering, left OP or was power-cycled); the feedback-loss rule tripped on it. motion-io's log names the SubDevice and says what to do |
//! | 12   | 46    | *ours* drive homing error: a `drive_homing` axis's drive reported a homing error (CiA 402 statusword bit 13), refused homing mode, or left it before attaining home |
//! | 41   | 4     | home sequence incompatible with home mode / axis (passive torque, virtual axis moving sequence, absolute mode with a sequence other than immediate) |
//! | 41   | 6     | home speed zero |
//! | 41   | 7     | home return speed zero |
//! | 41   | 20    | *ours* active home mode on a feedback-only axis |
//! | 41   | 21    | *ours* marker sequence but the feedback has no marker |
//! | 41   | 22    | *ours* unidirectional torque sequence |
//! | 41   | 23    | *ours* active homing in torque control mode |
//! | 41   | 24    | *ours* cyclic home position outside `[0, unwind)` |
//! | 41   | 25    | *ours* negative or non-finite number |
//! | 41   | 26    | *ours* home acceleration zero for an active sequence |
//! | 41   | 27    | *ours* home deceleration zero for an active sequence |
//! | 41   | 28    | *ours* torque level zero, above 100 %, or below the threshold (a hard stop could never be detected) |
//! | 41   | 29    | *ours* cyclic axis without a positive unwind |
//! | 41   | 30    | *ours* conversion constant not positive |
//! | 41   | 31    | *ours* home position outside the travel limits |
//! | 41   | 32    | *ours* travel limits empty or reversed |
//! | 41   | 33    | *ours* absolute home mode on a non-absolute feedback device |
//! | 41   | 34    | *ours* a homing speed the sequence commands is above `max_speed` |
//! | 41   | 35    | *ours* limit-switch sequence with a unidirectional direction (the axis must come back off the limit) |
//! | 41   | 36    | *ours* limit-switch sequence whose `home_offset` does not end the axis off the switch: it must point away from the limit, into the travel, by more than one cycle of travel at Home Return Speed |
//! | 41   | 37    | *ours* `home_reverse_at_limit` on a sequence that cannot reverse (only active bidirectional switch and switch then marker can; a unidirectional search is refused here, not failed at the limit) |
//! | 41   | 38    | *ours* limit-switch sequence or `home_reverse_at_limit` on an axis without limit switches (`limit_switches = false`, or a cyclic axis, which has no ends) |
//! | 1014 | 0     | homing interrupted externally: the wrapper's code, kept for tools that map it; this engine reports every interruption it sees more precisely (a stop request or the supervisor shutting down: 12/1, a shutdown: 12/12, lost feedback: 12/40) |
//! | 1015 | 0     | home timeout: homing took longer than `home_timeout` |
//! | 1016 | leg | *ours* search limit: a search leg travelled farther than `search_limit`; EXERR names the leg: 2 seek, 5 return, 10 creep, 11 reverse (the run back past the home switch after a limit, `home_reverse_at_limit`) (an explicit mapping, kept equal to the numbers these legs' phases had when the code was introduced) |
//! | 1017 | 0     | *ours* gantry skew: the sides of a gantry found their events further apart than `max_skew` (reported by the coordinator through `Request::stop_code`) |
//! | 1018 | 0     | *ours* ambiguous marker: switch then marker found its marker closer than `marker_min_distance` to the switch edge, and `refuse_ambiguous_marker` is set (axis stopped, not homed) |
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
//! The operations around homing (issue 15: enable, disable, reset, jog,
//! move, stop, the supervised stream) use the Logix codes the Logix motion
//! instructions report (MOTION-RM002, "Motion Error Codes (.ERR)") for
//! their **refusals** — answered in `Status::op.refused`, never setting the
//! axis's ER — and ERR 12 / 1019 for the **axis faults** that end a motion
//! (ER set, `Status::faulted`, cleared by `Operation::Reset`):
//!
//! | ERR  | EXERR | meaning |
//! |------|-------|---------|
//! | 3    | 0     | execution collision: the axis runs an operation this one may not replace (a move on a jogging or moving axis without `supersede`, a jog on a moving axis, anything but a stop on a streaming axis, a stream start on an axis in motion, a home on an axis that jogs, moves or streams) |
//! | 5    | 0     | servo off state: jog, move or stream on an axis whose drive is not enabled (ServoActionStatus false, or a disable in progress) |
//! | 5    | 1     | *ours* not a servo axis: enable, jog, move or stream on a `feedback_only` axis |
//! | 9    | 0     | overtravel condition: jog or move towards a tripped limit switch (motion away is allowed) |
//! | 12   | 12    | axis in shutdown: enable, jog, move or stream while `Request::shutdown` is set |
//! | 12   | 40    | as a refusal: enable, jog, move or stream without valid feedback (the position to start from is unknown) |
//! | 13   | 1     | parameter out of range, speed: not finite, not above zero, above `max_speed`, or (not homed) above `unhomed_speed`; a stream start without any speed bound (no `max_speed` and no homing speed to derive one) |
//! | 13   | 2     | parameter out of range, acceleration: not finite or not above zero |
//! | 13   | 3     | parameter out of range, deceleration: not finite, not above zero, or above `max_deceleration` |
//! | 13   | 4     | parameter out of range, target: outside `travel_limits` (homed, linear), beyond ±`max_position`, a jog towards a travel limit already reached, or a motion that could not stop inside the travel limits from where the axis is |
//! | 13   | 5     | parameter out of range, target not finite |
//! | 13   | 6     | parameter out of range, jog lease outside 50 ms ..= 5 s |
//! | 16   | 0     | home in process: enable, reset, jog, move or stream on an axis that is homing (stop it first; `disable` and `stop` are always accepted) |
//! | 20   | 0     | axis in faulted state: home, enable, jog, move or stream while the axis has an axis fault (`Status::faulted`): `reset` first |
//! | 12   | 16    | axis fault: the drive faulted (or dropped its power stage) — during homing, a jog, move or stream, or at rest |
//! | 12   | 40    | axis fault: feedback lost during a jog, move or stream (41 invalid, 44 implausible likewise) |
//! | 12   | 42    | axis fault: the drive did not report enabled within `enable_timeout` after an enable |
//! | 12   | 43    | axis fault: a jog, move or stream moved towards a tripped limit switch (stopped at `max_deceleration`) |
//! | 1019 | 1     | *ours* setpoint refused (the stream stops the axis at `max_deceleration`): position or velocity not finite |
//! | 1019 | 2     | *ours* setpoint refused: outside `travel_limits` (homed, linear) or beyond ±`max_position` |
//! | 1019 | 3     | *ours* setpoint refused: step faster than `max_speed` (or a velocity feed-forward above it) |
//! | 1019 | 4     | *ours* setpoint refused: change of segment velocity faster than `stream_acceleration` |
//! | 1019 | 5     | *ours* stream silent: no new setpoint for `stream_timeout_ms` after the last one was reached |
//! | 1019 | 6     | *ours* setpoint out of order: its time is not after the previous one's |
//! | 1019 | 7     | *ours* axis not homed (cleared while streaming) and `stream_unhomed` false |
//! | 1020 | 0     | *ours* jog lease expired (hold to run): NOT an error — the jog stops normally, ER stays false; only logged and shown as `StopCause::LeaseExpired` |
//!
//! The **cycle monitor** (`motion-monitor`, apart from the engine: it judges
//! every command leaving it) reports ERR 1021 when a command broke one of its
//! invariants; EXERR names the invariant. It is an axis fault (ER,
//! `Status::faulted`, cleared by `Operation::Reset`); the monitor has stopped
//! the axis itself (category 1 from the last command it passed, then the
//! power stage off; category 0 where the power stage was already off):
//!
//! | ERR  | EXERR | meaning |
//! |------|-------|---------|
//! | 1021 | 1     | *ours* monitor: commanded velocity (the command's velocity field) above the speed bound that applies (the cap: `max_speed`, `unhomed_speed` while not homed, the operation's own speed, the homing speeds; after a stop, the bound decaying at the stop's deceleration) |
//! | 1021 | 2     | *ours* monitor: commanded acceleration (second difference of the commanded positions over the cycle) above its bound (the operation's acceleration or deceleration, `stream_acceleration`, the homing accelerations; a stop at least `max_deceleration`) |
//! | 1021 | 3     | *ours* monitor: a set-point step larger than the speed bound allows over the time since the last command |
//! | 1021 | 4     | *ours* monitor: commanded position outside `travel_limits` while homed (linear axes), or further out than the command before it once outside |
//! | 1021 | 5     | *ours* monitor: the power stage asked on after a drive fault, a dropped power stage, a lost drive an enable still waited for, a new I/O process, a shutdown, or a disable that had come to rest, without an explicit enable, home, jog, move or stream since |
//! | 1021 | 6     | *ours* monitor: the sides of a gantry moved apart by more than `max_skew` from where they were at rest together |
//! | 1021 | 7     | *ours* monitor: a command position or velocity not finite |

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

// --- the operations around homing (issue 15) ---------------------------

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
/// The cycle monitor stopped the axis: a command broke one of its
/// invariants (ours). EXERR: `EX_MONITOR_*`.
pub const ERR_MONITOR: u16 = 1021;

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

// EXERR under ERR 1021: the invariant the cycle monitor found broken.
pub const EX_MONITOR_VELOCITY: u16 = 1;
pub const EX_MONITOR_ACCELERATION: u16 = 2;
pub const EX_MONITOR_STEP: u16 = 3;
pub const EX_MONITOR_SOFT_LIMIT: u16 = 4;
pub const EX_MONITOR_ENABLE: u16 = 5;
pub const EX_MONITOR_GANTRY: u16 = 6;
pub const EX_MONITOR_NOT_FINITE: u16 = 7;
