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
//! | limit switch | seek limit, stop at limit, return until clear (event), stop, move home |
//! | limit switch then marker | seek limit, stop at limit, return until clear then marker (event), stop, move home |
//! | bidirectional switch (then marker), after a limit (`home_reverse_at_limit`) | seek switch — limit first: stop at limit, reverse past the switch, stop, then the whole plan above again |
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
//! **Limit switch as the reference.** In the limit-switch sequences the
//! limit switch in Home Direction plays the home switch's part: the goals
//! `Switch*` mean that switch (the engine's "reference switch", see
//! `Axis::reference_switch_active`), and the plan is the bidirectional
//! switch plan with [`Leg::StopAtLimit`] after the seek: the one stop, with
//! the seek before it, during which that limit does not abort homing.
//!
//! **Reversing at a limit** (`home_reverse_at_limit`, CiA 402 methods 7–14 /
//! 23–30). A limit switch in Home Direction met by the first seek of a
//! bidirectional switch (then marker) sequence, before the home switch,
//! replaces the plan by its reversed form ([`after_reversal`]): the same leg
//! 0, then stop at the limit, run back at Home Speed until the home switch
//! has been passed entirely ([`Leg::Pass`]), stop — now on the near side —
//! and the original plan from its seek. The event is therefore the same
//! switch edge, approached in the same direction, as from a near-side start;
//! leg indices only grow, so a coordinator reading `Status::leg` sees legs
//! go by as usual. A reversal happens once: a limit in the second seek is an
//! overtravel (12 / 43).
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
    /// Decelerate at Home Deceleration to rest on the limit switch in Home
    /// Direction: after the seek of a limit-switch sequence, or where a
    /// limit reversed the search. That limit does not abort homing in this
    /// leg (nor in a limit-switch sequence's seek before it).
    StopAtLimit,
    /// After a reversal at a limit: jog against Home Direction at Home Speed
    /// until the goal (the home switch seen actuated and then released: the
    /// axis has passed it entirely).
    Pass(Goal),
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
            Leg::Seek(g) | Leg::Return(g) | Leg::Watch(g) | Leg::Pass(g) => Some(g),
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
// The limit-switch plans: the switch plans with a stop at the limit. Laid
// out a row per part so each reads against its switch plan.
#[rustfmt::skip]
const LIMIT: &[Leg] = &[
    Seek(SwitchDetect), StopAtLimit,
    Return(SwitchClear), Stop, MoveHome,
];
#[rustfmt::skip]
const LIMIT_MARKER: &[Leg] = &[
    Seek(SwitchDetect), StopAtLimit,
    Return(SwitchClearThenMarker), Stop, MoveHome,
];
#[rustfmt::skip]
const LIMIT_MARKER_CREEP: &[Leg] = &[
    Seek(SwitchDetect), StopAtLimit,
    Return(SwitchClearThenMarker), Stop, Creep, Stop, MoveHome,
];
// The reversed forms: leg 0, stop at the limit, back past the switch, stop
// (first row), then the whole bidirectional plan (`BI_SWITCH`,
// `BI_SWITCH_MARKER`, `BI_SWITCH_MARKER_CREEP`) again (second row).
#[rustfmt::skip]
const REV_SWITCH: &[Leg] = &[
    Seek(SwitchDetect), StopAtLimit, Pass(SwitchClear), Stop,
    Seek(SwitchDetect), Stop, Return(SwitchClear), Stop, MoveHome,
];
#[rustfmt::skip]
const REV_SWITCH_MARKER: &[Leg] = &[
    Seek(SwitchDetect), StopAtLimit, Pass(SwitchClear), Stop,
    Seek(SwitchDetect), Stop, Return(SwitchClearThenMarker), Stop, MoveHome,
];
#[rustfmt::skip]
const REV_SWITCH_MARKER_CREEP: &[Leg] = &[
    Seek(SwitchDetect), StopAtLimit, Pass(SwitchClear), Stop,
    Seek(SwitchDetect), Stop, Return(SwitchClearThenMarker), Stop, Creep, Stop, MoveHome,
];
/// Legs a reversed plan puts before the original one.
const REVERSAL_LEGS: usize = 4;
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
        HomeMode::Active
            if dir.is_unidirectional() && !seq.uses_torque() && !seq.uses_limit_switch() =>
        {
            match seq {
                S::Switch => UNI_SWITCH,
                S::Marker => UNI_MARKER,
                _ => UNI_SWITCH_MARKER,
            }
        }
        HomeMode::Active => match (seq, creep) {
            (S::Switch, _) => BI_SWITCH,
            (S::Marker, false) => BI_MARKER,
            (S::Marker, true) => BI_MARKER_CREEP,
            (S::SwitchThenMarker, false) => BI_SWITCH_MARKER,
            (S::SwitchThenMarker, true) => BI_SWITCH_MARKER_CREEP,
            (S::LimitSwitch, _) => LIMIT,
            (S::LimitSwitchThenMarker, false) => LIMIT_MARKER,
            (S::LimitSwitchThenMarker, true) => LIMIT_MARKER_CREEP,
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

/// The plan a search continues with when a limit switch ends the first seek
/// of `plan` (see the module docs): `None` for a plan that cannot reverse
/// (only the bidirectional switch and switch-then-marker plans can).
/// Compares a few legs, allocates nothing.
pub fn after_reversal(plan: &[Leg]) -> Option<&'static [Leg]> {
    [REV_SWITCH, REV_SWITCH_MARKER, REV_SWITCH_MARKER_CREEP]
        .into_iter()
        .find(|r| &r[REVERSAL_LEGS..] == plan)
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
        Some(StopAtLimit) => Phase::SeekStop,
        Some(Pass(_)) => Phase::Reverse,
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
    fn limit_plans_are_the_switch_plans_stopping_at_the_limit() {
        let with_limit_stop = |p: &[Leg]| {
            let mut v = p.to_vec();
            v[1] = StopAtLimit;
            v
        };
        let a = HomeMode::Active;
        for (limit, switch, creep) in [
            (S::LimitSwitch, S::Switch, false),
            (S::LimitSwitchThenMarker, S::SwitchThenMarker, false),
            (S::LimitSwitchThenMarker, S::SwitchThenMarker, true),
        ] {
            for d in [D::BidirectionalForward, D::BidirectionalReverse] {
                assert_eq!(
                    plan(limit, d, a, creep),
                    with_limit_stop(plan(switch, d, a, creep)).as_slice()
                );
            }
        }
        assert_eq!(find_at(LIMIT, 0), Find::Waypoint);
        assert_eq!(find_at(LIMIT, 2), Find::Event);
        assert_eq!(first_return(LIMIT), 2, "started on the limit: return leg");
        assert_eq!(phase_of(LIMIT, 1, false), Phase::SeekStop);
    }

    #[test]
    fn a_reversed_plan_is_the_reversal_then_the_whole_plan() {
        for p in [BI_SWITCH, BI_SWITCH_MARKER, BI_SWITCH_MARKER_CREEP] {
            let r = after_reversal(p).unwrap();
            assert_eq!(r[0], p[0], "leg 0 is the seek that met the limit");
            assert_eq!(
                r[1..REVERSAL_LEGS],
                [StopAtLimit, Pass(SwitchClear), Stop],
                "stop at the limit, back past the switch, stop"
            );
            assert_eq!(&r[REVERSAL_LEGS..], p);
            assert_eq!(find_at(r, 2), Find::Waypoint);
            assert_eq!(find_at(r, 4), Find::Waypoint);
            assert_eq!(phase_of(r, 2, false), Phase::Reverse);
            assert_eq!(r[first_return(r)], p[first_return(p)]);
            assert!(after_reversal(r).is_none(), "a reversal happens once");
        }
        for p in [LIMIT, BI_MARKER, TORQUE, UNI_SWITCH, PASSIVE_SWITCH] {
            assert!(after_reversal(p).is_none());
        }
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
