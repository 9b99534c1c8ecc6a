//! The plant's parameters (`[axis.sim]` in the TOML, plus the knobs tests use).
//!
//! The configuration comes from users and from property tests, so nothing in
//! it may make the plant panic or produce a non-finite feedback:
//! [`PlantConfig::sanitized`] maps every malformed value to a harmless one, and
//! [`Plant::new`](crate::Plant::new) only ever runs on sanitized values.

/// Default `push_gain`, % rated torque per unit of command beyond a hard stop.
pub const DEFAULT_PUSH_GAIN: f64 = 100.0;
/// Default `inertia_gain`, % rated per unit/s² of commanded acceleration.
pub const DEFAULT_INERTIA_GAIN: f64 = 0.01;
/// Default `friction`, % rated while moving.
pub const DEFAULT_FRICTION: f64 = 1.0;
/// Default `enable_delay_cycles`.
pub const DEFAULT_ENABLE_DELAY_CYCLES: u32 = 2;

/// A short torque bump at a fixed place of the travel (a tight spot of the
/// mechanics). It exists so that tests can check that the engine's Home Torque
/// Time filter ignores nuisance spikes shorter than the filter time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueSpike {
    /// Raw position where the spike starts, units.
    pub at: f64,
    /// Length of travel over which it lasts, units: the spike is present while
    /// the (end-of-cycle) position is in `[at, at + width]`.
    pub width: f64,
    /// Added torque, % rated, always in the direction of motion (it resists
    /// the motion, so the drive has to push harder).
    pub level: f64,
}

/// Parameters of one simulated axis: drive, mechanics and sensors.
///
/// All positions are raw (the drive's frame), in position units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantConfig {
    /// Raw position at power-up, units.
    pub start: f64,
    /// Raw interval `[lo, hi]` (inclusive) in which the home switch is actuated.
    pub switch: Option<(f64, f64)>,
    /// NC wiring: the electrical input reads closed (`true`) at rest and open
    /// inside the interval. NO (the default) reads closed inside the interval.
    pub switch_normally_closed: bool,
    /// Distance between markers; `0.0` = no markers.
    pub marker_every: f64,
    /// Raw position of one marker: markers are at `marker_at + k * marker_every`
    /// for every integer `k`, negative ones included.
    pub marker_at: f64,
    /// Raw mechanical ends `[lo, hi]`: the position never leaves them, and a
    /// command beyond one makes the drive push (torque rises).
    pub hard_stop: Option<(f64, f64)>,
    /// The overtravel limit switches (`[axis.sim] limit_switches`, formerly
    /// `overtravel`): the negative one actuated at or below `lo`, the
    /// positive one at or above `hi` (until the key's rename the ends
    /// themselves did not trip; now a switch is actuated *at* its end, the
    /// rule of the home switch's interval). An infinite end: no switch on
    /// that side. See [`limits`](crate::limits).
    pub overtravel: Option<(f64, f64)>,
    /// NC wiring of the limit switches (`limit_switches_normally_closed`):
    /// both reading actuated is a wire break, and the drive faults.
    pub limit_switches_normally_closed: bool,
    /// What the drive's registration (probe) input is wired to: the home
    /// switch, or the limit switch an axis homes on.
    pub registration_input: RegistrationInput,
    /// Units/s, signed: something else moves the axis while the drive is not
    /// enabled (passive homing, a hand wheel).
    pub external_speed: f64,
    /// % rated torque per unit of command pushed into a hard stop.
    pub push_gain: f64,
    /// % rated per unit/s² of commanded acceleration in free motion.
    pub inertia_gain: f64,
    /// % rated, in the sense of the velocity, while moving.
    pub friction: f64,
    /// Steps from the enable request (rising edge) to "enabled"; 0 = same step.
    pub enable_delay_cycles: u32,
    /// Optional nuisance spike for testing the torque-time filter.
    pub torque_spike: Option<TorqueSpike>,
}

/// The input the drive's registration latch (`Command::switch_arm`, probe 2
/// on EtherCAT) is wired to. Not a key: the sim wires it to the axis's
/// reference switch, the limit switch in Home Direction for the
/// limit-switch sequences, the home switch otherwise.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RegistrationInput {
    #[default]
    HomeSwitch,
    NegativeLimit,
    PositiveLimit,
}

impl Default for PlantConfig {
    /// At 0, nothing connected (no switch, markers, stops or overtravel),
    /// default gains, a two-cycle enable delay.
    fn default() -> Self {
        Self {
            start: 0.0,
            switch: None,
            switch_normally_closed: false,
            marker_every: 0.0,
            marker_at: 0.0,
            hard_stop: None,
            overtravel: None,
            limit_switches_normally_closed: false,
            registration_input: RegistrationInput::HomeSwitch,
            external_speed: 0.0,
            push_gain: DEFAULT_PUSH_GAIN,
            inertia_gain: DEFAULT_INERTIA_GAIN,
            friction: DEFAULT_FRICTION,
            enable_delay_cycles: DEFAULT_ENABLE_DELAY_CYCLES,
            torque_spike: None,
        }
    }
}

use crate::num::saturate;

/// `x` if finite, else `default`.
fn finite_or(x: f64, default: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        default
    }
}

