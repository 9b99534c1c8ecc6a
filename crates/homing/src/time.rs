//! Nanoseconds ↔ seconds, the way the step needs them: exact, and cheap.
//!
//! A step converts times a handful of times (profile samples, the
//! plausibility bound, the feedback-loss drain). On x86-64 an `u64` ↔ `f64`
//! conversion is a dozen instructions (there is no unsigned convert before
//! AVX-512) where an `i64` one is a single instruction; every span the
//! engine sees fits an `i64` (292 years), so the conversions go through
//! `i64` and fall back to the `u64` one above it — the same value either way.

/// `ns` in seconds: `ns as f64 * 1e-9`, bit for bit.
#[inline]
pub fn ns_to_s(ns: u64) -> f64 {
    ns_as_f64(ns) * 1e-9
}

/// `ns as f64`, bit for bit.
#[inline]
pub fn ns_as_f64(ns: u64) -> f64 {
    if ns <= i64::MAX as u64 {
        ns as i64 as f64
    } else {
        ns as f64
    }
}

/// `x as u64` (truncating, saturating, NaN → 0), bit for bit.
#[inline]
pub fn f64_as_ns(x: f64) -> u64 {
    // 2^63: below it (and at or above 0) the `i64` conversion is exact.
    if (0.0..9_223_372_036_854_775_808.0).contains(&x) {
        // SAFETY: `x` is finite and its integer part fits an `i64` (checked
        // just above), which is all `to_int_unchecked` asks; it spares the
        // saturation `as` adds around the one conversion instruction.
        unsafe { x.to_int_unchecked::<i64>() as u64 }
    } else {
        x as u64
    }
}

/// Seconds as whole ns; 0 for a time that is not finite or not positive.
pub fn secs_to_ns(s: f64) -> u64 {
    if s.is_finite() && s > 0.0 {
        (s * 1e9).min(u64::MAX as f64) as u64
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_conversions_give_the_plain_casts_values() {
        for ns in [
            0u64,
            1,
            999_999_999,
            (1 << 53) + 1,
            i64::MAX as u64,
            i64::MAX as u64 + 1,
            u64::MAX - 1,
            u64::MAX,
        ] {
            assert_eq!(ns_as_f64(ns).to_bits(), (ns as f64).to_bits(), "{ns}");
            assert_eq!(ns_to_s(ns).to_bits(), (ns as f64 * 1e-9).to_bits(), "{ns}");
        }
        for x in [
            0.0,
            -0.0,
            0.7,
            -1.5,
            1e9,
            9.2e18,
            9_223_372_036_854_775_808.0,
            1.8e19,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ] {
            assert_eq!(f64_as_ns(x), x as u64, "{x}");
        }
        assert_eq!(secs_to_ns(0.02), 20_000_000);
        assert_eq!(secs_to_ns(f64::INFINITY), 0);
        assert_eq!(secs_to_ns(-1.0), 0);
    }
}
