//! The feedback-loss rule: a leaky bucket of missing-feedback time.
//!
//! Counting consecutive missing cycles would mean something different at 1
//! and at 8 kHz, would forgive a peer that drops every other frame forever,
//! and would trip on one late frame at a high rate. The bucket is stated in
//! time instead:
//!
//! * a step without a fresh valid sample adds the time since the previous
//!   step — at most one nominal cycle (`cycle_ns`): a step that comes late
//!   because the *supervisor* stalled (its thread preempted, the whole VM
//!   descheduled) is one missed answer, not the peer's silence for the
//!   whole stall — so only time in which the peer could have answered and
//!   did not fills the bucket;
//! * a step with one drains `feedback_loss_drain` × that time;
//! * the rule trips when the bucket holds more than `feedback_timeout_ns`;
//! * a missing sample in a step the supervisor itself woke late for
//!   ([`Request::stalled`](crate::Request::stalled): the CPU both processes
//!   share was taken away, by the hypervisor, an SMI, a higher-priority
//!   thread) is excused — counted as a gap, not charged — for at most
//!   `feedback_timeout_ns` of such steps per gap. When the CPU comes back
//!   the supervisor, of higher priority, runs before the I/O process can
//!   answer, so a stalled machine would otherwise look like a silent peer;
//!   the bound keeps a dead peer on a permanently overloaded machine caught
//!   within twice the timeout.
//!
//! So a dead peer trips within the timeout plus one cycle, an isolated gap
//! shorter than the timeout never trips, and sustained loss of more than
//! `drain / (1 + drain)` of the cycles (20 % at 0.25) trips eventually.
//!
//! Once tripped the loss has been reported; the first fresh sample after it
//! starts a new connection with an empty bucket.
//!
//! The supervisor's I/O links judge their processes' answers with this same
//! bucket (attached / detached), so the rule has one implementation.

use crate::time::{f64_as_ns, ns_as_f64};

/// Bucket state. Times in ns.
#[derive(Clone, Copy, Debug, Default)]
pub struct FeedbackLoss {
    /// Missing time not yet drained.
    bucket: u64,
    /// Time of the previous step, once there was one.
    prev_step: Option<u64>,
    /// Time of the last step with a fresh valid sample (or of the first step,
    /// before any): where the current gap began.
    gap_since: Option<u64>,
    /// Missing time excused in this gap (stalled steps), ns.
    excused: u64,
    /// Tripped, and no fresh sample since.
    tripped: bool,
    /// The last drain worked out, `(dt, drain's bits, ns drained)`: nearly
    /// every step drains one nominal cycle at the same rate, and the float
    /// arithmetic of a drain costs more than the rest of the bucket.
    drained: (u64, u64, u64),
}

impl FeedbackLoss {
    /// Start of a step at `now`: the time elapsed since the previous step,
    /// at most `cycle_ns` (when non-zero).
    pub fn tick(&mut self, now: u64, cycle_ns: u64) -> u64 {
        let mut dt = self.prev_step.map_or(0, |t| now.saturating_sub(t));
        if cycle_ns > 0 {
            dt = dt.min(cycle_ns);
        }
        self.prev_step = Some(now);
        self.gap_since.get_or_insert(now);
        dt
    }

    /// This step had a fresh valid sample.
    pub fn fresh(&mut self, now: u64, dt: u64, drain: f64) {
        if self.tripped {
            self.tripped = false;
            self.bucket = 0;
        } else {
            let d = match self.drained {
                (t, bits, d) if t == dt && bits == drain.to_bits() => d,
                _ => {
                    // Saturating float → integer cast: a huge drain empties the bucket.
                    let d = f64_as_ns(drain.max(0.0) * ns_as_f64(dt));
                    self.drained = (dt, drain.to_bits(), d);
                    d
                }
            };
            self.bucket = self.bucket.saturating_sub(d);
        }
        self.gap_since = Some(now);
        self.excused = 0;
    }

    /// This step had no usable sample; `stalled`: the supervisor woke late
    /// for it. True when the rule trips now (once per loss).
    pub fn missing(&mut self, dt: u64, timeout_ns: u64, stalled: bool) -> bool {
        if stalled && self.excused.saturating_add(dt) <= timeout_ns {
            self.excused += dt;
            return false;
        }
        self.bucket = self.bucket.saturating_add(dt);
        if self.bucket > timeout_ns && !self.tripped {
            self.tripped = true;
            return true;
        }
        false
    }

    /// A new connection at `now` (a peer attached or restarted): empty
    /// bucket, no gap, nothing tripped.
    pub fn connected(&mut self, now: u64) {
        self.bucket = 0;
        self.excused = 0;
        self.tripped = false;
        self.gap_since = Some(now);
    }

    /// Length of the current gap at `now` (0 right after a fresh sample).
    pub fn gap(&self, now: u64) -> u64 {
        self.gap_since.map_or(0, |t| now.saturating_sub(t))
    }