/// An interval with `lo <= hi`, or `None` if either end is NaN. Infinite ends
/// are kept where they mean "unbounded on that side" (`keep_infinite`).
fn interval(iv: Option<(f64, f64)>, keep_infinite: bool) -> Option<(f64, f64)> {
    let (a, b) = iv?;
    let ok = |x: f64| {
        if keep_infinite {
            !x.is_nan()
        } else {
            x.is_finite()
        }
    };
    if !ok(a) || !ok(b) {
        return None;
    }
    Some(if a <= b { (a, b) } else { (b, a) })
}

impl PlantConfig {
    /// A copy with every malformed value replaced by a harmless one, so that
    /// the plant can neither panic nor produce a non-finite feedback:
    ///
    /// * non-finite `start`, `external_speed` → 0; non-finite gains → their
    ///   defaults;
    /// * intervals given as `(hi, lo)` are swapped; a switch interval with a
    ///   non-finite end, or a stop / overtravel interval with a NaN end, is
    ///   dropped (infinite stop or overtravel ends mean "none on that side";
    ///   stop ends are saturated to ±`f64::MAX`);
    /// * `marker_every` is taken as a magnitude (the marker set is the same);
    ///   non-finite `marker_every` or `marker_at` → no markers; `-0.0` → `0.0`;
    /// * a spike with a non-finite field is dropped;
    /// * `start` is clamped into the hard stops (the axis cannot be beyond them).
    pub fn sanitized(&self) -> Self {
        // Stop ends are saturated to ±f64::MAX: the same for every finite
        // position, but a clamp can then never produce an infinity.
        let hard_stop = interval(self.hard_stop, true).map(|(lo, hi)| (saturate(lo), saturate(hi)));
        let (marker_every, marker_at) = if self.marker_every.is_finite()
            && self.marker_at.is_finite()
            && self.marker_every != 0.0
        {
            (self.marker_every.abs(), self.marker_at + 0.0)
        } else {
            (0.0, finite_or(self.marker_at, 0.0) + 0.0)
        };
        let torque_spike = self
            .torque_spike
            .filter(|s| s.at.is_finite() && s.width.is_finite() && s.level.is_finite());
        let mut start = finite_or(self.start, 0.0);
        if let Some((lo, hi)) = hard_stop {
            start = start.max(lo).min(hi);
        }
        Self {
            start,
            switch: interval(self.switch, false),
            switch_normally_closed: self.switch_normally_closed,
            marker_every,
            marker_at,
            hard_stop,
            overtravel: interval(self.overtravel, true),
            limit_switches_normally_closed: self.limit_switches_normally_closed,
            registration_input: self.registration_input,
            external_speed: finite_or(self.external_speed, 0.0),
            push_gain: finite_or(self.push_gain, DEFAULT_PUSH_GAIN),
            inertia_gain: finite_or(self.inertia_gain, DEFAULT_INERTIA_GAIN),
            friction: finite_or(self.friction, DEFAULT_FRICTION),
            enable_delay_cycles: self.enable_delay_cycles,
            torque_spike,
        }
    }

    /// `x` clamped into the hard stops (unchanged without stops). Never uses
    /// `f64::clamp`, which panics on NaN bounds.
    pub fn clamp_to_stops(&self, x: f64) -> f64 {
        match self.hard_stop {
            Some((lo, hi)) => x.max(lo).min(hi),
            None => x,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_documented_ones() {
        let c = PlantConfig::default();
        assert_eq!(c.start, 0.0);
        assert_eq!(c.switch, None);
        assert_eq!(c.marker_every, 0.0);
        assert_eq!(c.hard_stop, None);
        assert_eq!(c.push_gain, 100.0);
        assert_eq!(c.inertia_gain, 0.01);
        assert_eq!(c.friction, 1.0);
        assert_eq!(c.enable_delay_cycles, 2);
        assert_eq!(c.sanitized(), c);
    }

    #[test]
    fn sanitizing_repairs_malformed_values() {
        let c = PlantConfig {
            start: 500.0,
            switch: Some((5.0, f64::NAN)),
            marker_every: -10.0,
            marker_at: 2.5,
            hard_stop: Some((100.0, -100.0)),
            overtravel: Some((f64::NEG_INFINITY, 90.0)),
            external_speed: f64::INFINITY,
            push_gain: f64::NAN,
            torque_spike: Some(TorqueSpike {
                at: 1.0,
                width: f64::NAN,
                level: 3.0,
            }),
            ..PlantConfig::default()
        }
        .sanitized();
        assert_eq!(c.start, 100.0);
        assert_eq!(c.switch, None);
        assert_eq!(c.marker_every, 10.0);
        assert_eq!(c.hard_stop, Some((-100.0, 100.0)));
        assert_eq!(c.overtravel, Some((f64::NEG_INFINITY, 90.0)));
        let inf = PlantConfig {
            hard_stop: Some((f64::INFINITY, f64::INFINITY)),
            ..PlantConfig::default()
        }
        .sanitized();
        assert_eq!(inf.hard_stop, Some((f64::MAX, f64::MAX)));
        assert_eq!(inf.start, f64::MAX);
        assert_eq!(c.external_speed, 0.0);
        assert_eq!(c.push_gain, DEFAULT_PUSH_GAIN);
        assert_eq!(c.torque_spike, None);

        let c = PlantConfig {
            marker_every: f64::INFINITY,
            marker_at: f64::NAN,
            switch: Some((5.0, 0.0)),
            ..PlantConfig::default()
        }
        .sanitized();
        assert_eq!(c.marker_every, 0.0);
        assert_eq!(c.marker_at, 0.0);
        assert_eq!(c.switch, Some((0.0, 5.0)));
    }
}
