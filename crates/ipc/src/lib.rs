//! `motion-ipc`: the supervisor's private iceoryx2 domain and the frame
//! ports every process of the product shares. The frames themselves (layout,
//! units ↔ counts) are `motion-frames`; this crate turns on its `zero-copy`
//! feature so they can travel through iceoryx2 shared memory.
//!
//! Who may talk to whom, and where (see [`domain`] for the why):
//!
//! * [`dir`] — the runtime directory: default, length limit, private and ours.
//! * [`domain`] — one supervisor start's domain ([`Domain`]): prefix, id, key,
//!   its iceoryx2 file prefix and config.
//! * [`session`] — the session file: claimed by the supervisor, joined by peers.
//! * [`liveness`] — whether a session's supervisor still runs.
//! * [`node`] — iceoryx2 node creation with the node-counter guard (0600).
//! * [`shm`] — a domain's files in `/dev/shm`.
//! * [`cleanup`] — leaving nothing behind in `/dev/shm`.
//! * [`names`] — service names.
//! * [`ports`] — the frame ports of one I/O process ([`SupervisorPorts`],
//!   [`IoPorts`]).
//! * [`setpoints`] — the supervised setpoint stream's service
//!   ([`SetpointSubscriber`] in the cycle, [`SetpointPublisher`] in programs).
//! * [`wait`] — exact waits on an iceoryx2 listener (`ppoll`).
//! * [`error`] — engineer-readable errors.
//!
//! The files depend on each other in one direction only: `error` and
//! `names` at the bottom; `dir` and `domain` on `error`; `shm` and
//! `liveness` on `domain`; `cleanup` on `shm`; `node` and `session` on those;
//! `ports` on `domain`, `names` and `wait`; `setpoints` on `domain` and `names`.

pub mod cleanup;
pub mod dir;
pub mod domain;
pub mod error;
pub mod liveness;
pub mod names;
pub mod node;
pub mod ports;
pub mod session;
pub mod setpoints;
pub mod shm;
pub mod wait;

pub use cleanup::{cleanup_domain, cleanup_stale_domains, CleanupReport};
pub use dir::{default_runtime_dir, runtime_dir_or_default};
pub use domain::Domain;
pub use error::IpcError;
pub use names::IoServiceNames;
pub use ports::{IoPorts, Ports, Sent, ShmFrame, SupervisorPorts};
pub use session::session_path;
pub use setpoints::{SetpointPublisher, SetpointSubscriber};

/// `CLOCK_MONOTONIC` now, in ns: the clock of every frame timestamp. It is
/// system-wide on Linux, so values taken in `motion-supervisor` and
/// `motion-io` compare directly. (The runtime's clock, under the name the
/// frame code uses.)
pub use motion_rt::now_ns as monotonic_ns;

/// A short directory under `/tmp` for one unit test (iceoryx2's socket paths
/// below a runtime directory are limited).
#[cfg(test)]
fn test_dir(tag: &str) -> std::path::PathBuf {
    std::path::PathBuf::from(format!("/tmp/mdt{}{tag}", std::process::id() % 100_000))
}
