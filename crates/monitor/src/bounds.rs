//! What the configuration allows an axis, resolved once when the monitor
//! is built: the speed caps, the accelerations, the soft limits.
//!
//! Each key's "not set" (`0`) means what the configuration says it means
//! (`motion_homing::OpLimits`, `effective_max_speed`: the keys' meaning,
//! stated once for every reader) — the monitor shares the configuration's
//! meaning with the engine, never its planning.

use motion_homing::{effective_max_speed, AxisConfig, AxisConfiguration, OpLimits, TravelMode};

/// What the power stage of the axis is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A drive that follows the command while its power stage is on.
    Servo,
    /// No hardware: the command is the position, always "following".
    Virtual,
    /// Nothing is commanded.
    FeedbackOnly,
}

/// The configuration's bounds, in units, units/s and units/s².
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bounds {
    pub kind: Kind,
    /// `max_speed` or the one the homing speeds derive; infinite when none
    /// (an operation is then bounded by its own speed only).
    pub max_speed: f64,
    /// The cap of everything but homing while not homed.
    pub unhomed_speed: f64,
    /// Logix "Maximum Deceleration": the least a stop may use.
    pub max_deceleration: f64,
    pub stream_acceleration: f64,
    /// A program that stops sending may go on for this long after its
    /// last setpoint arrived, ns.
    pub stream_timeout_ns: u64,
    /// The fastest speed the homing sequence commands (Home Speed, Home
    /// Return Speed, the creep speed).
    pub home_speed: f64,
    pub home_acceleration: f64,
    pub home_deceleration: f64,
    /// The soft limits (axis coordinates), on a linear axis that has them.
    pub limits: Option<(f64, f64)>,
    /// Positions closer than this are the same to the drive (half a count).
    pub half_count: f64,
}

/// `x` if it is a positive finite number, else 0.
fn positive(x: f64) -> f64 {
    if x.is_finite() && x > 0.0 {
        x
    } else {
        0.0
    }
}

impl Bounds {
    pub fn new(cfg: &AxisConfig) -> Self {
        let l = OpLimits::new(cfg);
        let limits = match (cfg.travel, cfg.travel_limits) {
            (TravelMode::Linear, Some((lo, hi)))
                if lo.is_finite() && hi.is_finite() && lo <= hi =>
            {
                Some((lo, hi))
            }
            _ => None,
        };
        let cpu = cfg.counts_per_unit;
        Self {
            kind: match cfg.configuration {
                AxisConfiguration::Servo => Kind::Servo,
                AxisConfiguration::Virtual => Kind::Virtual,
                AxisConfiguration::FeedbackOnly => Kind::FeedbackOnly,
            },
            max_speed: effective_max_speed(cfg).map_or(f64::INFINITY, positive),
            unhomed_speed: positive(l.unhomed_speed),
            max_deceleration: positive(l.max_deceleration),
            stream_acceleration: positive(l.stream_acceleration),
            stream_timeout_ns: l.stream_timeout_ns,
            home_speed: positive(cfg.home_speed)
                .max(positive(cfg.home_return_speed))
                .max(positive(cfg.home_creep_speed)),
            home_acceleration: positive(cfg.home_acceleration),
            home_deceleration: positive(cfg.home_deceleration),
            limits,
            half_count: if cpu.is_finite() && cpu > 0.0 {
                0.5 / cpu
            } else {
                0.0
            },
        }
    }

    /// The speed cap of jogs, moves and streams: `max_speed`, and
    /// `unhomed_speed` as well while not homed.
    pub fn speed_cap(&self, homed: bool) -> f64 {
        if homed {
            self.max_speed
        } else {
            self.max_speed.min(self.unhomed_speed)
        }
    }
}
