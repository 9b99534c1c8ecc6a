//! `motion-opcua`: an OPC UA server for a running motion-supervisor, on the
//! maintained Rust stack async-opcua (tokio). A separate process and a
//! client of the daemon's control and status services exactly like
//! `motionctl` — never on the cycle's CPU, never in the daemon's way.
//!
//! * [`space`] — what the address space holds (tables), [`nodes`] builds it,
//!   [`units`] the engineering units, [`values`] fills it from status frames,
//!   [`events`] the event of an axis going ER.
//! * [`methods`] — Home/Stop/Unhome, HomeAll/StopAll, and every operation
//!   of the engine a client may ask for (Enable, Disable, Reset, Jog, Move,
//!   …: derived from the engine's specs) per axis: arguments in, the
//!   control service's answer out; [`jogs`] — hold to run: a jog lives
//!   for its lease (at most 1 s), renewed only by calling again, and ends
//!   at once when its caller may no longer call.
//! * [`manager`] — the node manager: roles checked, calls to the daemon.
//! * [`bridge`] — the thread that talks to the daemon (and follows restarts).
//! * [`auth`], [`password`], [`pki`] — users and roles, argon2 hashes, the
//!   certificate, key and trust list.
//! * [`server`] — endpoints and limits; [`cli`] — the command line;
//!   [`logging`] — the log, every line escaped.

pub mod auth;
pub mod bridge;
pub mod cli;
pub mod events;
pub mod jogs;
pub mod logging;
pub mod manager;
pub mod methods;
pub mod nodes;
pub mod password;
pub mod pki;
pub mod server;
pub mod space;
pub mod units;
pub mod values;
