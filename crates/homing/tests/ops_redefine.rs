//! MRP / redefine position: only the raw → axis offset changes. Command
//! and feedback frames see no step, the soft limits stay on the machine
//! (their numbers shift), HomedStatus is kept; refusals change nothing;
//! cyclic positions wrap; a gantry side's redefine can be taken back.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;

fn by(d: f64) -> Operation {
    Operation::Redefine(RedefineSpec::by(d))
}

fn to(p: f64) -> Operation {
    Operation::Redefine(RedefineSpec::to(p))
}

/// Enabled, homed at 0 (immediate) and moved to 3.
fn homed_at_3() -> Rig {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    r.op(move_to(3.0)).unwrap();
    assert!(r.run_until(1000, |s| s.op.pc));
    r.run(5);
    r
}

#[test]
fn the_position_becomes_p_and_nothing_else_changes() {
    let mut r = homed_at_3();
    let before_cmd = *r.cmds.last().unwrap();
    let before_fb = r.fb;
    let id = r.op(to(100.0)).unwrap();
    let s = *r.axis.status();
    assert_eq!(
        (s.op.kind, s.op.pc, s.op.ip),
        (OpKind::Redefine, true, false)
    );
    assert_eq!(s.op.id, id);
    assert!(s.homed && s.pc && !s.er, "{s:?}");
    assert!((r.cmd_axis() - 100.0).abs() < 1e-12);
    assert!((r.axis.axis_position().unwrap() - 100.0).abs() < 1e-9);
    // The drive's command and its feedback are what they were.
    for _ in 0..20 {
        let c = r.step(Request::default());
        assert_eq!(c, before_cmd);
        assert_eq!(r.fb.position, before_fb.position);
    }
    assert_eq!(r.axis.raw_position(), Some(before_fb.position));
    assert_eq!(s.redefines, 1);
    assert!((s.shift - 97.0).abs() < 1e-12);
}

#[test]
fn soft_limits_stay_on_the_machine_and_their_numbers_shift() {
    let mut r = homed_at_3();
    assert_eq!(r.axis.status().soft_limits, Some((-10.0, 10.0)));
    r.op(by(5.0)).unwrap();
    r.step(Request::default());
    let s = *r.axis.status();
    assert!((r.cmd_axis() - 8.0).abs() < 1e-12);
    assert_eq!(s.soft_limits, Some((-5.0, 15.0)));
    // A move to the old number of the limit is fine now (machine 5 < 10).
    let outside = Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET));
    assert_eq!(r.op(move_to(15.001)), outside);
    assert_eq!(r.op(move_to(-5.001)), outside);
    // A jog into the positive limit stops on the same machine place: raw 10.
    r.op(jog(20.0)).unwrap();
    for _ in 0..2000 {
        r.step(Request {
            jog_renew: true,
            ..Request::default()
        });
        if !r.axis.status().jogging && r.axis.status().op.pc {
            break;
        }
    }
    let s = *r.axis.status();
    assert_eq!(s.last_stop, StopCause::SoftLimit, "{s:?}");
    assert!((r.cmds.last().unwrap().position - 10.0).abs() < 1e-9);
    assert!((r.cmd_axis() - 15.0).abs() < 1e-9);
    // A move to the limit's new number ends on the same machine place.
    r.op(move_to(-5.0)).unwrap();
    assert!(r.run_until(3000, |s| s.op.pc));
    assert!((r.cmds.last().unwrap().position + 10.0).abs() < 1e-9);
}

#[test]
fn a_setpoint_is_checked_against_the_shifted_limits() {
    let mut r = homed_at_3();
    r.op(by(-3.0)).unwrap();
    r.run(2);
    assert_eq!(r.axis.status().soft_limits, Some((-13.0, 7.0)));
    r.op(Operation::StreamStart).unwrap();
    // 7.5 was inside the configured limits and is outside the shifted ones.
    let t = r.now();
    r.setpoint(t, 0.0, None);
    r.setpoint(t + MS, 7.5, None);
    let s = *r.axis.status();
    assert_eq!(
        (s.err, s.exerr),
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_OUTSIDE_LIMITS)
    );
}

