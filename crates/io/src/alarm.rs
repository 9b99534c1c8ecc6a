//! A precise wake-up for the event-mode wait.
//!
//! `Ports::wait` is iceoryx2's `Listener::timed_wait`, a `recv` on a unix
//! datagram socket with `SO_RCVTIMEO`. The kernel counts that timeout in
//! jiffies: on this kind of machine a 1 ms timeout sleeps about 8 ms (measured),
//! so the timeout alone cannot be the clock of a 1 kHz watchdog stop. And a
//! timeout below 1 µs becomes `SO_RCVTIMEO = 0`, which means *block forever*.
//!
//! The alarm is a POSIX timer on `CLOCK_MONOTONIC` (an hrtimer: µs-exact),
//! armed for an absolute deadline, that sends `SIGALRM` to the loop's thread.
//! A socket receive with `SO_RCVTIMEO` set is never restarted after a signal
//! handler (`SA_RESTART` or not, see signal(7)), so the wait returns with
//! `EINTR` at the deadline, while a command's wake-up still ends it at once.
//! If the signal lands just before the wait starts, that wait sleeps for its
//! (coarse) timeout: the tick is late by at most that once.

use nix::sys::signal::{SigEvent, SigevNotify, Signal};
use nix::sys::time::TimeSpec;
use nix::sys::timer::{Expiration, Timer, TimerSetTimeFlags};
use nix::time::ClockId;

use crate::signals;

/// One-shot absolute-deadline alarm for the calling thread.
pub struct Alarm {
    timer: Timer,
    /// Deadline currently armed (ns, `CLOCK_MONOTONIC`); 0 = disarmed.
    armed_for: u64,
}

impl Alarm {
    /// Installs the (no-op) `SIGALRM` handler and creates the timer, directed
    /// at the calling thread.
    pub fn new() -> Result<Self, String> {
        signals::install_wakeup(Signal::SIGALRM)?;
        let event = SigEvent::new(SigevNotify::SigevThreadId {
            signal: Signal::SIGALRM,
            thread_id: nix::unistd::gettid().as_raw(),
            si_value: 0,
        });
        let timer = Timer::new(ClockId::CLOCK_MONOTONIC, event)
            .map_err(|e| format!("cannot create a CLOCK_MONOTONIC timer: {e}"))?;
        Ok(Self {
            timer,
            armed_for: 0,
        })
    }

    /// Fires at `deadline_ns` (`CLOCK_MONOTONIC`); replaces an earlier
    /// deadline. A system call only when the deadline changes.
    pub fn arm_at(&mut self, deadline_ns: u64) -> Result<(), String> {
        if deadline_ns == self.armed_for || deadline_ns == 0 {
            return Ok(());
        }
        let ts = TimeSpec::new(
            (deadline_ns / 1_000_000_000) as libc::time_t,
            (deadline_ns % 1_000_000_000) as libc::c_long,
        );
        self.timer
            .set(
                Expiration::OneShot(ts),
                TimerSetTimeFlags::TFD_TIMER_ABSTIME,
            )
            .map_err(|e| format!("cannot arm the wake-up timer: {e}"))?;
        self.armed_for = deadline_ns;
        Ok(())
    }
}
