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
//! | 1014 | 0     | homing interrupted externally: the wrapper's code, kept for tools that map it; this engine reports every interruption it sees more precisely (a stop request or the supervisor shutting down: 12/1, a shutdown: 12/12, lost feedback: 12/40) |
//! | 1015 | 0     | home timeout: homing took longer than `home_timeout` |
//! | 1016 | leg | *ours* search limit: a search leg travelled farther than `search_limit`; EXERR names the leg: 2 seek, 5 return, 10 creep (an explicit mapping, kept equal to the numbers these legs' phases had when the code was introduced) |
//! | 1017 | 0     | *ours* gantry skew: the sides of a gantry found their events further apart than `max_skew` (reported by the coordinator through `Request::stop_code`) |
//! | 1018 | 0     | *ours* ambiguous marker: switch then marker found its marker closer than `marker_min_distance` to the switch edge, and `refuse_ambiguous_marker` is set (axis stopped, not homed) |

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
