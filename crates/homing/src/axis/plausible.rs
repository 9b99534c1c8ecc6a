//! Plausible feedback: a forged or corrupt frame never becomes an event.
//!
//! Finite, in-range numbers (checked in `intake`) can still be lies. The axis
//! cannot move faster than `max_speed` (see
//! [`effective_max_speed`](crate::validate::effective_max_speed)), so:
//!
//! * **Jumps.** A position further than `max_speed × elapsed × 1.5 + 2 counts`
//!   from where the axis can be is refused: the sample is not used (it counts
//!   as missing feedback), HomedStatus is cleared, and homing aborts with ERR
//!   12 / EXERR 44. *Where the axis can be* is the last plausible sample and,
//!   for an axis that follows its command, every position commanded since:
//!   feedback answers an earlier command with a lag that varies (a starved
//!   I/O process catches up by several cycles in one, a stalled cycle makes
//!   the command itself jump), so the pure sample-to-sample bound would
//!   refuse genuine frames — it did, in the end-to-end runs. A frame that
//!   claims a place the axis was neither seen at nor sent to is still
//!   refused. `elapsed` runs from the last plausible sample, so a gap widens
//!   the bound as it should, and one forged frame does not make the genuine
//!   next one look like a jump back. The 1.5 and the 2 counts absorb timing
//!   jitter and quantisation. A real jump (an encoder re-referenced by its
//!   drive) looks the same: its samples are refused until the bound has
//!   grown past it, and meanwhile the feedback-loss rule trips; the axis must
//!   be homed again.
//! * **Latches.** A latched position must lie on the travel seen since the
//!   latch was armed, give or take one step of travel at `max_speed` (plus 2
//!   counts); one that does not is counted and ignored (see `detect`).
//!
//! Without a `max_speed` (passive or immediate axes that set none) nothing is
//! checked: there is no speed to check against.

use crate::config::AxisConfig;
use crate::time::ns_to_s;
use crate::validate::effective_max_speed;

#[derive(Clone, Copy, Debug)]
pub(super) struct Plausibility {
    /// Fastest plausible speed, units/s; `None`: no checks.
    max_speed: Option<f64>,
    /// Two counts, in units.
    quantum: f64,
    /// Time (ns) of the last plausible sample.
    since: Option<u64>,
    /// Where the axis can have been since then: the last plausible sample's
    /// position and every command sent from the one before it on.
    span: Option<(f64, f64)>,
    /// The last command sent.
    last_command: Option<f64>,
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
            since: None,
            span: None,
            last_command: None,
        }
    }

    /// Checks a (finite) position sampled at `now`; a plausible one starts
    /// the span anew.
    pub fn position(&mut self, p: f64, now: u64) -> bool {
        if let (Some(v), Some(t0), Some((lo, hi))) = (self.max_speed, self.since, self.span) {
            let elapsed = ns_to_s(now.saturating_sub(t0));
            let bound = v * elapsed * 1.5 + self.quantum;
            if p < lo - bound || p > hi + bound {
                return false;
            }
        }
        self.since = Some(now);
        let c = self.last_command.unwrap_or(p);
        self.span = Some(if p <= c { (p, c) } else { (c, p) });
        true
    }

    /// A command was sent: the axis may go there. (Compared, not
    /// `f64::min`/`max`: commands are finite, and this runs every step.)
    pub fn commanded(&mut self, c: f64) {
        self.last_command = Some(c);
        if let Some((lo, hi)) = &mut self.span {
            if c < *lo {
                *lo = c;
            }
            if c > *hi {
                *hi = c;
            }
        }
    }

    /// How far a latch may lie outside the travel seen since its arming,
    /// for a sample `dt_ns` after the previous one; `None`: no check.
    pub fn latch_margin(&self, dt_ns: u64) -> Option<f64> {
        self.max_speed.map(|v| v * ns_to_s(dt_ns) + self.quantum)
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
    fn commanded_positions_are_plausible_whatever_the_lag() {
        // Feedback lagging 9 cycles behind a 90 u/s command, then catching up
        // in one: 0.81 in 1 ms, far beyond 180 x 0.001 x 1.5 + 0.002 = 0.272,
        // but the command went there.
        let mut c = checker(180.0);
        c.commanded(0.0);
        assert!(c.position(0.0, 0));
        for k in 1..=9 {
            c.commanded(0.09 * f64::from(k));
        }
        assert!(c.position(0.81, MS));
        // A place neither seen nor commanded is refused.
        c.commanded(0.9);
        assert!(!c.position(5.0, 2 * MS));
        // The span starts anew from each plausible sample (here 0.9, also the
        // last command): 0.3 further in 1 ms is above 0.272.
        assert!(c.position(0.9, 3 * MS));
        assert!(!c.position(1.2, 4 * MS));
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