#[test]
fn refusals_change_nothing() {
    // Not homed.
    let mut r = Rig::at(2.0);
    r.enable();
    assert_eq!(
        r.op(by(1.0)),
        Err((ERR_REDEFINE_REFUSED, EX_REDEFINE_NOT_HOMED))
    );
    assert_eq!(r.axis.axis_position(), Some(2.0));
    // Jogging, moving, stopping.
    let mut r = homed_at_3();
    r.op(jog(5.0)).unwrap();
    assert_eq!(r.op(by(1.0)), Err((ERR_EXECUTION_COLLISION, EX_REDEFINE)));
    r.op(Operation::Stop).unwrap();
    assert!(r.axis.status().stopping);
    assert_eq!(r.op(by(1.0)), Err((ERR_EXECUTION_COLLISION, EX_REDEFINE)));
    assert!(r.run_until(1000, |s| !s.stopping && s.op.pc));
    r.op(move_to(0.0)).unwrap();
    assert_eq!(r.op(to(1.0)), Err((ERR_EXECUTION_COLLISION, EX_REDEFINE)));
    assert!(r.run_until(1000, |s| s.op.pc));
    // Streaming.
    r.op(Operation::StreamStart).unwrap();
    assert_eq!(r.op(by(1.0)), Err((ERR_EXECUTION_COLLISION, EX_REDEFINE)));
    r.op(Operation::StreamEnd).unwrap();
    assert!(r.run_until(1000, |s| !s.streaming && !s.stopping));
    // Not finite.
    assert_eq!(
        r.op(by(f64::NAN)),
        Err((ERR_REDEFINE_REFUSED, EX_REDEFINE_NOT_FINITE))
    );
    assert_eq!(
        r.op(to(f64::INFINITY)),
        Err((ERR_REDEFINE_REFUSED, EX_REDEFINE_NOT_FINITE))
    );
    assert_eq!(
        r.op(by(f64::MAX)),
        Err((ERR_REDEFINE_REFUSED, EX_REDEFINE_NOT_FINITE))
    );
    assert_eq!(r.axis.status().redefines, 0);
    assert!(r.cmd_axis().abs() < 1e-12);
    assert_eq!(r.axis.status().soft_limits, Some((-10.0, 10.0)));
    // Faulted: a refused setpoint leaves an axis fault.
    r.op(Operation::StreamStart).unwrap();
    let t = r.now();
    r.setpoint(t, f64::NAN, None);
    assert!(r.run_until(1000, |s| s.faulted && !s.stopping));
    assert_eq!(r.op(by(1.0)), Err((ERR_AXIS_FAULTED, EX_REDEFINE)));
}

#[test]
fn refused_while_homing() {
    let cfg = AxisConfig {
        home_sequence: HomeSequence::Switch,
        home_return_speed: 2.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, machine_at(-50.0));
    r.enable();
    r.step(home());
    assert!(r.axis.status().ip);
    let refused = r.op(by(1.0));
    assert_eq!(refused, Err((ERR_HOME_IN_PROCESS, EX_REDEFINE)));
}

#[test]
fn homing_again_forgets_the_shift() {
    let mut r = homed_at_3();
    r.op(by(5.0)).unwrap();
    r.step(Request::default());
    assert_eq!(r.axis.status().soft_limits, Some((-5.0, 15.0)));
    r.step(home());
    r.step(Request::default());
    let s = *r.axis.status();
    assert!(s.homed && s.pc);
    assert_eq!(s.shift, 0.0);
    assert_eq!(s.soft_limits, Some((-10.0, 10.0)));
    // Immediate: home position 0 where it stands; the drift reference is the
    // homing's, not the redefined one.
    assert!(r.cmd_axis().abs() < 1e-9);
    assert_eq!(s.prior_offset, Some(0.0), "{s:?}");
    assert_eq!(s.redefines, 1);
}

