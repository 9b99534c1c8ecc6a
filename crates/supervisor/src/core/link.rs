//! One I/O process as the cycle sees it: which frames are accepted, whether
//! it is attached, the gaps in its answers, and its round trip.
//!
//! # Which answers count
//!
//! A feedback frame is used only if it has this process's axis count and
//! answers one of the commands of the last `window` cycles (`window` = the
//! feedback time bound in cycles). An answer to an older command is old
//! data (a lagging process, or `motion-io`'s watchdog frames, which answer
//! none) and counts as missing; an answer to a command never sent
//! (`answers_sequence` beyond the last one — `u64::MAX` from a forger) is
//! refused. The session key was checked by the ports already.
//!
//! # Attached
//!
//! The process is attached while its answers satisfy the leaky-bucket rule
//! the engines apply to their feedback — the same type,
//! `motion_homing::FeedbackLoss`: missing time fills the bucket,
//! fresh answers drain it, and past the time bound the process is detached
//! (the engines abort homing on its axes by the same rule, independently),
//! including its excuse for steps the supervisor woke late for.
//! When answers come back — or frames of a new *origin* arrive, i.e. the
//! process was restarted — it (re)attaches, and its axes are told they were
//! reconnected: HomedStatus cleared, as the CIP rules ask.

use motion_frames::FeedbackFrame;
use motion_homing::FeedbackLoss;
use motion_report::GapCounts;

use crate::shared::IoSnap;
use motion_status::IoCounters;

/// Send times kept for the round trip (cycles).
const SENT_RING: usize = 32;

#[derive(Clone, Debug)]
pub struct IoLink {
    /// Axis indices in frame order.
    pub axes: Vec<usize>,
    attached: bool,
    ever_attached: bool,
    /// Origin (incarnation) of the peer whose frames are accepted.
    origin: u64,
    /// Sequence of the last command published (0: none yet).
    last_sent: u64,
    /// Send time per sequence (ring).
    sent_ns: [u64; SENT_RING],
    window: u64,
    /// Nominal cycle: a late step counts one cycle toward the bucket.
    cycle_ns: u64,
    /// The engines' feedback-loss bucket (`motion_homing::FeedbackLoss`),
    /// judging this process's answers.
    loss: FeedbackLoss,
    limit_ns: u64,
    drain: f64,
    gap: u64,
    counts: IoCounters,
}

/// What one cycle's frame of a link amounts to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkCycle {
    /// The frame is used as feedback this cycle.
    pub fresh: bool,
    /// The process (re)attached in this cycle (or restarted): its axes
    /// must be told.
    pub reconnected: bool,
    /// It is a new process (another origin than before): its drives were
    /// off or stopped by its watchdog in between.
    pub restarted: bool,
    /// It answered the previous command (else: a late reply).
    pub answered_previous: bool,
    /// Command published → answer published, ns (when it answered a command
    /// whose send time is known).
    pub roundtrip_ns: Option<u64>,
}

impl IoLink {
    pub fn new(axes: Vec<usize>, limit_ns: u64, drain: f64, cycle_ns: u64) -> Self {
        let window = limit_ns.div_ceil(cycle_ns.max(1)).max(1);
        Self {
            axes,
            attached: false,
            ever_attached: false,
            origin: 0,
            last_sent: 0,
            sent_ns: [0; SENT_RING],
            window,
            cycle_ns: cycle_ns.max(1),
            loss: FeedbackLoss::default(),
            limit_ns,
            drain: if drain.is_finite() {
                drain.clamp(0.0, 1.0)
            } else {
                0.25
            },
            gap: 0,
            counts: IoCounters::default(),
        }
    }

    pub fn attached(&self) -> bool {
        self.attached
    }

    /// A command frame with `sequence` was published at `now_ns`.
    pub fn sent(&mut self, sequence: u64, now_ns: u64) {
        self.last_sent = sequence;
        self.sent_ns[(sequence % SENT_RING as u64) as usize] = now_ns;
    }

    /// A received frame the ports refused (layout, key).
    pub fn refused(&mut self) {
        self.counts.frames_refused += 1;
    }

