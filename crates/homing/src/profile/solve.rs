//! The one root finder the S-curve planners use, bounded for the cycle.
//!
//! The planners' unknowns (a move's peak speed, a timed move's cruise
//! speed, a stop's deceleration) enter their equations through square
//! roots and saturations, so they are found numerically: the Illinois
//! variant of regula falsi, which keeps a bracket (never leaves it, never
//! divides by zero) and converges superlinearly on these smooth, monotone
//! functions. It stops at adjacent floats, an exact zero, or after
//! [`MAX_EVALUATIONS`]: planning is bounded in time like the rest of the
//! step.

/// Evaluations at most: 64 would bisect any bracket of floats to its end.
pub(super) const MAX_EVALUATIONS: usize = 64;

/// Narrows a bracket around a sign change of `f`: `good` with
/// `f(good) <= 0` and `bad` with `f(bad) > 0` (in either order on the
/// axis). Returns the final `(good, bad)`: the caller takes the side it
/// needs (a planner takes `good`, the side its constraint holds on).
pub(super) fn bracket(
    f: impl Fn(f64) -> f64,
    mut good: f64,
    mut f_good: f64,
    mut bad: f64,
    mut f_bad: f64,
) -> (f64, f64) {
    // Which end moved last: the Illinois step halves the other end's value
    // when the same end moves twice, so the bracket closes from both sides;
    // after three moves of the same end (a kink, not a smooth curve) the
    // next step bisects.
    let mut last = 0i8;
    let mut streak = 0;
    for _ in 0..MAX_EVALUATIONS {
        let (lo, hi) = if good < bad { (good, bad) } else { (bad, good) };
        let mut x = (good * f_bad - bad * f_good) / (f_bad - f_good);
        if streak >= 3 || !(x > lo && x < hi) {
            x = lo + 0.5 * (hi - lo);
        }
        if !(x > lo && x < hi) {
            break; // adjacent floats
        }
        let fx = f(x);
        if fx.is_nan() {
            break;
        }
        let moved = if fx <= 0.0 { 1 } else { -1 };
        streak = if moved == last { streak + 1 } else { 1 };
        if fx <= 0.0 {
            good = x;
            f_good = fx;
            if last == 1 {
                f_bad *= 0.5;
            }
            last = 1;
            if fx == 0.0 {
                break;
            }
        } else {
            bad = x;
            f_bad = fx;
            if last == -1 {
                f_good *= 0.5;
            }
            last = -1;
        }
    }
    (good, bad)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn converges_to_adjacent_floats_from_either_side() {
        let n = Cell::new(0);
        let f = |x: f64| {
            n.set(n.get() + 1);
            x * x * x - 2.0
        };
        let (g, b) = bracket(f, 0.0, -2.0, 2.0, 6.0);
        let root = 2f64.cbrt();
        assert!(g <= root && f(g) <= 0.0 && f(b) > 0.0);
        assert!((g - root).abs() <= 4.0 * f64::EPSILON, "{g} {root}");
        assert!(n.get() < 30, "{} evaluations", n.get());
        // Decreasing: good above the root.
        let (g, _) = bracket(|x| 1.0 - x, 2.0, -1.0, 0.0, 1.0);
        assert!(g >= 1.0 && g - 1.0 <= 4.0 * f64::EPSILON);
    }

    #[test]
    fn a_kinked_or_nan_function_stays_bounded() {
        let n = Cell::new(0);
        let f = |x: f64| {
            n.set(n.get() + 1);
            if x < 0.3 {
                -1.0
            } else {
                1e9
            }
        };
        let (g, b) = bracket(f, 0.0, -1.0, 1.0, 1e9);
        assert!(g < 0.3 && b >= 0.3 && b - g < 1e-4, "{g} {b}");
        assert!(n.get() <= MAX_EVALUATIONS + 2);
        let (g, _) = bracket(|_| f64::NAN, 0.0, -1.0, 1.0, 1.0);
        assert_eq!(g, 0.0);
    }
}
