//! Switch then marker with the marker too close to the switch edge.
//!
//! Machine: switch [0, 5]; markers every 10, one just outside the switch:
//! at -0.1 (bidirectional forward: the return clears the edge at 0 going
//! reverse, the first marker beyond it is -0.1) or at 0.1 (unidirectional
//! and passive forward: detected at 0, the first marker after it is 0.1).
//! Either way the marker lies 0.1 from the edge, give or take the edge's
//! sampling error (R x T / 2 = 0.001 on the return, V x T / 2 = 0.01 on a
//! unidirectional seek, 5 x T / 2 = 0.0025 passive at 5 u/s).

mod common;

use common::run;
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::PlantConfig;

const T: f64 = 0.001;

fn stm(dir: HomeDirection, min: f64, refuse: bool) -> AxisConfig {
    AxisConfig {
        marker_min_distance: min,
        refuse_ambiguous_marker: refuse,
        ..common::axis(HomeSequence::SwitchThenMarker, dir)
    }
}

fn machine(marker_at: f64) -> PlantConfig {
    PlantConfig {
        marker_at,
        ..common::machine()
    }
}

#[test]
fn a_close_marker_is_a_warning_and_homing_completes() {
    let o = run(
        stm(HomeDirection::BidirectionalForward, 0.5, false),
        machine(-0.1),
        T,
        60.0,
    );
    let s = o.status;
    assert!(s.pc && s.homed && s.ambiguous_marker, "{s:?}");
    assert_eq!(s.event_raw, Some(-0.1));
    assert!(s.switch_edge_raw.unwrap().abs() <= 0.001 + 1e-9);
    assert!((o.final_raw - -0.1).abs() < 1e-9);
}

#[test]
fn a_close_marker_is_refused_when_configured() {
    let o = run(
        stm(HomeDirection::BidirectionalForward, 0.5, true),
        machine(-0.1),
        T,
        60.0,
    );
    let s = o.status;
    assert!(
        s.er && s.dn && !s.ip && !s.pc && !s.homed && s.ambiguous_marker,
        "{s:?}"
    );
    assert_eq!((s.err, s.exerr), (ERR_AMBIGUOUS_MARKER, 0));
    assert_eq!(s.event_raw, None, "the reference was not taken");
    assert_eq!(o.commands.last().unwrap().velocity, 0.0, "stopped");
    // Stopped from R = 2 at 500 u/s²: R² / 2D = 0.004 past the marker, plus
    // up to two cycles of travel (0.004) before the stop began.
    assert!(
        (-0.108 - 1e-9..=-0.104 + 1e-9).contains(&o.final_raw),
        "{}",
        o.final_raw
    );
}

#[test]
fn a_marker_far_enough_is_not_flagged() {
    // 0.1 - 0.001 (edge error) is still above 0.09; and the check is off at 0.
    for min in [0.09, 0.0] {
        let o = run(
            stm(HomeDirection::BidirectionalForward, min, true),
            machine(-0.1),
            T,
            60.0,
        );
        assert!(
            o.status.pc && !o.status.ambiguous_marker,
            "{min}: {:?}",
            o.status
        );
    }
    // The usual machine: the marker -7.5 lies 7.5 from the edge.
    let o = run(
        stm(HomeDirection::BidirectionalForward, 0.5, true),
        machine(2.5),
        T,
        60.0,
    );
    assert!(o.status.pc && !o.status.ambiguous_marker);
    assert_eq!(o.status.event_raw, Some(-7.5));
}

#[test]
fn unidirectional_passive_and_creep_sequences_are_checked_too() {
    let o = run(
        stm(HomeDirection::UnidirectionalForward, 0.5, false),
        machine(0.1),
        T,
        60.0,
    );
    assert!(
        o.status.homed && o.status.ambiguous_marker,
        "{:?}",
        o.status
    );
    assert_eq!(o.status.event_raw, Some(0.1));

    let passive = AxisConfig {
        configuration: AxisConfiguration::FeedbackOnly,
        home_mode: HomeMode::Passive,
        ..stm(HomeDirection::BidirectionalForward, 0.5, true)
    };
    let plant = PlantConfig {
        start: -3.0,
        external_speed: 5.0,
        ..machine(0.1)
    };
    let o = run(passive, plant, T, 60.0);
    assert_eq!((o.status.err, o.status.exerr), (ERR_AMBIGUOUS_MARKER, 0));

    // No marker latch, creep 0.5: the crept marker (-0.1 within 0.5 x T / 2)
    // is the one checked against the edge.
    let creep = AxisConfig {
        marker_latch: false,
        home_creep_speed: 0.5,
        ..stm(HomeDirection::BidirectionalForward, 0.5, false)
    };
    let o = run(creep, machine(-0.1), T, 60.0);
    assert!(o.status.pc && o.status.ambiguous_marker, "{:?}", o.status);
    assert!((o.status.event_raw.unwrap() - -0.1).abs() <= 0.5 * T / 2.0 + 1e-9);
}

#[test]
fn marker_min_distance_is_validated() {
    let c = AxisConfig {
        marker_min_distance: -1.0,
        ..stm(HomeDirection::BidirectionalForward, 0.0, false)
    };
    let e: Vec<(&str, u16)> = validate(&c)
        .iter()
        .map(|e| (e.attribute, e.exerr))
        .collect();
    assert_eq!(e, [("marker_min_distance", EX_BAD_NUMBER)]);
}