    /// One cycle: `frame` is the newest frame received this cycle, if any;
    /// `stalled`: the supervisor woke late for it.
    pub fn step(&mut self, now_ns: u64, frame: Option<&FeedbackFrame>, stalled: bool) -> LinkCycle {
        let mut out = LinkCycle::default();
        // At most one cycle per step: the supervisor's own stall is not the
        // peer's silence (the engines count the same way, same code).
        let elapsed = self.loss.tick(now_ns, self.cycle_ns);

        let mut usable = None;
        if let Some(f) = frame {
            let answers = f.answers_sequence;
            if f.header.axis_count as usize != self.axes.len() || answers > self.last_sent {
                // Another machine's process, or an answer to a command never
                // sent: not ours to use.
                self.counts.frames_refused += 1;
            } else if self.last_sent - answers >= self.window || answers == 0 {
                self.counts.frames_too_old += 1;
            } else {
                usable = Some(f);
            }
        }

        match usable {
            Some(f) => {
                out.fresh = true;
                out.answered_previous = f.answers_sequence == self.last_sent;
                let t0 = self.sent_ns[(f.answers_sequence % SENT_RING as u64) as usize];
                if self.last_sent - f.answers_sequence < SENT_RING as u64
                    && t0 > 0
                    && f.header.timestamp_ns >= t0
                {
                    out.roundtrip_ns = Some(f.header.timestamp_ns - t0);
                }
                if self.gap > 0 {
                    self.counts.gaps.add(self.gap);
                    self.gap = 0;
                }
                self.counts.frames_received += 1;
                self.loss.fresh(now_ns, elapsed, self.drain);
                let new_origin = f.header.origin != self.origin;
                if !self.attached || new_origin {
                    if self.ever_attached && new_origin {
                        self.counts.incarnations += 1;
                        out.restarted = true;
                    }
                    self.attached = true;
                    self.ever_attached = true;
                    self.origin = f.header.origin;
                    self.loss.connected(now_ns);
                    self.counts.attachments += 1;
                    out.reconnected = true;
                }
            }
            None => {
                self.counts.frames_missing += 1;
                // Before the process first attached there is no gap to count.
                if self.ever_attached {
                    self.gap += 1;
                }
                // Trips once per loss; a stalled step is excused within a
                // bound (see `motion_homing::axis::loss`).
                if self.loss.missing(elapsed, self.limit_ns, stalled) && self.attached {
                    self.attached = false;
                }
            }
        }
        self.counts.gap_cycles = self.gap;
        out
    }

    /// For the snapshot; the current gap is counted as if it ended now.
    pub fn snap(&self) -> IoSnap {
        let mut s = IoSnap {
            attached: self.attached,
            counters: self.counts,
        };
        s.counters.gaps.longest_cycles = s.counters.gaps.longest_cycles.max(self.gap);
        s
    }

