//! MAM against the plant: trapezoids that land exactly, software overtravel
//! of targets, supersede, lost feedback mid-move, cyclic axes.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;

const CYCLE_S: f64 = 0.001;

#[test]
fn a_move_lands_exactly_on_its_target_with_pc() {
    // 0 → 5 at 20 u/s, 500 u/s² both ways: 0.04 s up (0.4), 0.04 s down
    // (0.4), cruise 4.2 / 20 = 0.21 s: 0.29 s in all.
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let id = r.op(move_to(5.0)).unwrap();
    let from = r.k - 1;
    assert!(r.axis.status().moving && r.axis.status().op.ip);
    assert!(r.run_until(1000, |s| !s.moving));
    let s = *r.axis.status();
    assert_eq!(
        (s.op.id, s.op.kind, s.op.pc, s.op.ip),
        (id, OpKind::Move, true, false)
    );
    assert!(!s.er && s.last_stop == StopCause::None, "{s:?}");
    assert_eq!(r.cmd_axis(), 5.0);
    let took = r.k - 1 - from;
    assert!((289..=291).contains(&took), "{took} cycles");
    let cmds = r.since(from);
    assert!(max_speed(cmds, CYCLE_S) <= 20.0 + 1e-6);
    assert!(max_accel(cmds, CYCLE_S) <= 500.0 + 1e-3);
    assert!(cmds.windows(2).all(|w| w[1].position >= w[0].position));
    // Relative: +2 from the command position.
    r.op(Operation::Move(MoveSpec {
        relative: true,
        ..move_spec(2.0)
    }))
    .unwrap();
    assert!(r.run_until(1000, |s| s.op.pc));
    assert!((r.cmd_axis() - 7.0).abs() < 1e-12);
    r.run(3);
    assert!((r.plant.position() - 7.0).abs() < 1e-12);
}

#[test]
fn targets_outside_the_travel_limits_are_refused_while_homed() {
    let target = Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET));
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    assert_eq!(r.op(move_to(10.001)), target);
    assert_eq!(r.op(move_to(-11.0)), target);
    let by = |d: f64| {
        Operation::Move(MoveSpec {
            relative: true,
            ..move_spec(d)
        })
    };
    assert_eq!(r.op(by(10.5)), target);
    assert_eq!(r.op(by(1e308)), target);
    assert_eq!(
        r.op(move_to(f64::NAN)),
        Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_NOT_FINITE))
    );
    assert_eq!(
        r.op(by(f64::INFINITY)),
        Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_NOT_FINITE))
    );
    // On the limit: allowed.
    assert!(r.op(move_to(10.0)).is_ok());
    assert!(r.run_until(1000, |s| s.op.pc));
    assert_eq!(r.cmd_axis(), 10.0);
    // Not homed: the soft limits do not apply (no reference), max_position does.
    assert!(r.axis.clear_homed());
    assert!(r.op(move_to(11.0)).is_ok());
    assert!(r.run_until(1000, |s| s.op.pc));
    assert!((r.cmd_axis() - 11.0).abs() < 1e-12);
    assert_eq!(r.op(move_to(2e9)), target, "beyond max_position");
}

#[test]
fn a_move_on_a_jogging_or_moving_axis_needs_supersede() {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    r.op(jog(10.0)).unwrap();
    r.run(50);
    assert_eq!(r.op(move_to(-5.0)), Err((ERR_EXECUTION_COLLISION, 0)));
    assert!(r.axis.status().jogging);
    let sup = Operation::Move(MoveSpec {
        supersede: true,
        ..move_spec(-5.0)
    });
    let id = r.op(sup).unwrap();
    assert!(r.axis.status().moving && !r.axis.status().jogging);
    // It reverses with its deceleration: no jump.
    assert!(r.run_until(2000, |s| s.op.pc));
    assert_eq!(r.axis.status().op.id, id);
    assert_eq!(r.cmd_axis(), -5.0);
    assert!(max_accel(&r.cmds, CYCLE_S) <= 500.0 + 1e-3);
    // A move superseding a move.
    r.op(move_to(5.0)).unwrap();
    r.run(100);
    assert_eq!(r.op(move_to(0.0)), Err((ERR_EXECUTION_COLLISION, 0)));
    let Operation::Move(sup) = sup else {
        unreachable!()
    };
    r.op(Operation::Move(MoveSpec { target: 0.0, ..sup }))
        .unwrap();
    assert!(r.run_until(2000, |s| s.op.pc));
    assert_eq!(r.cmd_axis(), 0.0);
}

#[test]
fn a_supersede_that_could_not_stop_inside_the_limits_is_refused() {
    // Jogging +40 with deceleration 2000 (max_deceleration 2000): the jog
    // plans its stop at 10 from 40² / (2·2000) = 0.4 before it. At 9.4,
    // still at 40, a move back to 0 with deceleration 500 would first need
    // 40² / (2·500) = 1.6 to stop: 11.0, past the limit. Refused 13/4; the
    // jog goes on and ends on 10.
    let cfg = AxisConfig {
        max_deceleration: 2000.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    r.op(Operation::Jog(JogSpec {
        speed: 40.0,
        accel: Some(2000.0),
        decel: Some(2000.0),
        lease: Some(secs(5_000 * MS)),
        jerk: None,
    }))
    .unwrap();
    while r.cmd_axis() < 9.4 {
        r.run(1);
    }
    let back = Operation::Move(MoveSpec {
        supersede: true,
        ..move_spec(0.0)
    });
    assert_eq!(
        r.op(back),
        Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET))
    );
    assert!(r.run_until(1000, |s| !s.jogging));
    assert_eq!(r.cmd_axis(), 10.0);
    assert!(r.cmds.iter().all(|c| r.axis.to_axis(c.position) <= 10.0));
}

