//! The cells that fail only because of the engine's known holes, each
//! named by its hole, until its fix is merged: they run and report (a
//! listed cell that passes is reported too, so the list can only shrink).

use super::events::Event;
use super::states::State;

/// The hole a cell waits for, if it does.
pub fn hole(state: State, event: Event) -> Option<&'static str> {
    WAITING
        .iter()
        .find(|(s, e, _)| *s == state && *e == event)
        .map(|&(_, _, h)| h)
}

/// Hole 2: the enable request withdrawn on a fault, a dropped power stage
/// (or a drive that left and came back off) in every state — here during
/// a homing's abort ramp, and a homing search whose drive or I/O process
/// went away.
const HOLE_2: &str = "hole 2 (enable withdrawn on a fault or a dropped power stage in every state)";
/// Hole 3: a stream followed on the cycle's timeline (here: a setpoint an
/// hour ahead on the program's clock).
const HOLE_3: &str = "hole 3 (stream limits on the cycle's timeline)";
/// Hole 4: a program that stops sending stopped within `stream_timeout_ms`
/// of its last setpoint's arrival, braking, never dead on its last one.
const HOLE_4: &str = "hole 4 (a dead or silent program's axes stopped within its bound)";
/// Found by this campaign, outside the seven: an enable still waiting for
/// the drive (an `Enable`, or a homing's start) carries over a lost drive
/// or a new I/O process, and the drive is asked on again when it is back.
const PENDING_ENABLE: &str = "engine: a pending enable survives a lost drive or a new I/O process";

const WAITING: &[(State, Event, &str)] = &[
    (State::HomingSeek, Event::DriveLost, HOLE_2),
    (State::HomingSeek, Event::IoGone, HOLE_2),
    (State::HomingStopping, Event::DriveFault, HOLE_2),
    (State::HomingStopping, Event::PowerDropped, HOLE_2),
    (State::HomingStopping, Event::DriveLost, HOLE_2),
    (State::Streaming, Event::TimestampJump, HOLE_3),
    (State::Streaming, Event::OwnerDeath, HOLE_4),
    (State::Enabling, Event::DriveLost, PENDING_ENABLE),
    (State::Enabling, Event::IoGone, PENDING_ENABLE),
    (State::HomingEnabling, Event::DriveLost, PENDING_ENABLE),
    (State::HomingEnabling, Event::IoGone, PENDING_ENABLE),
];
