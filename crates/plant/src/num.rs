//! Numeric helpers that keep every reported value finite and well defined.

use motion_homing::Feedback;

/// The numbers in a plant's feedback: position, velocity, torque and the
/// two latched positions. Each one is finite whatever the input — the
/// plant is total — and the plant's tests check it over this list, so a
/// number added to the feedback is added here, once.
pub fn feedback_numbers(fb: &Feedback) -> [f64; 5] {
    [
        fb.position,
        fb.velocity,
        fb.torque,
        fb.marker_latch.position,
        fb.switch_latch.position,
    ]
}

/// Sign of `x` with `sign(0) = 0` (and `sign(NaN) = 0`). `f64::signum(0.0)` is
/// `1.0`, which would make a standing axis feel friction.
pub(crate) fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// `x` made finite: NaN → 0, ±∞ → ±`f64::MAX`. Applied to every computed
/// feedback value, so huge (finite) commands give saturated but finite numbers.
pub(crate) fn saturate(x: f64) -> f64 {
    if x.is_nan() {
        0.0
    } else {
        // Constant, ordered bounds: this clamp cannot panic.
        x.clamp(-f64::MAX, f64::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_of_zero_is_zero() {
        assert_eq!(sign(0.0), 0.0);
        assert_eq!(sign(-0.0), 0.0);
        assert_eq!(sign(3.0), 1.0);
        assert_eq!(sign(-3.0), -1.0);
        assert_eq!(sign(f64::NAN), 0.0);
    }

    #[test]
    fn saturate_makes_finite() {
        assert_eq!(saturate(f64::NAN), 0.0);
        assert_eq!(saturate(f64::INFINITY), f64::MAX);
        assert_eq!(saturate(f64::NEG_INFINITY), -f64::MAX);
        assert_eq!(saturate(-2.5), -2.5);
    }
}
