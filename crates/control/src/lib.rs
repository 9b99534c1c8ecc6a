//! The control plane of a running `motion-supervisor`:
//!
//! * [`message`] — the `#[repr(C)]` request and response of the control
//!   service and the status frame, with a layout version in their iceoryx2
//!   type names (as the frames have). Plain fixed-size data, so any iceoryx2
//!   client can speak them — the Python package in `python/` does, with
//!   nothing but the `iceoryx2` package, whose ctypes classes are built from
//!   the description `tests/wire_layout.rs` writes (status rows included).
//! * [`request`] — a request as an enum ([`Request`]): decoded from the
//!   wire once, at the daemon's edge, and encoded from it by Rust clients;
//!   an unknown kind is an error, never another request.
//! * [`response`] — a response built from typed outcomes ([`AxisOutcome`],
//!   [`Reason`]); the `REASON_*`/`RESULT_*` numbers are written there.
//! * [`client`] — what `motionctl` (and any Rust HMI) uses: join the
//!   supervisor's domain through its session file, send requests, read status.
//! * [`report`] — a status frame and an answer in the reports' words
//!   ([`AxisReport`]: `status --json`'s and `home --json`'s rows, errors and
//!   warnings in words). The status entries and their fields are
//!   `motion-status`'s table.
//! * [`ops`] — enable, disable, reset, move and the hold-to-run [`Jog`]
//!   for Rust clients; [`stream`] — the supervised setpoint stream's
//!   [`stream::Stream`] handle and the acquire answer's axis map;
//!   [`follow`] — following operations to their end in the status.
//! * [`server`] — the daemon's side: serve requests and publish status, off
//!   the real-time thread.
//!
//! Requests carry the session key (from the owner-only session file); the
//! supervisor refuses every request without it. Responses and status frames
//! carry the session id, so a client knows it talks to the supervisor it
//! joined.

pub mod client;
pub mod follow;
pub mod homing;
pub mod message;
pub mod ops;
pub mod progress;
pub mod report;
pub mod request;
pub mod response;
pub mod server;
pub mod stream;

pub use client::{Client, ClientError};
pub use follow::OpOutcome;
pub use message::*;
pub use ops::{Jog, JogSpec, MoveSpec, OpError};
pub use report::AxisReport;
pub use request::{Axes, DecodeError, Request, Since};
pub use response::{AxisOutcome, Reason};
pub use server::{Server, ServerError};