#[test]
fn cyclic_positions_wrap_into_the_unwind() {
    let cfg = AxisConfig {
        travel: TravelMode::Cyclic,
        unwind: 360.0,
        travel_limits: None,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(10.0));
    r.enable_and_home();
    assert!(r.cmd_axis().abs() < 1e-12);
    r.op(to(370.0)).unwrap();
    assert!((r.cmd_axis() - 10.0).abs() < 1e-9, "{}", r.cmd_axis());
    r.op(by(-20.0)).unwrap();
    assert!((r.cmd_axis() - 350.0).abs() < 1e-9, "{}", r.cmd_axis());
    r.op(by(725.0)).unwrap();
    assert!((r.cmd_axis() - 355.0).abs() < 1e-9, "{}", r.cmd_axis());
    r.op(to(-1.0)).unwrap();
    assert!((r.cmd_axis() - 359.0).abs() < 1e-9, "{}", r.cmd_axis());
    // The shift is kept within one revolution.
    assert!(r.axis.status().shift.abs() < 4.0 * 360.0);
    let p = r.axis.axis_position().unwrap();
    assert!((0.0..360.0).contains(&p), "{p}");
    // Nothing moved: the raw position is where homing left it.
    assert_eq!(r.axis.raw_position(), Some(10.0));
    // A move to an absolute position goes the shortest way in the new frame.
    r.op(move_to(1.0)).unwrap();
    assert!(r.run_until(2000, |s| s.op.pc));
    assert!((r.cmd_axis() - 1.0).abs() < 1e-9);
    assert!((r.cmds.last().unwrap().position - 12.0).abs() < 1e-9);
}

#[test]
fn a_gantry_sides_redefine_is_taken_back_whole() {
    let mut a = homed_at_3();
    let cmd = *a.cmds.last().unwrap();
    let shift = a.axis.redefine_shift(&RedefineSpec::to(50.0)).unwrap();
    assert!((shift - 47.0).abs() < 1e-12);
    // Pure: asking changed nothing.
    assert!((a.cmd_axis() - 3.0).abs() < 1e-12);
    let id = a.op(by(shift)).unwrap();
    assert!((a.cmd_axis() - 50.0).abs() < 1e-12);
    assert!(a.axis.take_back_redefine(id));
    assert!(!a.axis.take_back_redefine(id));
    let s = *a.axis.status();
    assert!((a.axis.to_axis(cmd.position) - 3.0).abs() < 1e-12);
    assert_eq!((s.shift, s.redefines, s.op.pc), (0.0, 0, false));
    assert_eq!(s.soft_limits, Some((-10.0, 10.0)));
    assert_eq!(a.step(Request::default()), cmd);
}

#[test]
fn a_restored_reference_keeps_its_shift() {
    let cfg = AxisConfig {
        absolute: true,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(3.0));
    r.enable_and_home();
    r.op(by(5.0)).unwrap();
    let (offset, shift) = (
        r.axis.reference_offset().unwrap(),
        r.axis.reference_shift().unwrap(),
    );
    assert_eq!((offset, shift), (2.0, 5.0));
    // A new engine (a restart) on the same raw position.
    let mut b = Rig::new(cfg, op_plant(3.0));
    b.run(2);
    let now = b.now() - MS;
    b.axis.restore_reference(now, offset, shift).unwrap();
    b.step(Request::default());
    assert_eq!(b.axis.axis_position(), Some(5.0));
    assert_eq!(b.axis.status().soft_limits, Some((-5.0, 15.0)));
    // The travel-limit check of a restore is on the machine too: raw 3 with
    // offset -10 is axis -7, inside the configured [-10, 10] but outside
    // the shifted [-5, 15].
    let mut c = Rig::new(cfg, op_plant(3.0));
    c.run(2);
    let now = c.now() - MS;
    assert!(matches!(
        c.axis.restore_reference(now, -10.0, 5.0),
        Err(RestoreRefusal::OutsideTravelLimits { .. })
    ));
}
