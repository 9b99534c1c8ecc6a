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

/// Empty: every cell that once waited here (the enable withdrawn on a
/// fault or a dropped power stage in every state, the stream followed on
/// the cycle's timeline, a dead or silent program's axes stopped within
/// their bound, a pending enable dropped on a lost drive or a new I/O
/// process) passes since the engine's fixes; a new known hole is listed
/// here with its name until its fix lands.
const WAITING: &[(State, Event, &str)] = &[];
