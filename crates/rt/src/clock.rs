//! Monotonic time in nanoseconds.
//!
//! Everything in this crate measures time as `u64` nanoseconds of
//! `CLOCK_MONOTONIC`: it never jumps when NTP or an operator sets the wall
//! clock, it is the clock `clock_nanosleep` sleeps against, and a `u64` of
//! nanoseconds lasts 584 years of uptime, so arithmetic on it is plain integer
//! arithmetic with no `Duration`/`Instant` conversions in the cycle.

use libc::{c_long, time_t, timespec};

/// Nanoseconds per second.
pub const NANOS_PER_SEC: u64 = 1_000_000_000;

/// Current `CLOCK_MONOTONIC` time in nanoseconds (`clock_gettime`, served by
/// the vDSO on Linux: no system call, no allocation).
#[inline]
pub fn now_ns() -> u64 {
    let mut ts = timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec. CLOCK_MONOTONIC always
    // exists on Linux, so the call cannot fail with a valid pointer.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    debug_assert_eq!(rc, 0, "clock_gettime(CLOCK_MONOTONIC) failed");
    timespec_to_ns(&ts)
}

/// Converts a `timespec` (non-negative) to nanoseconds.
#[inline]
pub fn timespec_to_ns(ts: &timespec) -> u64 {
    (ts.tv_sec as u64)
        .saturating_mul(NANOS_PER_SEC)
        .saturating_add(ts.tv_nsec as u64)
}

/// Converts nanoseconds to a `timespec`.
#[inline]
pub fn ns_to_timespec(ns: u64) -> timespec {
    timespec {
        tv_sec: (ns / NANOS_PER_SEC) as time_t,
        tv_nsec: (ns % NANOS_PER_SEC) as c_long,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        for ns in [0, 1, 999_999_999, 1_000_000_000, 1_234_567_890_123] {
            assert_eq!(timespec_to_ns(&ns_to_timespec(ns)), ns);
        }
    }

    #[test]
    fn monotonic() {
        let a = now_ns();
        let b = now_ns();
        assert!(a > 0);
        assert!(b >= a);
    }
}
