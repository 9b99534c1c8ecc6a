//! The measurement: one message per period, timed as the supervisor's cycle
//! times its exchange with motion-io, after a warm-up that proves the peer
//! is there. Answers later than half a period past the deadline are
//! counted apart, not put in the percentiles.

use crate::exchange::Exchange;
use hdrhistogram::Histogram;
use motion_bench::histogram;
use motion_bench::proc;
use motion_rt::{now_ns, PeriodicTimer};
use std::time::{Duration, Instant};

/// Result of one mode.
pub struct Measured {
    pub hist: Histogram<u64>,
    pub sent: u64,
    /// Messages without an answer within half a period.
    pub late: u64,
}

/// One cycle as `rt_thread` does it: clear stale wake-ups, timestamp,
/// publish + notify, wait (at most half a period after the deadline, at most
/// 4 wake-ups) for the answer to *this* message. Returns the round trip, ns.
fn cycle<X: Exchange>(x: &mut X, deadline: u64, period_ns: u64) -> Result<Option<u64>, String> {
    x.clear();
    let t_send = now_ns();
    let seq = x.send()?;
    for _ in 0..4 {
        if !x.wait_until(deadline + period_ns / 2) {
            break;
        }
        if x.answer() == Some(seq) {
            return Ok(Some(now_ns() - t_send));
        }
    }
    Ok(None)
}

/// `count` messages, one per period of `period_ns` (the cycle's timer:
/// absolute deadlines, whole periods that passed skipped with the phase
/// kept), after `warmup` answers in a row.
pub fn measure<X: Exchange>(
    x: &mut X,
    count: u64,
    period_ns: u64,
    warmup: u64,
) -> Result<Measured, String> {
    let mut timer = PeriodicTimer::new(period_ns);
    // warm-up: until `warmup` answers in a row (peer started, connected)
    let (started, mut in_row) = (Instant::now(), 0);
    while in_row < warmup {
        if started.elapsed() > Duration::from_secs(15) {
            return Err(format!(
                "the peer did not answer {warmup} messages in a row within 15 s"
            ));
        }
        if proc::stop_requested() {
            return Err("interrupted".into());
        }
        let deadline = timer.wait().deadline_ns;
        in_row = if cycle(x, deadline, period_ns)?.is_some() {
            in_row + 1
        } else {
            0
        };
    }
    let mut m = Measured {
        hist: histogram(),
        sent: 0,
        late: 0,
    };
    while m.sent < count {
        if m.sent % 1000 == 0 && proc::stop_requested() {
            return Err("interrupted".into());
        }
        let deadline = timer.wait().deadline_ns;
        m.sent += 1;
        match cycle(x, deadline, period_ns)? {
            Some(rt) => m.hist.saturating_record(rt.max(1)),
            None => m.late += 1,
        }
    }
    Ok(m)
}
