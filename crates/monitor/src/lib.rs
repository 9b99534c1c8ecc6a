//! The independent cycle monitor: a small pure function between the engine
//! and the frames that sees every command leaving and every feedback
//! arriving, and enforces the invariants whatever the operations' code did
//! — as LinuxCNC's motion controller checks the planners' output against
//! the joint limits every servo period whoever planned it, and a TwinCAT
//! NC axis is monitored apart from the generator that commands it.
//!
//! It depends on `motion-homing` only for the types that cross the
//! engine's boundary (`Command`, `Feedback`, `Request`, `Status`,
//! `AxisConfig`, the code table) and the configuration's meaning of its
//! keys; it shares none of the engine's planning: its bounds come from the
//! configuration and from what was asked (an operation's speed and
//! accelerations as its request carried them, a homing's configured
//! speeds), never from the engine's plan, and its own stop is its own.
//!
//! # The invariants (ERR 1021, EXERR below)
//!
//! | EXERR | invariant | bound |
//! |---|---|---|
//! | 1 velocity | the command's velocity | the speed bound: the cap that applies — `max_speed`; `unhomed_speed` too while not homed; a jog's or move's own speed; the homing speeds while homing; for a stream, 0 from `stream_timeout_ms` after its last setpoint arrived — and after the cap drops (a stop, a fault, an end), the speed allowed before, decaying at the deceleration that motion's stops reach at least (SS1 ramp monitoring) |
//! | 2 acceleration | change of the commanded positions' velocity from one interval to the next, over the longer interval | while the speed grows: the operation's acceleration, `stream_acceleration`, Home Acceleration; while it shrinks: the operation's deceleration, `max_deceleration`, Home Deceleration, `stream_acceleration` (the largest that applies); braking harder only to end on a soft limit |
//! | 3 step | first divided difference of the commanded positions | the speed bound at the start of the interval |
//! | 4 soft limit | the command in axis coordinates while homed (linear, `travel_limits`) | inside; once outside (it never should be), never further out |
//! | 5 enable | the power stage asked on | only after an explicit enable, home, jog, move or stream since the last drive fault, dropped power stage, lost drive, shutdown, or disable come to rest |
//! | 6 gantry | the distance between a gantry's sides | within `max_skew` of where they stood together (not while homing) |
//! | 7 not finite | every command | a number |
//!
//! Judged on the raw positions the drive receives (differences over the
//! times between the cycles, so a late cycle is judged over the time it
//! spanned), while the drive
//! follows them (a servo axis asked on whose drive reports its power stage
//! on without a fault and does not home itself; a virtual axis always),
//! with a relative tolerance of [`TOLERANCE`] (1e-6) on every bound plus
//! the positions' own rounding ([`POSITION_ROUNDING`], 64 ulp of their
//! magnitude) — and half a count on the soft limits.
//!
//! # A trip
//!
//! The command is replaced by the monitor's stop: category 1 (EN 60204-1)
//! from the last command it passed, at the largest deceleration that
//! applied (at least `max_deceleration`; ending on a soft limit it would
//! pass), then the power stage off — or category 0 where the power stage
//! is already off (a fault, a dropped or lost drive, a shutdown, an enable
//! it was not allowed): it is never asked on to brake. The trip (the
//! invariant, the value against its bound, the category) stays until a
//! `Reset` the engine accepts; the caller tells the engine
//! (`Axis::monitor_tripped`) and hands the [`Trip`] on as data: the cycle
//! formats nothing.
//!
//! Pure, sans-I/O: no clock, thread, allocation or panic; `check` is a
//! few dozen floating-point operations per axis per cycle (the engine
//! bench measures it).

#![forbid(unsafe_code)]

mod bounds;
mod envelope;
mod events;
pub mod gantry;
mod mode;
mod monitor;
mod power;
mod ramp;
mod trip;

pub use events::Cycle;
pub use gantry::{Apart, Side, Together};
pub use monitor::{Monitor, POSITION_ROUNDING, TOLERANCE};
pub use trip::{Category, Invariant, Trip, Withdrawn};