    /// Gaps counted so far (only finished gaps).
    pub fn gaps(&self) -> &GapCounts {
        &self.counts.gaps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    fn frame(answers: u64, origin: u64) -> FeedbackFrame {
        let mut f = FeedbackFrame::ZERO;
        f.header.axis_count = 1;
        f.header.origin = origin;
        f.answers_sequence = answers;
        f
    }

    fn link() -> IoLink {
        IoLink::new(vec![0], 10 * MS, 0.25, MS)
    }

    /// Cycle k: publish command k, and get the answer to k-1.
    fn run(l: &mut IoLink, k: u64, answer: bool, origin: u64) -> LinkCycle {
        let f = frame(k.saturating_sub(1), origin);
        let c = l.step(k * MS, (answer && k > 1).then_some(&f), false);
        l.sent(k, k * MS);
        c
    }

    #[test]
    fn attaches_on_the_first_answer_and_tolerates_a_short_gap() {
        let mut l = link();
        assert!(!run(&mut l, 1, true, 7).fresh);
        let c = run(&mut l, 2, true, 7);
        assert!(c.fresh && c.reconnected && l.attached());
        for k in 3..50 {
            assert!(!run(&mut l, k, true, 7).reconnected);
        }
        // 5 ms gap: still attached.
        for k in 50..55 {
            run(&mut l, k, false, 7);
        }
        assert!(l.attached());
        assert!(run(&mut l, 55, true, 7).fresh);
        assert_eq!(l.snap().counters.gaps.four_to_ten, 1);
        assert_eq!(l.snap().counters.gaps.longest_cycles, 5);
    }

    #[test]
    fn a_dead_peer_detaches_within_the_bound_and_reattaches() {
        let mut l = link();
        for k in 1..20 {
            run(&mut l, k, true, 7);
        }
        let mut detached_at = None;
        for k in 20..40 {
            run(&mut l, k, false, 7);
            if !l.attached() && detached_at.is_none() {
                detached_at = Some(k);
            }
        }
        // Bucket 0 + 1 ms per missing cycle > 10 ms on the 11th.
        assert_eq!(detached_at, Some(30));
        let c = run(&mut l, 40, true, 7);
        assert!(c.reconnected && l.attached());
        assert_eq!(l.snap().counters.attachments, 2);
    }

    #[test]
    fn late_steps_are_excused_within_the_bound() {
        let mut l = link();
        for k in 1..20 {
            run(&mut l, k, true, 7);
        }
        // A dead peer, and every step late: 10 ms excused, then 11 charged.
        let mut detached_at = None;
        for k in 20..60 {
            let c = l.step(k * MS, None, true);
            assert!(!c.fresh);
            l.sent(k, k * MS);
            if !l.attached() && detached_at.is_none() {
                detached_at = Some(k);
            }
        }
        assert_eq!(detached_at, Some(40));
        // Late steps missing every other cycle, for ever: attached throughout,
        // and every gap counted.
        let mut l = link();
        for k in 1..2000 {
            let answer = k % 2 == 0;
            let f = frame(k - 1, 7);
            l.step(k * MS, answer.then_some(&f), !answer);
            l.sent(k, k * MS);
            assert!(k < 3 || l.attached(), "{k}");
        }
        assert_eq!(l.snap().counters.gaps.one, 998);
    }

    #[test]
    fn a_restarted_peer_is_a_reconnection() {
        let mut l = link();
        for k in 1..10 {
            run(&mut l, k, true, 7);
        }
        let c = run(&mut l, 10, true, 8);
        assert!(c.reconnected);
        assert_eq!(l.snap().counters.incarnations, 1);
    }

    #[test]
    fn answers_from_the_future_or_too_old_are_not_used() {
        let mut l = link();
        for k in 1..20 {
            run(&mut l, k, true, 7);
        }
        let forged = frame(u64::MAX, 7);
        assert!(!l.step(20 * MS, Some(&forged), false).fresh);
        assert_eq!(l.snap().counters.frames_refused, 1);
        let old = frame(5, 7); // 14 commands old, window 10
        assert!(!l.step(21 * MS, Some(&old), false).fresh);
        assert_eq!(l.snap().counters.frames_too_old, 1);
        let mut wrong = frame(19, 7);
        wrong.header.axis_count = 3;
        assert!(!l.step(22 * MS, Some(&wrong), false).fresh);
        assert_eq!(l.snap().counters.frames_refused, 2);
    }

    #[test]
    fn a_stall_of_the_supervisor_does_not_detach() {
        let mut l = link();
        for k in 1..20 {
            run(&mut l, k, true, 7);
        }
        // The supervisor sleeps through 40 ms; the answer is not there yet at
        // its next step (the peer was stalled too), then it is.
        let f = frame(19, 7);
        assert!(!l.step(60 * MS, None, false).fresh);
        assert!(l.attached(), "one late step is one missed answer");
        assert!(l.step(61 * MS, Some(&f), false).fresh);
    }

    #[test]
    fn round_trip_from_the_answers_timestamp() {
        let mut l = link();
        l.sent(1, 5 * MS);
        let mut f = frame(1, 7);
        f.header.timestamp_ns = 5 * MS + 30_000;
        let c = l.step(6 * MS, Some(&f), false);
        assert_eq!(c.roundtrip_ns, Some(30_000));
    }
}
