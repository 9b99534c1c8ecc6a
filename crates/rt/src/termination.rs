//! SIGINT / SIGTERM for both processes: the handler only records which
//! signal arrived; the main loop polls and shuts down in order (stop the
//! axes, drop the iceoryx2 ports and node, clean up shared memory).
//!
//! Installed with `SA_RESTART`, so ordinary system calls resume; waits that
//! the kernel never restarts (`ppoll`, `clock_nanosleep` return `EINTR`)
//! wake up, and the caller looks at [`received`]. A real-time thread that
//! must not be woken blocks both signals itself.

use std::sync::atomic::{AtomicI32, Ordering};

use nix::sys::signal::{sigaction, SaFlags, SigAction, SigHandler, SigSet, Signal};

static RECEIVED: AtomicI32 = AtomicI32::new(0);

extern "C" fn on_termination(sig: libc::c_int) {
    // async-signal-safe: one atomic store
    RECEIVED.store(sig, Ordering::SeqCst);
}

/// Installs the handler for SIGINT and SIGTERM (idempotent).
pub fn install() -> Result<(), String> {
    let action = SigAction::new(
        SigHandler::Handler(on_termination),
        SaFlags::SA_RESTART,
        SigSet::empty(),
    );
    for sig in [Signal::SIGINT, Signal::SIGTERM] {
        // SAFETY: the handler only stores to an atomic.
        unsafe { sigaction(sig, &action) }
            .map_err(|e| format!("cannot install the {sig} handler: {e}"))?;
    }
    Ok(())
}

/// The signal number that arrived (e.g. `Some(15)`), if any.
pub fn received() -> Option<i32> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// Name of the signal that arrived ("SIGTERM"), if any.
pub fn received_name() -> Option<&'static str> {
    received().and_then(|s| Signal::try_from(s).ok().map(Signal::as_str))
}
