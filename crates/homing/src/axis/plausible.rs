//! Plausible feedback: a forged or corrupt frame never becomes an event.
//!
//! Finite, in-range numbers (checked in `intake`) can still be lies. The axis
//! cannot move faster than `max_speed` (see
//! [`effective_max_speed`](crate::validate::effective_max_speed)), so:
//!
//! * **Jumps.** A position that moved further since the last plausible sample
//!   than `max_speed × elapsed × 1.5 + 2 counts` is refused: the sample is not
//!   used (it counts as missing feedback), HomedStatus is cleared, and homing
//!   aborts with ERR 12 / EXERR 44. The reference stays the last *plausible*
//!   sample, so one forged frame does not make the genuine next one look like
//!   a jump back; `elapsed` runs from that sample, so a gap widens the bound
//!   as it should. The 1.5 and the 2 counts absorb frame-timing jitter and
//!   quantisation. A real jump (an encoder re-referenced by its drive) looks
//!   the same: its samples are refused until the bound has grown past it, and
//!   meanwhile the feedback-loss rule trips; the axis must be homed again.
//! * **Latches.** A latched position must lie on the travel seen since the
//!   latch was armed, give or take one step of travel at `max_speed` (plus 2
//!   counts); one that does not is counted and ignored (see `detect`).
//!
//! Without a `max_speed` (passive or immediate axes that set none) nothing is
//! checked: there is no speed to check against.

use crate::config::AxisConfig;
use crate::validate::effective_max_speed;

#[derive(Clone, Copy, Debug)]
pub(super) struct Plausibility {
    /// Fastest plausible speed, units/s; `None`: no checks.
    max_speed: Option<f64>,
    /// Two counts, in units.
    quantum: f64,
    /// Position and time (ns) of the last plausible sample.
    reference: Option<(f64, u64)>,
}

impl Plausibility {
    pub fn new(cfg: &AxisConfig) -> Self {
        let quantum = if cfg.counts_per_unit.is_finite() && cfg.counts_per_unit > 0.0 {
            2.0 / cfg.counts_per_unit
        } else {
            0.0
        };
        Self {
            max_speed: effective_max_speed(cfg),
            quantum,
            reference: None,
        }
    }

    /// Checks a (finite) position sampled at `now`; a plausible one becomes
    /// the new reference.
    pub fn position(&mut self, p: f64, now: u64) -> bool {
        if let (Some(v), Some((p0, t0))) = (self.max_speed, self.reference) {
            let elapsed = now.saturating_sub(t0) as f64 * 1e-9;
            if (p - p0).abs() > v * elapsed * 1.5 + self.quantum {
                return false;
            }
        }
        self.reference = Some((p, now));
        true
    }

    /// How far a latch may lie outside the travel seen since its arming,
    /// for a sample `dt_ns` after the previous one; `None`: no check.
    pub fn latch_margin(&self, dt_ns: u64) -> Option<f64> {
        self.max_speed
            .map(|v| v * dt_ns as f64 * 1e-9 + self.quantum)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    fn checker(max_speed: f64) -> Plausibility {
        Plausibility::new(&AxisConfig {
            counts_per_unit: 1000.0,
            max_speed,
            ..AxisConfig::default()
        })
    }

    #[test]
    fn bound_is_speed_times_elapsed_times_1_5_plus_2_counts() {
        // 10 u/s, 1 ms: 10 x 0.001 x 1.5 + 2 / 1000 = 0.017.
        let mut c = checker(10.0);
        assert!(c.position(0.0, 0));
        assert!(c.position(0.0169, MS));
        assert!(!c.position(0.0169 + 0.0171, 2 * MS), "0.0171 > 0.017");
        // The refused sample is not the reference: 2 ms after the last
        // plausible one the bound is 0.032.
        assert!(c.position(0.0169 + 0.0171, 3 * MS));
        assert!(!c.position(1.0, 4 * MS));
        assert!(c.position(0.034 + 0.0169, 4 * MS), "back on track");
    }

    #[test]
    fn no_speed_no_check() {
        let mut c = checker(0.0); // immediate, nothing commanded: nothing derived
        assert!(c.position(0.0, 0));
        assert!(c.position(1e6, 1));
        assert_eq!(c.latch_margin(MS), None);
        // One step of travel at 10 u/s plus 2 counts: 0.01 + 0.002.
        let m = checker(10.0).latch_margin(MS).unwrap();
        assert!((m - 0.012).abs() < 1e-12, "{m}");
    }
}
