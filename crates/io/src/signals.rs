//! SIGINT / SIGTERM: the handler only records the request; the main loop
//! checks [`requested`] every iteration and shuts down in order (stop the
//! axes, last feedback, drop ports and node, clean the domain).
//!
//! The iceoryx2 node is created with signal handling disabled, so these are
//! the only handlers. They are installed with `SA_RESTART`, so that ordinary
//! system calls (a write to stderr, a futex inside iceoryx2) are resumed
//! transparently; the blocking wait for a command is a `ppoll`, which the
//! kernel never restarts: it returns `EINTR` at once (reported by the ports
//! as `IpcError::Interrupted`), and the loop sees the flag.

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};

use nix::sys::signal::{sigaction, SaFlags, SigAction, SigHandler, SigSet, Signal};

static REQUESTED: AtomicBool = AtomicBool::new(false);
static SIGNAL: AtomicI32 = AtomicI32::new(0);

extern "C" fn on_termination(sig: libc::c_int) {
    // async-signal-safe: two atomic stores
    SIGNAL.store(sig, Ordering::Relaxed);
    REQUESTED.store(true, Ordering::SeqCst);
}

fn install(sig: Signal, handler: extern "C" fn(libc::c_int)) -> Result<(), String> {
    let action = SigAction::new(
        SigHandler::Handler(handler),
        SaFlags::SA_RESTART,
        SigSet::empty(),
    );
    // SAFETY: the handlers only store to atomics (async-signal-safe); no
    // handler of anybody else is replaced (iceoryx2's are disabled).
    unsafe { sigaction(sig, &action) }
        .map(drop)
        .map_err(|e| format!("cannot install the {sig} handler: {e}"))
}

/// Installs the handler for SIGINT and SIGTERM.
pub fn install_termination() -> Result<(), String> {
    install(Signal::SIGINT, on_termination)?;
    install(Signal::SIGTERM, on_termination)
}

/// True once SIGINT or SIGTERM arrived.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// Name of the signal that arrived ("SIGTERM"), if any.
pub fn name() -> Option<&'static str> {
    match SIGNAL.load(Ordering::Relaxed) {
        0 => None,
        s => Signal::try_from(s).ok().map(Signal::as_str),
    }
}
