//! The simulated limit switches (`[axis.sim] limit_switches`, old spelling
//! `overtravel`, `limit_switches_normally_closed`) and what they must be for
//! an axis that homes on one or reverses at one.
//!
//! `limit_switches = [lo, hi]`: the negative switch is actuated at or below
//! `lo`, the positive one at or above `hi`. `overtravel = [lo, hi]` is still
//! read, with the same (new) rule: its ends used to trip only strictly
//! beyond them; now a switch is actuated at its end, as the home switch is
//! at the ends of its interval. Giving both is a problem.

use crate::keys::Reader;
use crate::keytable::sim::{LIMIT_SWITCHES, OVERTRAVEL};
use crate::Problem;
use motion_homing::AxisConfig;
use motion_plant::{PlantConfig, RegistrationInput};

/// `limit_switches`, else `overtravel`.
pub(crate) fn read(r: &mut Reader<'_>) -> Option<(f64, f64)> {
    let new = r.has(&LIMIT_SWITCHES);
    let old = r.has(&OVERTRAVEL);
    if new && old {
        r.problem(
            &OVERTRAVEL,
            "given together with limit_switches, which replaces it: keep limit_switches".into(),
        );
    }
    let key = if old && !new {
        &OVERTRAVEL
    } else {
        &LIMIT_SWITCHES
    };
    let limits = r.interval(key);
    r.mark_used(&OVERTRAVEL);
    limits
}

/// Where the sim wires the drive's registration (probe) input: to the
/// axis's reference switch — the limit switch in Home Direction for the
/// limit-switch sequences, the home switch otherwise (as a machine builder
/// wires a drive's probe input to the switch the axis homes on).
pub(crate) fn registration_input(engine: &AxisConfig) -> RegistrationInput {
    if !engine.home_sequence.uses_limit_switch() {
        RegistrationInput::HomeSwitch
    } else if engine.home_direction.sign() > 0.0 {
        RegistrationInput::PositiveLimit
    } else {
        RegistrationInput::NegativeLimit
    }
}

/// An axis on the `sim` backend that homes on a limit switch or reverses
/// at one has simulated limit switches, the one in Home Direction at least
/// a seek's stopping distance before its hard stop (the seek stops on the switch: at Home
/// Speed V it runs V²/2D past the switch's end, plus up to two cycles of
/// travel until it sees the switch and commands the stop).
pub(crate) fn check_sim(
    axis: &str,
    engine: &AxisConfig,
    sim: &PlantConfig,
    cycle_s: f64,
    problems: &mut Vec<Problem>,
) {
    let homes_on_limit = engine.home_sequence.uses_limit_switch();
    if !(homes_on_limit || engine.home_reverse_at_limit) || !engine.limit_switches {
        return;
    }
    let why = if homes_on_limit {
        format!(
            "the axis homes on a limit switch ({})",
            engine.home_sequence
        )
    } else {
        "the axis reverses at a limit switch (home_reverse_at_limit)".to_string()
    };
    let Some((lo, hi)) = sim.overtravel else {
        problems.push(Problem::new(
            Some(axis),
            "sim.limit_switches",
            format!("missing: {why}, and the simulated plant has none"),
        ));
        return;
    };
    let (v, d) = (engine.home_speed, engine.home_deceleration);
    if !(v > 0.0 && d > 0.0) {
        return;
    }
    let needed = v * v / (2.0 * d) + 2.0 * v * cycle_s;
    let Some((stop_lo, stop_hi)) = sim.hard_stop else {
        return;
    };
    let (side, room) = if engine.home_direction.sign() > 0.0 {
        ("positive", stop_hi - hi)
    } else {
        ("negative", lo - stop_lo)
    };
    if room < needed {
        problems.push(Problem::new(
            Some(axis),
            "sim.limit_switches",
            format!(
                "the {side} limit switch ends {room:.3} units before the hard stop; a seek at \
                 home_speed stops up to {needed:.3} units past it ({why})"
            ),
        ));
    }
}
