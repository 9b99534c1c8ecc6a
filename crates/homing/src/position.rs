//! Raw ↔ axis position and the choice of a Home Position target on a cyclic
//! axis. Raw positions never wrap; only the axis position of a cyclic axis
//! wraps into `[0, unwind)`.

/// Wraps `x` into `[0, unwind)`. A result that rounds to `unwind` is 0, so a
/// value that is a whole number of revolutions reads exactly 0.
pub fn wrap(x: f64, unwind: f64) -> f64 {
    let r = x.rem_euclid(unwind);
    if unwind - r <= unwind * 1e-12 {
        0.0
    } else {
        r
    }
}

/// `base + k * unwind` closest to `around`: the shortest way (at most half a
/// revolution) for a bidirectional move on a cyclic axis.
pub fn nearest_cyclic(base: f64, around: f64, unwind: f64) -> f64 {
    let k = ((around - base) / unwind).round();
    base + k * unwind
}

/// The first `base + k * unwind` (any integer k) that lies at least `min_dist`
/// ahead of `from` in direction `dir` (±1): whole revolutions added (or
/// removed) so that a unidirectional move reaches it without reversing.
pub fn ahead_cyclic(base: f64, from: f64, dir: f64, min_dist: f64, unwind: f64) -> f64 {
    // Want (base + k*u - from) * dir >= min_dist, smallest such k*dir.
    let need = (min_dist - (base - from) * dir) / unwind;
    let k = need.ceil();
    let mut t = base + dir * k * unwind;
    // Guard the rounding at the boundary: never return a target short of min_dist.
    if (t - from) * dir < min_dist {
        t += dir * unwind;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_is_in_range() {
        assert_eq!(wrap(370.0, 360.0), 10.0);
        assert_eq!(wrap(-10.0, 360.0), 350.0);
        assert_eq!(wrap(720.0, 360.0), 0.0);
        assert_eq!(wrap(-1e-15, 360.0), 0.0);
    }

    #[test]
    fn nearest_is_within_half_a_revolution() {
        assert_eq!(nearest_cyclic(10.0, 355.0, 360.0), 370.0);
        assert_eq!(nearest_cyclic(10.0, -170.0, 360.0), -350.0);
    }

    #[test]
    fn ahead_adds_and_removes_revolutions() {
        // Event at 100 (+offset 0), axis already at 101 moving forward: next 460.
        assert_eq!(ahead_cyclic(100.0, 101.0, 1.0, 0.5, 360.0), 460.0);
        // Far ahead target comes back to within one revolution.
        assert_eq!(ahead_cyclic(100.0 + 720.0, 101.0, 1.0, 0.5, 360.0), 460.0);
        // Reverse.
        assert_eq!(ahead_cyclic(100.0, 99.0, -1.0, 0.5, 360.0), -260.0);
        // Exactly reachable.
        assert_eq!(ahead_cyclic(110.0, 100.0, 1.0, 10.0, 360.0), 110.0);
    }
}
