//! The bounds the operations around homing run within, as the
//! configuration gives them: each key's "not set" (`0`) resolved to its
//! default once, here, so the engine, `check` and the control plane agree.

use crate::config::{AxisConfig, AxisConfiguration, TravelMode};
use crate::validate::effective_max_speed;

/// `stream_timeout_ns` when not set: 50 ms (50 cycles at 1 kHz; a Python
/// program at 100 Hz may miss four in a row).
pub const DEFAULT_STREAM_TIMEOUT_NS: u64 = 50_000_000;
/// `stream_acceleration` when not set: this many times `home_acceleration`
/// (a program's trajectory is usually livelier than a homing leg).
pub const STREAM_ACCELERATION_FACTOR: f64 = 10.0;
/// Shortest and longest lease of a hold-to-run jog, ns (50 ms ..= 5 s): a
/// shorter one cannot be renewed reliably over a busy control plane, a
/// longer one is no longer "hold to run".
pub const JOG_LEASE_NS: (u64, u64) = (50_000_000, 5_000_000_000);

/// Largest jerk a jog, move or change may ask for, units/s³ (the `jerk`
/// key's bound too): an acceleration of 1e9 units/s² reached in a
/// millisecond. Beyond it a plan's numbers lose their meaning.
pub const MAX_JERK: f64 = 1e12;

fn positive(x: f64) -> Option<f64> {
    (x.is_finite() && x > 0.0).then_some(x)
}

/// Jog and move speed cap while not homed: `unhomed_speed`, else
/// `home_speed`; 0 when neither is set (nothing moves unhomed).
pub fn effective_unhomed_speed(cfg: &AxisConfig) -> f64 {
    positive(cfg.unhomed_speed)
        .or(positive(cfg.home_speed))
        .unwrap_or(0.0)
}

/// Logix "Maximum Deceleration": `max_deceleration`, else the largest
/// deceleration configured on the axis (`home_deceleration`); 0 when none
/// is (then no operation moves the axis: it could not be stopped).
pub fn effective_max_deceleration(cfg: &AxisConfig) -> f64 {
    positive(cfg.max_deceleration)
        .or(positive(cfg.home_deceleration))
        .unwrap_or(0.0)
}

/// Bound of a stream's change of segment velocity: `stream_acceleration`,
/// else 10 × `home_acceleration`; 0 when neither is set.
pub fn effective_stream_acceleration(cfg: &AxisConfig) -> f64 {
    positive(cfg.stream_acceleration)
        .or(positive(cfg.home_acceleration).map(|a| STREAM_ACCELERATION_FACTOR * a))
        .unwrap_or(0.0)
}

/// A silent stream stops the axis after this long: `stream_timeout_ns`,
/// else 50 ms.
pub fn effective_stream_timeout_ns(cfg: &AxisConfig) -> u64 {
    if cfg.stream_timeout_ns > 0 {
        cfg.stream_timeout_ns
    } else {
        DEFAULT_STREAM_TIMEOUT_NS
    }
}

/// Every bound of the operations, resolved once (the engine keeps it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpLimits {
    /// `max_speed` or the one derived from the homing speeds; `None`: no
    /// speed bound is known — jog, move and stream are refused (13 / 7);
    /// homing, which has its own speeds, still works.
    pub max_speed: Option<f64>,
    pub unhomed_speed: f64,
    pub max_deceleration: f64,
    pub stream_acceleration: f64,
    pub stream_timeout_ns: u64,
}

impl OpLimits {
    pub fn new(cfg: &AxisConfig) -> Self {
        Self {
            max_speed: effective_max_speed(cfg),
            unhomed_speed: effective_unhomed_speed(cfg),
            max_deceleration: effective_max_deceleration(cfg),
            stream_acceleration: effective_stream_acceleration(cfg),
            stream_timeout_ns: effective_stream_timeout_ns(cfg),
        }
    }
}

/// What a controls engineer would want pointed out about the operations'
/// bounds (legal, but probably not meant); `check` prints them beside
/// [`advisories`](crate::validate::advisories).
pub fn advisories(cfg: &AxisConfig) -> Vec<String> {
    let l = OpLimits::new(cfg);
    let mut out = Vec::new();
    if cfg.configuration == AxisConfiguration::FeedbackOnly {
        return out;
    }
    if l.max_speed.is_none() {
        out.push(
            "max_speed: none set and no homing speed to derive one (immediate, absolute or \
             passive homing): jog, move and the setpoint stream are refused (ERR 13 / EXERR 7); \
             homing works. Set max_speed to move the axis."
                .into(),
        );
    }
    if l.max_deceleration == 0.0 {
        out.push(
            "max_deceleration: none set and no home_deceleration: jogs, moves and the stream \
             are refused (ERR 13 / EXERR 3): nothing could stop them"
                .into(),
        );
    }
    if l.unhomed_speed == 0.0 {
        out.push(
            "unhomed_speed: none set and no home_speed: the axis cannot be jogged or moved \
             before it is homed"
                .into(),
        );
    } else if l.max_speed.is_some_and(|m| l.unhomed_speed > m) {
        out.push(format!(
            "unhomed_speed {} is above max_speed {}: max_speed applies",
            l.unhomed_speed,
            l.max_speed.unwrap_or(0.0)
        ));
    }
    if cfg.travel == TravelMode::Cyclic && cfg.travel_limits.is_some() {
        out.push("travel_limits: a cyclic axis has no software travel limits".into());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_come_from_the_homing_attributes() {
        let cfg = AxisConfig {
            home_speed: 20.0,
            home_acceleration: 400.0,
            home_deceleration: 500.0,
            ..AxisConfig::default()
        };
        let l = OpLimits::new(&cfg);
        assert_eq!(l.unhomed_speed, 20.0);
        assert_eq!(l.max_deceleration, 500.0);
        assert_eq!(l.stream_acceleration, 4000.0);
        assert_eq!(l.stream_timeout_ns, 50_000_000);
        let set = OpLimits::new(&AxisConfig {
            unhomed_speed: 5.0,
            max_deceleration: 2000.0,
            stream_acceleration: 100.0,
            stream_timeout_ns: 7,
            max_speed: 30.0,
            ..cfg
        });
        assert_eq!(
            set,
            OpLimits {
                max_speed: Some(30.0),
                unhomed_speed: 5.0,
                max_deceleration: 2000.0,
                stream_acceleration: 100.0,
                stream_timeout_ns: 7,
            }
        );
        let none = OpLimits::new(&AxisConfig::default());
        assert_eq!((none.unhomed_speed, none.max_deceleration), (0.0, 0.0));
        assert_eq!(none.max_speed, None);
    }

    #[test]
    fn check_says_when_nothing_may_move_for_want_of_a_speed_bound() {
        let immediate = AxisConfig {
            home_sequence: crate::config::HomeSequence::Immediate,
            home_deceleration: 500.0,
            ..AxisConfig::default()
        };
        let said = advisories(&immediate);
        assert!(
            said.iter()
                .any(|a| a.starts_with("max_speed:") && a.contains("EXERR 7")),
            "{said:?}"
        );
        let set = AxisConfig {
            max_speed: 10.0,
            ..immediate
        };
        assert!(!advisories(&set).iter().any(|a| a.starts_with("max_speed:")));
    }
}
