//! A test hook, in debug builds only: SIGUSR1 blocks the main loop for good
//! — as a write to a stderr nobody reads once blocked it, or a bug would —
//! while the process and its other threads (the EtherCAT bus thread) run
//! on. The end-to-end tests use it to show that the bus thread then stops
//! the drives by itself. Release builds do not install it.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use nix::sys::signal::{sigaction, SaFlags, SigAction, SigHandler, SigSet, Signal};

static ASKED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_usr1(_: libc::c_int) {
    // async-signal-safe: one atomic store
    ASKED.store(true, Ordering::SeqCst);
}

/// Installs the SIGUSR1 handler (debug builds; a failure is ignored: the
/// hook is for tests).
pub fn install() {
    if cfg!(debug_assertions) {
        let action = SigAction::new(
            SigHandler::Handler(on_usr1),
            SaFlags::SA_RESTART,
            SigSet::empty(),
        );
        // SAFETY: the handler only stores to an atomic.
        let _ = unsafe { sigaction(Signal::SIGUSR1, &action) };
    }
}

/// Blocks the calling thread for good once SIGUSR1 arrived (only SIGKILL
/// ends the process then).
pub fn if_asked() {
    if ASKED.load(Ordering::Relaxed) {
        loop {
            std::thread::sleep(Duration::from_secs(3600));
        }
    }
}
