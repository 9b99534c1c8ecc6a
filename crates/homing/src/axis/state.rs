//! What the axis is doing, with the data each phase needs and nothing more.
//!
//! A homing run carries its plan, the index of its current leg, what that leg
//! is doing, and the few facts earlier legs found that later legs use (where
//! the hard stop is, a rough marker to creep over). The operator-facing
//! [`Phase`] is derived from the state, never stored.

use super::detect::Search;
use super::ops::motion::Motion;
use crate::plan::{phase_of, Leg};
use crate::status::Phase;

/// The per-axis state.
#[derive(Clone, Copy, Debug)]
pub(super) enum State {
    /// Not homing; holding (or tracking the actual position while disabled).
    Idle,
    /// Active start: waiting since `since` (ns) for the drive to report enabled.
    Enabling { since: u64 },
    /// A sequence in progress.
    Homing(Homing),
    /// Aborted: decelerating to rest; then, if the drive's values are still
    /// overridden, `released` once the command is back on the actual
    /// position, then restoring.
    Stopping { released: bool },
    /// An operation's motion (jog, move, stream, or its stop): see `ops`.
    Motion(Motion),
}

/// A homing sequence in progress.
#[derive(Clone, Copy, Debug)]
pub(super) struct Homing {
    pub plan: &'static [Leg],
    /// Index of the current leg in `plan`.
    pub leg: usize,
    pub run: Run,
    /// Raw position of the hard stop, from the torque event on: Home Position
    /// beyond it is never moved to.
    pub hard_stop: Option<f64>,
    /// A marker found at speed (no latch), to creep back over.
    pub rough_marker: Option<f64>,
}

/// What the current leg is doing.
#[derive(Clone, Copy, Debug)]
pub(super) enum Run {
    /// At rest, held at the barrier (`Request::hold`) before the leg starts.
    /// `min_move_ns`: the shortest the leg's move to Home Position can take
    /// (0 for other legs).
    Waiting { min_move_ns: u64 },
    /// Searching for the leg's goal.
    Search(Search),
    /// Following the leg's profile to its end. `to_home`: the profile ends at
    /// Home Position (a continue leg that only stops does not).
    Profile { to_home: bool },
    /// The drive homes the axis itself (`Leg::DriveHomes`).
    Drive(DriveRun),
}

impl Homing {
    pub fn new(plan: &'static [Leg], leg: usize) -> Self {
        Self {
            plan,
            leg,
            run: Run::Profile { to_home: false },
            hard_stop: None,
            rough_marker: None,
        }
    }

    /// The current leg (a plan is never indexed past its end: reaching the
    /// end completes the sequence).
    pub fn current(&self) -> Option<Leg> {
        self.plan.get(self.leg).copied()
    }
}

impl State {
    pub fn phase(&self) -> Phase {
        match self {
            // Homing's phase: an operation's motion is not homing.
            State::Idle | State::Motion(_) => Phase::Idle,
            State::Enabling { .. } => Phase::Enabling,
            State::Stopping { .. } => Phase::Stopping,
            State::Homing(h) => {
                // Waiting before a continue leg: it will move to Home Position.
                let to_home = matches!(h.run, Run::Profile { to_home: true } | Run::Waiting { .. });
                phase_of(h.plan, h.leg, to_home)
            }
        }
    }

    /// Homing with a leg that commands motion (not a passive watch): the
    /// drive must be enabled and fault-free, and overtravel is checked.
    pub fn commands_motion(&self) -> bool {
        match self {
            State::Homing(h) => !matches!(h.current(), Some(Leg::Watch(_)) | None),
            _ => false,
        }
    }
}

/// The drive-homing leg's progress (`Run::Drive`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct DriveRun {
    /// When the leg asked the drive to home, ns.
    pub since: u64,
    /// The drive reported homing active for this request.
    pub seen_active: bool,
    /// The drive reported home attained; the request has dropped and the
    /// leg waits for the drive to hand back.
    pub attained: bool,
}
