//! Every homing sequence as one ordered list of legs.
//!
//! A sequence reads in one place: the plan. The state machine
//! ([`Axis`](crate::Axis)) runs the legs of its plan in order, and
//! [`Status::leg`](crate::Status) is the index of the current leg in it, so a
//! coordinator (gantry, home order) can see where each axis is.
//!
//! | sequence (active) | plan |
//! |---|---|
//! | bidirectional switch | seek switch, stop, return until clear (event), stop, move home |
//! | bidirectional marker | seek marker (event), stop, move home |
//! | bidirectional switch then marker | seek switch, stop, return until clear then marker (event), stop, move home |
//! | torque | seek torque (event), stop, release, move home |
//! | torque then marker | seek torque, stop, release, return to marker (event), stop, restore, move home |
//! | unidirectional switch / marker / switch then marker | seek event, continue (on to Home Position, or stop) |
//!
//! A passive sequence watches for its event (one leg); Immediate, and the
//! Absolute home mode (immediate only), have no legs at all.
//!
//! **Creep** (the seek / back-off / creep scheme, for drives without a marker
//! latch): a marker found at speed is only *rough*; the plan stops past it
//! and creeps back over it (`…, stop, creep (event), stop, …`).
//!
//! **Where the event is.** The last search leg of a plan finds the home event.
//! A marker found by a search leg that is followed by a creep is rough; what
//! an earlier search leg finds (switch detected, hard stop before a marker) is
//! a waypoint of the sequence.
//!
//! **Switch active at start** (spec §4): a bidirectional switch sequence skips
//! its seek and stop and starts with the return leg
//! ([`first_return`]); a unidirectional one establishes the event where it
//! stands and starts with its continue leg.

use crate::config::{AxisConfig, HomeDirection, HomeMode, HomeSequence};
use crate::status::Phase;

/// What a search leg is looking for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Goal {
    /// Switch goes from released to actuated.
    SwitchDetect,
    /// Switch seen actuated in this leg, then released.
    SwitchClear,
    /// `SwitchClear`, then the first marker beyond the clear point.
    SwitchClearThenMarker,
    /// `SwitchDetect`, then the first marker beyond the detect point.
    SwitchDetectThenMarker,
    /// The first marker.
    Marker,
    /// Torque at or over the threshold for the torque time.
    Torque,
}

/// One leg of a homing sequence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Leg {
    /// Jog in Home Direction at Home Speed until the goal is found.
    Seek(Goal),
    /// Decelerate at Home Deceleration to rest.
    Stop,
    /// Bring the command back onto the actual position at Home Return Speed:
    /// after a hard stop the command has run past the wall, and the torque
    /// must fall before the drive's limits are restored.
    Release,
    /// Jog against Home Direction at Home Return Speed until the goal.
    Return(Goal),
    /// Creep back over a rough marker at Home Creep Speed.
    Creep,
    /// Restore the overridden torque limits and error tolerances (no motion).
    Restore,
    /// Trapezoidal move to Home Position at Home Return Speed (the shortest
    /// way on a cyclic axis); skipped when it lies inside a hard stop.
    MoveHome,
    /// Unidirectional: on to Home Position at Home Speed if that needs no
    /// reversal, else decelerate to a stop (IP clears without PC).
    Continue,
    /// Passive: wait for the goal while something else moves the axis.
    Watch(Goal),
    /// The drive homes the axis itself (`drive_homing`): asked for, then
    /// watched until the drive reports home attained (or an error); the
    /// command follows the drive (see `axis::drive_homing`).
    DriveHomes,
}

impl Leg {
    /// A leg that searches for a goal (and so is bounded by the search limit,
    /// except a passive watch, which commands nothing).
    pub fn goal(self) -> Option<Goal> {
        match self {
            Leg::Seek(g) | Leg::Return(g) | Leg::Watch(g) => Some(g),
            Leg::Creep => Some(Goal::Marker),
            _ => None,
        }
    }

    /// The leg commands motion. A coordinator's barrier (`Request::hold`)
    /// holds an axis at rest only before such a leg: holding before a leg
    /// that does not move (restore) would synchronise nothing.
    pub fn moves(self) -> bool {
        !matches!(self, Leg::Restore | Leg::Watch(_))
    }
}

use Goal::*;
use Leg::*;

/// A sequence the drive homes by itself (`drive_homing`).
pub const DRIVE_HOMES: &[Leg] = &[DriveHomes, MoveHome];

