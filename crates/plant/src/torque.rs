//! The torque the drive reports.
//!
//! Deliberately simple and hand-computable, because tests compare with exact
//! values: in free motion it is inertia (from the *commanded* acceleration)
//! plus Coulomb friction; pushing into a hard stop it is a stiff spring on the
//! part of the command the stop refuses, which dominates everything else; the
//! drive's torque limits clip the result. The limits do not slow the motion:
//! the model assumes the drive is strong enough for the commanded profile.

use crate::config::PlantConfig;
use crate::num::{saturate, sign};

/// Inputs of one cycle's torque, all finite.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TorqueInputs {
    /// This cycle's command position.
    pub command: f64,
    /// The position actually reached (command clamped to the hard stops).
    pub position: f64,
    /// Commanded acceleration: second difference of the last three commands / dt².
    pub acceleration: f64,
    /// Actual velocity over the cycle.
    pub velocity: f64,
    /// Torque limits in force, as magnitudes.
    pub limit_positive: f64,
    pub limit_negative: f64,
}

/// Torque of an enabled drive, % rated, signed, within the limits.
pub(crate) fn torque(cfg: &PlantConfig, t: &TorqueInputs) -> f64 {
    let raw = if t.position != t.command {
        // Command beyond a hard stop: the drive pushes with a torque
        // proportional to how far the command is beyond the stop.
        cfg.push_gain * (t.command - t.position)
    } else {
        cfg.inertia_gain * t.acceleration + cfg.friction * sign(t.velocity)
    };
    let spike = match cfg.torque_spike {
        Some(s) if s.at <= t.position && t.position <= s.at + s.width => s.level * sign(t.velocity),
        _ => 0.0,
    };
    // Limits are magnitudes; a negative (malformed) one counts as zero.
    let hi = t.limit_positive.max(0.0);
    let lo = -t.limit_negative.max(0.0);
    saturate(saturate(saturate(raw) + spike).min(hi).max(lo))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TorqueSpike;

    fn inputs(command: f64, position: f64, acceleration: f64, velocity: f64) -> TorqueInputs {
        TorqueInputs {
            command,
            position,
            acceleration,
            velocity,
            limit_positive: 50.0,
            limit_negative: 20.0,
        }
    }

    #[test]
    fn free_motion_is_inertia_plus_friction() {
        let cfg = PlantConfig {
            inertia_gain: 0.5,
            friction: 2.0,
            ..PlantConfig::default()
        };
        assert_eq!(torque(&cfg, &inputs(1.0, 1.0, 4.0, 1.0)), 4.0);
        assert_eq!(torque(&cfg, &inputs(1.0, 1.0, 4.0, -1.0)), 0.0);
        assert_eq!(torque(&cfg, &inputs(1.0, 1.0, 0.0, 0.0)), 0.0);
        assert_eq!(torque(&cfg, &inputs(1.0, 1.0, -8.0, -3.0)), -6.0);
    }

    #[test]
    fn push_dominates_and_is_limited() {
        let cfg = PlantConfig::default();
        assert_eq!(torque(&cfg, &inputs(10.125, 10.0, 1e6, 0.0)), 12.5);
        assert_eq!(torque(&cfg, &inputs(11.0, 10.0, 0.0, 0.0)), 50.0);
        assert_eq!(torque(&cfg, &inputs(-10.125, -10.0, 0.0, 0.0)), -12.5);
        assert_eq!(torque(&cfg, &inputs(-11.0, -10.0, 0.0, 0.0)), -20.0);
    }

    #[test]
    fn spike_adds_in_direction_of_motion() {
        let cfg = PlantConfig {
            friction: 1.0,
            inertia_gain: 0.0,
            torque_spike: Some(TorqueSpike {
                at: 5.0,
                width: 1.0,
                level: 30.0,
            }),
            ..PlantConfig::default()
        };
        assert_eq!(torque(&cfg, &inputs(4.5, 4.5, 0.0, 1.0)), 1.0);
        assert_eq!(torque(&cfg, &inputs(5.0, 5.0, 0.0, 1.0)), 31.0);
        assert_eq!(torque(&cfg, &inputs(6.0, 6.0, 0.0, 1.0)), 31.0);
        assert_eq!(torque(&cfg, &inputs(5.5, 5.5, 0.0, -1.0)), -20.0, "limited");
        assert_eq!(torque(&cfg, &inputs(5.5, 5.5, 0.0, 0.0)), 0.0, "standing");
    }

    #[test]
    fn overflow_saturates() {
        let cfg = PlantConfig::default();
        let mut t = inputs(f64::MAX, -f64::MAX, f64::INFINITY, 1.0);
        t.limit_positive = f64::INFINITY;
        assert_eq!(torque(&cfg, &t), f64::MAX);
    }
}
