//! Waiting on a descriptor until an absolute deadline, exactly.

use crate::monotonic_ns;

/// What [`ppoll_until`] saw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PollWake {
    /// The descriptor is readable (a wake-up is pending).
    Readable,
    /// The deadline passed (or had passed already).
    Deadline,
    /// A signal arrived (EINTR).
    Interrupted,
    /// `ppoll` failed otherwise.
    Error,
}

/// Waits until `fd` is readable or the absolute `CLOCK_MONOTONIC` time
/// `deadline_ns` passes, with `ppoll`: its timeout is an hrtimer (exact, no
/// slack for a SCHED_FIFO thread), unlike a socket's `SO_RCVTIMEO`, which is
/// counted in jiffies (iceoryx2's `timed_wait` sleeps up to 4 ms for 0.5 ms at
/// HZ=250). The mechanism of [`crate::Ports::wait_until`], for callers that
/// hold a raw iceoryx2 listener (the IPC benchmark's bare peer).
pub fn ppoll_until(fd: i32, deadline_ns: u64) -> PollWake {
    let now = monotonic_ns();
    if now >= deadline_ns {
        return PollWake::Deadline;
    }
    let rem = deadline_ns - now;
    let ts = libc::timespec {
        tv_sec: (rem / 1_000_000_000) as libc::time_t,
        tv_nsec: (rem % 1_000_000_000) as libc::c_long,
    };
    let mut pfd = libc::pollfd {
        fd,
        events: libc::POLLIN,
        revents: 0,
    };
    // SAFETY: one valid pollfd, a valid timespec, no signal mask.
    match unsafe { libc::ppoll(&mut pfd, 1, &ts, core::ptr::null()) } {
        0 => PollWake::Deadline,
        rc if rc > 0 => PollWake::Readable,
        _ if std::io::Error::last_os_error().raw_os_error() == Some(libc::EINTR) => {
            PollWake::Interrupted
        }
        _ => PollWake::Error,
    }
}