const PASSIVE_SWITCH: &[Leg] = &[Watch(SwitchDetect)];
const PASSIVE_MARKER: &[Leg] = &[Watch(Marker)];
const PASSIVE_SWITCH_MARKER: &[Leg] = &[Watch(SwitchDetectThenMarker)];

const UNI_SWITCH: &[Leg] = &[Seek(SwitchDetect), Continue];
const UNI_MARKER: &[Leg] = &[Seek(Marker), Continue];
const UNI_SWITCH_MARKER: &[Leg] = &[Seek(SwitchDetectThenMarker), Continue];

const BI_SWITCH: &[Leg] = &[
    Seek(SwitchDetect),
    Stop,
    Return(SwitchClear),
    Stop,
    MoveHome,
];
const BI_MARKER: &[Leg] = &[Seek(Marker), Stop, MoveHome];
const BI_MARKER_CREEP: &[Leg] = &[Seek(Marker), Stop, Creep, Stop, MoveHome];
const BI_SWITCH_MARKER: &[Leg] = &[
    Seek(SwitchDetect),
    Stop,
    Return(SwitchClearThenMarker),
    Stop,
    MoveHome,
];
const BI_SWITCH_MARKER_CREEP: &[Leg] = &[
    Seek(SwitchDetect),
    Stop,
    Return(SwitchClearThenMarker),
    Stop,
    Creep,
    Stop,
    MoveHome,
];
const TORQUE: &[Leg] = &[Seek(Torque), Stop, Release, MoveHome];
const TORQUE_MARKER: &[Leg] = &[
    Seek(Torque),
    Stop,
    Release,
    Return(Marker),
    Stop,
    Restore,
    MoveHome,
];
const TORQUE_MARKER_CREEP: &[Leg] = &[
    Seek(Torque),
    Stop,
    Release,
    Return(Marker),
    Stop,
    Creep,
    Stop,
    Restore,
    MoveHome,
];

/// The legs of a sequence. `creep`: markers found at speed are refined by a
/// creep leg (see [`creeps`]).
///
/// Combinations that validation refuses (passive torque, unidirectional
/// torque) still get a plan, so the function is total; they never run.
pub fn plan(seq: HomeSequence, dir: HomeDirection, mode: HomeMode, creep: bool) -> &'static [Leg] {
    use HomeSequence as S;
    if seq == S::Immediate || mode == HomeMode::Absolute {
        return &[];
    }
    match mode {
        HomeMode::Absolute => &[],
        HomeMode::Passive => match seq {
            S::Switch => PASSIVE_SWITCH,
            S::SwitchThenMarker => PASSIVE_SWITCH_MARKER,
            _ => PASSIVE_MARKER,
        },
        HomeMode::Active if dir.is_unidirectional() && !seq.uses_torque() => match seq {
            S::Switch => UNI_SWITCH,
            S::Marker => UNI_MARKER,
            _ => UNI_SWITCH_MARKER,
        },
        HomeMode::Active => match (seq, creep) {
            (S::Switch, _) => BI_SWITCH,
            (S::Marker, false) => BI_MARKER,
            (S::Marker, true) => BI_MARKER_CREEP,
            (S::SwitchThenMarker, false) => BI_SWITCH_MARKER,
            (S::SwitchThenMarker, true) => BI_SWITCH_MARKER_CREEP,
            (S::Torque, _) => TORQUE,
            (_, false) => TORQUE_MARKER,
            (_, true) => TORQUE_MARKER_CREEP,
        },
    }
}

/// A marker found at speed is refined by a creep leg: the drive has no
/// marker latch, a creep speed is set, and the sequence is active and
/// bidirectional (creeping back reverses).
pub fn creeps(cfg: &AxisConfig) -> bool {
    !cfg.marker_latch
        && cfg.home_creep_speed > 0.0
        && cfg.home_mode == HomeMode::Active
        && !cfg.home_direction.is_unidirectional()
}

/// The plan of `cfg`'s sequence.
pub fn plan_for(cfg: &AxisConfig) -> &'static [Leg] {
    if cfg.drive_homing
        && cfg.home_mode == HomeMode::Active
        && cfg.home_sequence != HomeSequence::Immediate
    {
        // the drive homes (see `axis::drive_homing`), then the move home
        return DRIVE_HOMES;
    }
    plan(
        cfg.home_sequence,
        cfg.home_direction,
        cfg.home_mode,
        creeps(cfg),
    )
}

