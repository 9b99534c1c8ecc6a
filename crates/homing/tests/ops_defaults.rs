//! What a client leaves out of an operation is filled from the axis's own
//! configuration, in the engine, as the operation arrives: a move or jog
//! without dynamics runs exactly as one given `home_speed`,
//! `home_acceleration` and `home_deceleration`; a jog without a lease
//! holds 0.5 s; with no default configured, the number left out is
//! refused like a bad one (13).

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;

/// Commands of a move from 0 to 5 given by `spec`, until it is done.
fn move_commands(spec: MoveSpec) -> Vec<f64> {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let from = r.k;
    r.op(Operation::Move(spec)).unwrap();
    assert!(r.run_until(5000, |s| s.op.pc));
    r.since(from).iter().map(|c| c.position).collect()
}

#[test]
fn a_move_left_at_its_defaults_is_the_move_with_the_homing_dynamics() {
    let explicit = MoveSpec {
        speed: Some(20.0),
        accel: Some(500.0),
        decel: Some(500.0),
        ..MoveSpec::to(5.0)
    };
    let defaulted = move_commands(MoveSpec::to(5.0));
    assert_eq!(defaulted, move_commands(explicit));
    // Given ones win over the defaults.
    let slower = move_commands(MoveSpec {
        speed: Some(5.0),
        ..MoveSpec::to(5.0)
    });
    assert!(slower.len() > defaulted.len() + 500, "{}", slower.len());
}

#[test]
fn a_jog_without_a_lease_holds_half_a_second() {
    let mut r = Rig::at(0.0);
    r.enable();
    let id = r.op(Operation::Jog(JogSpec::at(2.0))).unwrap();
    // Unrenewed: running at 499 ms, stopping at 501 ms.
    r.run(498);
    assert!(r.axis.status().jogging);
    r.run(3);
    let s = *r.axis.status();
    assert!(
        !s.jogging && s.last_stop == StopCause::LeaseExpired,
        "{s:?}"
    );
    assert_eq!(s.op.id, id);
}

#[test]
fn a_number_left_out_without_a_default_is_refused_like_a_bad_one() {
    let cfg = AxisConfig {
        home_speed: 0.0,
        max_speed: 50.0,
        unhomed_speed: 10.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable();
    assert_eq!(
        r.op(Operation::Move(MoveSpec::to(1.0))),
        Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_SPEED))
    );
    let given = MoveSpec {
        speed: Some(2.0),
        ..MoveSpec::to(1.0)
    };
    assert!(r.op(Operation::Move(given)).is_ok());
}

#[test]
fn a_lease_outside_its_bounds_is_refused() {
    let mut r = Rig::at(0.0);
    r.enable();
    for lease in [0.01, 6.0, f64::NAN, -1.0, f64::INFINITY] {
        let jog = JogSpec {
            lease: Some(lease),
            ..JogSpec::at(1.0)
        };
        assert_eq!(
            r.op(Operation::Jog(jog)),
            Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_LEASE)),
            "{lease}"
        );
    }
}
