//! Absolute-deadline periodic timer.
//!
//! A cycle that sleeps for "one period" after doing its work drifts: every
//! wake-up latency and every microsecond of work is added to the period, and
//! the error accumulates forever. [`PeriodicTimer`] instead keeps an absolute
//! deadline (`deadline += period`) and sleeps with
//! `clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, deadline)`, so a late
//! wake-up makes *that* cycle late but never shifts the next one.
//!
//! A signal interrupts `clock_nanosleep` with `EINTR`; because the deadline is
//! absolute, retrying with the *same* deadline is exactly right (a relative
//! sleep would have to recompute the remainder and would drift again).
//!
//! When a cycle overruns so badly that whole periods have already passed when
//! the timer wakes, those periods are *missed*: the timer counts them and
//! skips ahead by whole periods (`deadline += k * period`) so the phase of the
//! loop is kept and it does not run a burst of back-to-back catch-up cycles.
//! (cyclictest skips missed periods silently; we count them.)

use nix::errno::Errno;
use nix::sys::time::TimeSpec;
use nix::time::{clock_nanosleep, ClockId, ClockNanosleepFlags};

use crate::clock::{now_ns, NANOS_PER_SEC};

/// What one [`PeriodicTimer::wait`] observed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Wakeup {
    /// The absolute `CLOCK_MONOTONIC` deadline slept to, in ns.
    pub deadline_ns: u64,
    /// When the thread was actually running again, in ns.
    pub woke_ns: u64,
    /// `woke_ns - deadline_ns`, saturating at 0. Includes the time the cycle
    /// overran when `wait` was called after its deadline had passed.
    pub latency_ns: u64,
    /// Whole periods after `deadline_ns` that had already passed when the
    /// thread woke and were skipped. The next deadline is
    /// `deadline_ns + (1 + missed) * period`.
    pub missed: u64,
}

/// Periodic wake-ups on absolute `CLOCK_MONOTONIC` deadlines.
///
/// `wait` makes no allocation and no system call other than
/// `clock_nanosleep` and `clock_gettime` (vDSO).
#[derive(Debug, Clone)]
pub struct PeriodicTimer {
    period_ns: u64,
    next_deadline_ns: u64,
    total_missed: u64,
    cycles: u64,
}

impl PeriodicTimer {
    /// A timer whose first deadline is one period from now.
    ///
    /// # Panics
    ///
    /// If `period_ns` is 0 (a programming error, not an OS condition).
    pub fn new(period_ns: u64) -> Self {
        Self::starting_at(period_ns, now_ns().saturating_add(period_ns))
    }

    /// A timer whose first deadline is `first_deadline_ns` (absolute
    /// `CLOCK_MONOTONIC`), e.g. to align several loops to a common phase.
    ///
    /// # Panics
    ///
    /// If `period_ns` is 0.
    pub fn starting_at(period_ns: u64, first_deadline_ns: u64) -> Self {
        assert!(period_ns > 0, "PeriodicTimer period must be > 0 ns");
        Self {
            period_ns,
            next_deadline_ns: first_deadline_ns,
            total_missed: 0,
            cycles: 0,
        }
    }

    /// Sleeps until the next absolute deadline and advances it.
    ///
    /// `EINTR` is retried with the same absolute deadline. If the deadline has
    /// already passed the call returns at once (a late cycle); whole periods
    /// that have passed as well are counted in [`Wakeup::missed`] and skipped.
    pub fn wait(&mut self) -> Wakeup {
        let deadline = self.next_deadline_ns;
        let request = TimeSpec::new(
            (deadline / NANOS_PER_SEC) as libc::time_t,
            (deadline % NANOS_PER_SEC) as _,
        );
        loop {
            match clock_nanosleep(
                ClockId::CLOCK_MONOTONIC,
                ClockNanosleepFlags::TIMER_ABSTIME,
                &request,
            ) {
                Ok(_) => break,
                // A signal handler ran: sleep again to the SAME deadline.
                Err(Errno::EINTR) => continue,
                // EINVAL/EFAULT cannot happen with a valid timespec on
                // CLOCK_MONOTONIC; do not spin on it either way.
                Err(_) => break,
            }
        }
        let woke = now_ns();
        let late = woke.saturating_sub(deadline);
        // Deadlines deadline + k*period for k = 1..=missed are already in the
        // past: skip them, keep the phase.
        let missed = late / self.period_ns;
        self.next_deadline_ns =
            deadline.saturating_add((missed + 1).saturating_mul(self.period_ns));
        self.total_missed += missed;
        self.cycles += 1;
        Wakeup {
            deadline_ns: deadline,
            woke_ns: woke,
            latency_ns: late,
            missed,
        }
    }

    /// Re-phases the timer: the next deadline becomes one period from now.
    /// Use after a deliberate pause (e.g. a state change outside the cycle).
    pub fn reset(&mut self) {
        self.next_deadline_ns = now_ns().saturating_add(self.period_ns);
    }

    /// The period in nanoseconds.
    pub fn period_ns(&self) -> u64 {
        self.period_ns
    }

    /// The absolute deadline the next [`wait`](Self::wait) sleeps to.
    pub fn next_deadline_ns(&self) -> u64 {
        self.next_deadline_ns
    }

    /// Periods skipped since the timer was created.
    pub fn total_missed(&self) -> u64 {
        self.total_missed
    }

    /// Number of completed [`wait`](Self::wait) calls.
    pub fn cycles(&self) -> u64 {
        self.cycles
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deadlines_advance_by_one_period() {
        let period = 2_000_000;
        let mut t = PeriodicTimer::new(period);
        let first = t.next_deadline_ns();
        let mut prev: Option<Wakeup> = None;
        for _ in 0..10 {
            let w = t.wait();
            assert!(w.woke_ns >= w.deadline_ns);
            assert_eq!(w.latency_ns, w.woke_ns - w.deadline_ns);
            if let Some(p) = prev {
                assert_eq!(w.deadline_ns, p.deadline_ns + (1 + p.missed) * period);
            } else {
                assert_eq!(w.deadline_ns, first);
            }
            prev = Some(w);
        }
        assert_eq!(t.cycles(), 10);
    }

    #[test]
    fn late_wait_returns_at_once_and_counts() {
        let period = 1_000_000;
        // First deadline 10.5 periods in the past.
        let start = now_ns() - 10 * period - period / 2;
        let mut t = PeriodicTimer::starting_at(period, start);
        let w = t.wait();
        assert_eq!(w.deadline_ns, start);
        assert!(w.missed >= 10, "{w:?}");
        assert_eq!(t.total_missed(), w.missed);
        assert!(t.next_deadline_ns() > w.woke_ns);
        assert_eq!(t.next_deadline_ns(), start + (w.missed + 1) * period);
    }

    #[test]
    #[should_panic(expected = "period must be > 0")]
    fn zero_period_panics() {
        let _ = PeriodicTimer::new(0);
    }
}