/// What a search leg's find is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Find {
    /// The home event.
    Event,
    /// A marker found at speed, to be crept over by a later leg.
    Rough,
    /// A waypoint: the switch detected before its clear point, a hard stop
    /// before the marker.
    Waypoint,
}

/// What the search leg at `i` finds (see the module docs).
pub fn find_at(plan: &[Leg], i: usize) -> Find {
    let later = plan.get(i + 1..).unwrap_or(&[]);
    if matches!(later, [Stop, Creep, ..]) {
        Find::Rough
    } else if later.iter().any(|l| l.goal().is_some()) {
        Find::Waypoint
    } else {
        Find::Event
    }
}

/// Index of the first return leg: where a bidirectional switch sequence
/// starts when the switch is already active (0 if the plan has none).
pub fn first_return(plan: &[Leg]) -> usize {
    plan.iter()
        .position(|l| matches!(l, Return(_)))
        .unwrap_or(0)
}

/// The operator-facing phase of leg `i`. A stop is a seek stop after a seek
/// and a return stop otherwise; a continue leg is a move home while it moves
/// to Home Position (`to_home`) and a seek stop when it only stops.
pub fn phase_of(plan: &[Leg], i: usize, to_home: bool) -> Phase {
    match plan.get(i) {
        None => Phase::Idle,
        Some(Seek(_)) => Phase::Seek,
        Some(Stop) if i > 0 && matches!(plan[i - 1], Seek(_)) => Phase::SeekStop,
        Some(Stop) | Some(Restore) => Phase::ReturnStop,
        Some(Release) => Phase::Release,
        Some(Return(_)) => Phase::Return,
        Some(Creep) => Phase::Creep,
        Some(MoveHome) => Phase::MoveHome,
        Some(Continue) if to_home => Phase::MoveHome,
        Some(Continue) => Phase::SeekStop,
        Some(Watch(_)) => Phase::Passive,
        Some(DriveHomes) => Phase::DriveHoming,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use HomeDirection as D;
    use HomeSequence as S;

    #[test]
    fn one_sequence_reads_in_one_place() {
        let p = plan(
            S::TorqueThenMarker,
            D::BidirectionalReverse,
            HomeMode::Active,
            false,
        );
        // Torque then marker: the torque sequence up to the release (seek
        // into the stop, stop, release), then back to the marker, stop,
        // restore the overridden drive values, move home.
        assert_eq!(&TORQUE[..3], [Seek(Torque), Stop, Release]);
        let torque_then_marker =
            [&TORQUE[..3], &[Return(Marker), Stop, Restore, MoveHome]].concat();
        assert_eq!(p, torque_then_marker);
        assert!(plan(
            S::Immediate,
            D::BidirectionalForward,
            HomeMode::Active,
            false
        )
        .is_empty());
        assert_eq!(
            plan(
                S::SwitchThenMarker,
                D::UnidirectionalReverse,
                HomeMode::Active,
                true
            ),
            [Seek(SwitchDetectThenMarker), Continue],
            "unidirectional never creeps back"
        );
    }

    #[test]
    fn the_last_search_finds_the_event() {
        let p = BI_SWITCH_MARKER_CREEP;
        assert_eq!(find_at(p, 0), Find::Waypoint);
        assert_eq!(find_at(p, 2), Find::Rough);
        assert_eq!(find_at(p, 4), Find::Event);
        assert_eq!(find_at(TORQUE, 0), Find::Event);
        assert_eq!(find_at(TORQUE_MARKER, 0), Find::Waypoint);
        assert_eq!(find_at(TORQUE_MARKER, 3), Find::Event);
        assert_eq!(find_at(UNI_MARKER, 0), Find::Event);
        assert_eq!(find_at(PASSIVE_SWITCH_MARKER, 0), Find::Event);
        assert_eq!(first_return(BI_SWITCH), 2);
    }

    #[test]
    fn phases_keep_their_names() {
        let p = TORQUE_MARKER_CREEP;
        let names: Vec<&str> = (0..p.len()).map(|i| phase_of(p, i, false).name()).collect();
        assert_eq!(
            names,
            [
                "seek",
                "seek_stop",
                "release",
                "return",
                "return_stop",
                "creep",
                "return_stop",
                "return_stop",
                "move_home"
            ]
        );
        assert_eq!(phase_of(UNI_SWITCH, 1, true), Phase::MoveHome);
        assert_eq!(phase_of(UNI_SWITCH, 1, false), Phase::SeekStop);
    }
}