#[test]
fn lost_feedback_mid_move_is_an_axis_fault_stopped_at_max_deceleration() {
    // Frames withheld from step 150 on: steps 150..=159 fill the
    // feedback-loss bucket to exactly 10 ms, step 160 goes above it; ER 12/40, faulted, the move ends without PC and
    // the axis stops at max_deceleration 500 from 20 u/s: 0.4 further.
    let mut r = Rig::at(0.0);
    r.frame = |k, fb| (k < 150).then_some(fb);
    r.enable_and_home();
    let id = r.op(move_to(-9.0)).unwrap();
    assert!(r.run_until(1000, |s| s.faulted));
    let s = *r.axis.status();
    assert_eq!(
        (s.er, s.err, s.exerr),
        (true, 12, EX_FEEDBACK_LOST),
        "{s:?}"
    );
    assert_eq!(r.k - 1, 160);
    assert_eq!(s.last_stop, StopCause::FeedbackLost);
    assert_eq!((s.op.id, s.op.ip, s.op.pc), (id, false, false));
    assert!(!s.moving && s.stopping);
    let at = r.cmds.last().unwrap().position;
    let v = (at - r.cmds[r.cmds.len() - 2].position) / CYCLE_S;
    assert!((v + 20.0).abs() < 1.0, "still at speed: {v}");
    assert!(r.run_until(200, |s| !s.stopping));
    // Cruising at −20 (the move is 153 ms in: past its 40 ms of
    // acceleration, far from its deceleration): 20² / (2·500) = 0.4 on.
    let end = r.cmds.last().unwrap().position;
    assert!((end - (at - 0.4)).abs() < 1e-9, "{end} vs {at}");
    // Faulted: everything but reset, stop, disable refused.
    assert_eq!(r.op(move_to(0.0)), Err((ERR_AXIS_FAULTED, 0)));
}

#[test]
fn cyclic_axes_move_the_shortest_way_and_have_no_travel_limits() {
    let cfg = AxisConfig {
        travel: TravelMode::Cyclic,
        unwind: 360.0,
        travel_limits: None,
        home_speed: 100.0,
        max_speed: 200.0,
        home_acceleration: 5000.0,
        home_deceleration: 5000.0,
        home_position: 10.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    assert_eq!(r.axis.axis_position(), Some(10.0));
    // 10 → 350: backwards through 0 (20 degrees), not forwards (340).
    // At 100 u/s, accelerations 5000.
    let brisk = |target: f64, relative: bool| {
        Operation::Move(MoveSpec {
            relative,
            speed: Some(100.0),
            accel: Some(5000.0),
            decel: Some(5000.0),
            ..move_spec(target)
        })
    };
    let m = brisk(350.0, false);
    r.op(m).unwrap();
    assert!(r.run_until(1000, |s| s.op.pc));
    assert_eq!(r.cmds.last().unwrap().position, -20.0);
    assert_eq!(r.cmd_axis(), 350.0);
    // Relative: whole revolutions.
    r.op(brisk(720.0, true)).unwrap();
    assert!(r.run_until(20_000, |s| s.op.pc));
    assert_eq!(r.cmds.last().unwrap().position, 700.0);
    // Jogs run on, homed, without any limit.
    r.op(Operation::Jog(JogSpec {
        speed: 100.0,
        accel: Some(5000.0),
        decel: Some(5000.0),
        lease: Some(secs(5_000 * MS)),
        jerk: None,
    }))
    .unwrap();
    r.run(4000);
    assert!(r.axis.status().jogging && r.axis.status().homed);
    assert!(r.cmds.last().unwrap().position > 1000.0);
}

#[test]
fn without_a_speed_bound_nothing_moves_but_homing_still_works() {
    // No max_speed and an immediate homing, which derives none: homed, a
    // move at 1e6 u/s would be taken at its word. Jog, move and stream are
    // refused, naming max_speed (13 / 7); homing works as before.
    let cfg = AxisConfig {
        max_speed: 0.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    let none = Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_NO_MAX_SPEED));
    let fast = Operation::Move(MoveSpec {
        speed: Some(1e6),
        accel: Some(1e9),
        ..move_spec(5.0)
    });
    assert_eq!(r.op(fast), none);
    assert_eq!(r.op(move_to(5.0)), none);
    assert_eq!(r.op(jog(1.0)), none);
    assert_eq!(r.op(Operation::StreamStart), none);
    assert!(r.cmds.iter().all(|c| c.position == 0.0));
    // Unhomed too (the unhomed cap is not a bound of its own).
    assert!(r.axis.clear_homed());
    assert_eq!(r.op(jog(1.0)), none);
    // Homing still works.
    r.step(home());
    r.step(Request::default());
    assert!(r.axis.status().homed && r.axis.status().pc);
}
