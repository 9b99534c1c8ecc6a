//! ERR / EXERR in plain words (the table is `motion_homing::codes`).

use motion_homing::codes::*;

/// One line per ERR/EXERR.
pub fn explain(err: u16, exerr: u16) -> &'static str {
    match (err, exerr) {
        (0, _) => "no error",
        (ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST) => "homing terminated by a stop or disable",
        (ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN) => "axis in shutdown",
        (ERR_SERVO_MESSAGE, EX_DRIVE_FAULT) => "drive fault during homing",
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST) => "feedback lost (I/O process silent or gone)",
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_INVALID) => "invalid feedback (non-finite or absurd)",
        (ERR_SERVO_MESSAGE, EX_ENABLE_TIMEOUT) => "drive did not enable in time",
        (ERR_SERVO_MESSAGE, EX_OVERTRAVEL) => "hardware overtravel during homing",
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
        (ERR_ILLEGAL_HOMING_CONFIG, _) => "illegal homing configuration",
        (ERR_GANTRY_SKEW, _) => "gantry sides latched their events further apart than max_skew",
        (ERR_AMBIGUOUS_MARKER, _) => {
            "the marker lies too close to the switch edge to tell which one is meant"
        }
        (ERR_INTERRUPTED, _) => "homing interrupted externally",
        (ERR_TIMEOUT, _) => "home timeout exceeded",
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
