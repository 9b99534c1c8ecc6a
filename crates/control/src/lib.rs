//! The control plane of a running `motion-supervisor`:
//!
//! * [`message`] — the `#[repr(C)]` request and response of the control
//!   service and the status frame, with a layout version in their iceoryx2
//!   type names (as the frames have). Plain fixed-size data, so any iceoryx2
//!   client can speak them — `examples/python/` does, with nothing but the
//!   `iceoryx2` package.
//! * [`client`] — what `motionctl` (and any Rust HMI) uses: join the
//!   supervisor's domain through its session file, send requests, read status.
//! * [`server`] — the daemon's side: serve requests and publish status, off
//!   the real-time thread.
//!
//! Requests carry the session key (from the owner-only session file); the
//! supervisor refuses every request without it. Responses and status frames
//! carry the session id, so a client knows it talks to the supervisor it
//! joined.

pub mod client;
pub mod homing;
pub mod message;
pub mod progress;
pub mod report;
pub mod server;

pub use client::{Client, ClientError};
pub use message::*;
pub use server::{Server, ServerError};