    pub fn bucket(&self) -> u64 {
        self.bucket
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    /// Steps at 1 ms; `pattern(k)` says whether step k had fresh feedback.
    /// Returns the step at which the rule tripped first.
    fn trips_at(pattern: impl Fn(u64) -> bool, steps: u64) -> Option<u64> {
        let mut l = FeedbackLoss::default();
        for k in 0..steps {
            let dt = l.tick(k * MS, MS);
            if pattern(k) {
                l.fresh(k * MS, dt, 0.25);
            } else if l.missing(dt, 10 * MS, false) {
                return Some(k);
            }
        }
        None
    }

    #[test]
    fn a_stall_of_the_supervisor_is_one_missed_answer() {
        // Steps at 1 ms, then the supervisor itself stalls 30 ms: its next
        // step (no fresh sample yet) adds one cycle, not 30 ms.
        let mut l = FeedbackLoss::default();
        for k in 0..10 {
            let dt = l.tick(k * MS, MS);
            l.fresh(k * MS, dt, 0.25);
        }
        let dt = l.tick(40 * MS, MS);
        assert_eq!(dt, MS);
        assert!(!l.missing(dt, 10 * MS, false));
        assert_eq!(l.bucket(), MS);
        // Without a nominal cycle the whole stall counts (and trips).
        let mut l = FeedbackLoss::default();
        l.tick(0, 0);
        let dt = l.tick(30 * MS, 0);
        assert!(l.missing(dt, 10 * MS, false));
    }

    #[test]
    fn dead_peer_trips_after_timeout_plus_one_cycle() {
        // Last fresh at 99; missing from 100: 10 ms at 109 (not above), 11 ms at 110.
        assert_eq!(trips_at(|k| k < 100, 1000), Some(110));
    }

    #[test]
    fn isolated_gap_below_the_timeout_never_trips() {
        // 10 missing steps = exactly 10 ms: not above the timeout.
        assert_eq!(trips_at(|k| !(100..110).contains(&k), 10_000), None);
        // Such gaps every 50 ms: 10 ms in, 40 x 0.25 = 10 ms out.
        assert_eq!(trips_at(|k| k % 50 >= 10, 10_000), None);
    }

    #[test]
    fn half_loss_trips_tenth_and_fifth_do_not() {
        // Odd steps missing: after step 2n+1 the bucket holds 1 + 0.75 n ms,
        // above 10 ms first at n = 13: step 27.
        assert_eq!(trips_at(|k| k % 2 == 0, 10_000), Some(27));
        assert_eq!(trips_at(|k| k % 10 != 9, 100_000), None);
        // 20 %: one missing (+1 ms), four fresh (-4 x 0.25 ms): break-even.
        assert_eq!(trips_at(|k| k % 5 != 4, 100_000), None);
        // 25 %: +1 - 3 x 0.25 = +0.25 ms per 4 steps: 1 + 0.25 n > 10 at n = 37.
        assert_eq!(trips_at(|k| k % 4 != 3, 100_000), Some(3 + 4 * 37));
    }

    #[test]
    fn stalled_steps_are_excused_up_to_the_timeout() {
        // Every other step stalled and missing, the others fresh: with the
        // stalls charged this trips (see above); excused it never does.
        let mut l = FeedbackLoss::default();
        for k in 0..10_000 {
            let dt = l.tick(k * MS, MS);
            if k % 2 == 0 {
                l.fresh(k * MS, dt, 0.25);
            } else {
                assert!(!l.missing(dt, 10 * MS, true), "{k}");
            }
        }
        assert_eq!(l.bucket(), 0);
        // A dead peer on a machine whose every step is late: 10 ms excused,
        // then charged; trips after 21 missing steps.
        let mut l = FeedbackLoss::default();
        let dt = l.tick(0, MS);
        l.fresh(0, dt, 0.25);
        let tripped = (1..100).find(|&k| {
            let dt = l.tick(k * MS, MS);
            l.missing(dt, 10 * MS, true)
        });
        assert_eq!(tripped, Some(21));
        assert_eq!(l.gap(21 * MS), 21 * MS);
    }

    #[test]
    fn a_remembered_drain_is_the_drain() {
        // (0, 0, 0) at first: dt 0 at rate 0 drains 0, as computed.
        let mut l = FeedbackLoss {
            bucket: 10 * MS,
            ..FeedbackLoss::default()
        };
        l.fresh(0, 0, 0.0);
        assert_eq!(l.bucket(), 10 * MS);
        l.bucket = 10 * MS;
        l.fresh(0, MS, 0.25);
        assert_eq!(l.bucket(), 10 * MS - MS / 4);
        l.fresh(0, MS, 0.25);
        assert_eq!(l.bucket(), 10 * MS - MS / 2, "remembered");
        l.fresh(0, MS, 0.5);
        assert_eq!(l.bucket(), 10 * MS - MS, "another rate");
        l.fresh(0, 2 * MS, 0.5);
        assert_eq!(l.bucket(), 8 * MS, "another time");
        l.fresh(0, MS, 1e300);
        assert_eq!(l.bucket(), 0, "a huge drain empties the bucket");
    }

    #[test]
    fn gap_and_reset_after_a_trip() {
        let mut l = FeedbackLoss::default();
        let dt = l.tick(0, MS);
        l.fresh(0, dt, 0.25);
        for k in 1..=11 {
            let dt = l.tick(k * MS, MS);
            assert_eq!(l.missing(dt, 10 * MS, false), k == 11, "{k}");
        }
        assert_eq!(l.gap(11 * MS), 11 * MS);
        assert_eq!(l.bucket(), 11 * MS);
        // Still lost: reported once.
        let dt = l.tick(12 * MS, MS);
        assert!(!l.missing(dt, 10 * MS, false));
        // Back: a new connection, empty bucket, no gap.
        let dt = l.tick(13 * MS, MS);
        l.fresh(13 * MS, dt, 0.25);
        assert_eq!((l.bucket(), l.gap(13 * MS)), (0, 0));
    }
}
