//! Drift: a home event that lands further than `drift_limit` from where the
//! same axis's recent events landed. A worn or loose home switch, a slipping
//! coupling or a marker taken one revolution off all show up here long
//! before parts come out wrong — and no single homing can see it, because
//! each homing only knows its own event.
//!
//! The comparison is with the median of the recent events (not the last
//! one), so one bad homing neither hides a drift nor raises a warning on the
//! next good one.

/// Recent values of one quantity of one axis (event position in the prior
/// reference, or switch-to-marker distance), oldest first.
#[derive(Clone, Debug, Default)]
pub struct DriftHistory {
    values: Vec<f64>,
}

/// A value outside the limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drift {
    pub value: f64,
    pub median: f64,
    /// `value - median`.
    pub deviation: f64,
    /// Events the median was taken over.
    pub over: usize,
}

/// How many recent events the median is taken over.
pub const RECENT: usize = 5;

impl DriftHistory {
    pub fn from_values(values: impl IntoIterator<Item = f64>) -> Self {
        let mut h = Self::default();
        for v in values {
            h.push(v);
        }
        h
    }

    /// Learns a value of a successful homing (non-finite values ignored).
    pub fn push(&mut self, v: f64) {
        if v.is_finite() {
            self.values.push(v);
            if self.values.len() > RECENT {
                self.values.remove(0);
            }
        }
    }

    pub fn median(&self) -> Option<f64> {
        if self.values.is_empty() {
            return None;
        }
        let mut v = self.values.clone();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        Some(if n % 2 == 1 {
            v[n / 2]
        } else {
            (v[n / 2 - 1] + v[n / 2]) / 2.0
        })
    }

    /// `Some` when `value` lies further than `limit` (> 0) from the median
    /// of the recent values; `None` without a limit or without history.
    pub fn check(&self, value: f64, limit: f64) -> Option<Drift> {
        if limit.is_nan() || limit <= 0.0 || !value.is_finite() {
            return None;
        }
        let median = self.median()?;
        let deviation = value - median;
        (deviation.abs() > limit).then_some(Drift {
            value,
            median,
            deviation,
            over: self.values.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warns_beyond_the_limit_from_the_median() {
        // Events 10.000, 10.002, 9.999, 10.001: median 10.0005.
        let h = DriftHistory::from_values([10.000, 10.002, 9.999, 10.001]);
        assert!((h.median().unwrap() - 10.0005).abs() < 1e-12);
        // 10.05 is 0.0495 off: within 0.1, beyond 0.02.
        assert_eq!(h.check(10.05, 0.1), None);
        let d = h.check(10.05, 0.02).unwrap();
        assert!((d.deviation - 0.0495).abs() < 1e-12);
        assert_eq!(d.over, 4);
        // No limit, no history: nothing to say.
        assert_eq!(h.check(99.0, 0.0), None);
        assert_eq!(DriftHistory::default().check(99.0, 0.1), None);
    }

    #[test]
    fn one_outlier_does_not_move_the_median() {
        // A coupling slipped once (12.0) and was repaired: the next normal
        // event is not reported as drift.
        let h = DriftHistory::from_values([10.0, 10.0, 12.0, 10.0, 10.0]);
        assert_eq!(h.check(10.001, 0.01), None);
        assert!(h.check(12.0, 0.01).is_some());
    }

    #[test]
    fn keeps_only_the_recent_values() {
        let mut h = DriftHistory::default();
        for k in 0..10 {
            h.push(f64::from(k));
        }
        h.push(f64::NAN);
        // 5, 6, 7, 8, 9.
        assert_eq!(h.median(), Some(7.0));
    }
}
