//! ERR / EXERR in plain words (the table is `motion_homing::codes`).

use motion_homing::codes::*;

/// One line per ERR/EXERR.
pub fn explain(err: u16, exerr: u16) -> &'static str {
    match (err, exerr) {
        (0, _) => "no error",
        (ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST) => "homing terminated by a stop or disable",
        (ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN) => "axis in shutdown",
        (ERR_SERVO_MESSAGE, EX_DRIVE_FAULT) => "drive fault",
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST) => "feedback lost (I/O process silent or gone)",
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_INVALID) => "invalid feedback (non-finite or absurd)",
        (ERR_SERVO_MESSAGE, EX_ENABLE_TIMEOUT) => "drive did not enable in time",
        (ERR_SERVO_MESSAGE, EX_OVERTRAVEL) => "hardware overtravel: a limit switch was hit",
        (ERR_SERVO_MESSAGE, EX_DRIVE_LOST) => {
            "drive lost: it stopped answering on its bus, left operation or was power-cycled \
             (its I/O process is alive; its log names the drive and what to do)"
        }
        (ERR_SERVO_MESSAGE, EX_DRIVE_HOMING_ERROR) => {
            "the drive's own homing failed: it reported a homing error or did not take homing \
             mode"
        }
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_IMPLAUSIBLE) => {
            "implausible feedback: a position the axis cannot have reached (never a home event)"
        }
        (ERR_ILLEGAL_HOMING_CONFIG, EX_ACTIVE_ON_FEEDBACK_ONLY) => {
            "illegal homing configuration: active homing on a feedback-only axis"
        }
        (ERR_ILLEGAL_HOMING_CONFIG, EX_ABSOLUTE_NOT_ABSOLUTE) => {
            "illegal homing configuration: absolute home mode needs an absolute feedback device"
        }
        (ERR_ILLEGAL_HOMING_CONFIG, EX_ABOVE_MAX_SPEED) => {
            "illegal homing configuration: a homing speed above max_speed"
        }
        (ERR_ILLEGAL_HOMING_CONFIG, EX_LIMIT_UNIDIRECTIONAL) => {
            "illegal homing configuration: a limit switch sequence must be bidirectional"
        }
        (ERR_ILLEGAL_HOMING_CONFIG, EX_LIMIT_OFFSET) => {
            "illegal homing configuration: home_offset would leave the axis on the limit switch"
        }
        (ERR_ILLEGAL_HOMING_CONFIG, EX_REVERSE_NOT_APPLICABLE) => {
            "illegal homing configuration: this sequence cannot reverse at a limit"
        }
        (ERR_ILLEGAL_HOMING_CONFIG, EX_NO_LIMIT_SWITCHES) => {
            "illegal homing configuration: the axis has no limit switches"
        }
        (ERR_ILLEGAL_HOMING_CONFIG, _) => "illegal homing configuration",
        (ERR_GANTRY_SKEW, _) => "gantry sides latched their events further apart than max_skew",
        (ERR_AMBIGUOUS_MARKER, _) => {
            "the marker lies too close to the switch edge to tell which one is meant"
        }
        (ERR_EXECUTION_COLLISION, _) => {
            "execution collision: the axis runs an operation this one may not replace"
        }
        (ERR_SERVO_OFF, EX_NOT_SERVO) => "not a servo axis: nothing to enable or move",
        (ERR_SERVO_OFF, _) => "servo off state: the drive is not enabled",
        (ERR_OVERTRAVEL_CONDITION, _) => {
            "overtravel condition: motion towards a tripped limit switch"
        }
        (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_SPEED) => "parameter out of range: speed",
        (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_ACCELERATION) => {
            "parameter out of range: acceleration"
        }
        (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_DECELERATION) => {
            "parameter out of range: deceleration"
        }
        (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET) => {
            "parameter out of range: target outside the travel limits"
        }
        (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_NOT_FINITE) => {
            "parameter out of range: target not finite"
        }
        (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_LEASE) => "parameter out of range: jog lease",
        (ERR_PARAMETER_OUT_OF_RANGE, _) => "parameter out of range",
        (ERR_HOME_IN_PROCESS, _) => "home in process: stop homing first",
        (ERR_AXIS_FAULTED, _) => "axis in faulted state: reset first",
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_NOT_FINITE) => "setpoint refused: not finite",
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_OUTSIDE_LIMITS) => {
            "setpoint refused: outside the travel limits"
        }
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_SPEED) => "setpoint refused: step above max_speed",
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_ACCELERATION) => {
            "setpoint refused: change of velocity above stream_acceleration"
        }
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_STALE) => "stream silent longer than stream_timeout_ms",
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_OUT_OF_ORDER) => {
            "setpoint out of order: its time is not after the previous one's"
        }
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_NOT_HOMED) => {
            "stream stopped: the axis is not homed (stream_unhomed is false)"
        }
        (ERR_SETPOINT_REFUSED, _) => "setpoint refused",
        (ERR_JOG_LEASE_EXPIRED, _) => "jog lease expired: the jog stopped (hold to run)",
        (ERR_MONITOR, EX_MONITOR_VELOCITY) => {
            "cycle monitor: commanded velocity above its bound (the log has the values)"
        }
        (ERR_MONITOR, EX_MONITOR_ACCELERATION) => {
            "cycle monitor: commanded acceleration above its bound (the log has the values)"
        }
        (ERR_MONITOR, EX_MONITOR_STEP) => {
            "cycle monitor: a set-point step larger than the speed bound allows"
        }
        (ERR_MONITOR, EX_MONITOR_SOFT_LIMIT) => {
            "cycle monitor: commanded position beyond a travel limit"
        }
        (ERR_MONITOR, EX_MONITOR_ENABLE) => {
            "cycle monitor: the power stage asked on without a request since it had to go off"
        }
        (ERR_MONITOR, EX_MONITOR_GANTRY) => "cycle monitor: the gantry's sides moved apart",
        (ERR_MONITOR, EX_MONITOR_NOT_FINITE) => "cycle monitor: a command that is not a number",
        (ERR_MONITOR, _) => "cycle monitor: a command broke an invariant",
        (ERR_INTERRUPTED, _) => "homing interrupted externally",
        (ERR_TIMEOUT, _) => "home timeout exceeded",
        (ERR_SEARCH_LIMIT, EX_SEARCH_REVERSE) => {
            "the run back past the home switch after a limit went beyond the search limit"
        }
        (ERR_SEARCH_LIMIT, _) => "search travelled beyond the search limit",
        _ => "error",
    }
}

/// [`explain`], and for a loss of feedback how long it had been missing
/// when the rule tripped (`gap_s`, seconds; 0 or `None` = not known).
pub fn describe(err: u16, exerr: u16, gap_s: Option<f64>) -> String {
    let text = explain(err, exerr);
    match gap_s {
        Some(g) if (err, exerr) == (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST) && g > 0.0 => {
            format!("{text}: no valid feedback for {:.1} ms", g * 1e3)
        }
        _ => text.to_string(),
    }
}
