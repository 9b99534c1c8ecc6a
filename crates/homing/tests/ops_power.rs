//! MSO, MSF, MAFR and the drive's faults against the plant: enable holds
//! the actual position, enable timeout, disable stops first, a drive fault
//! (at rest, mid-jog, mid-homing) needs a reset — which pulses
//! `Command::fault_reset` and never enables — and the power stage never
//! comes back on by itself.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::PlantConfig;

#[test]
fn enable_holds_the_actual_position_and_reports_servo_action() {
    let mut r = Rig::at(3.7);
    r.run(3);
    let id = r.op(Operation::Enable).unwrap();
    let s = r.axis.status();
    assert!(s.op.ip && !s.servo_action, "{s:?}");
    assert!(r.run_until(10, |s| s.servo_action));
    let s = *r.axis.status();
    assert_eq!((s.op.id, s.op.kind, s.op.pc), (id, OpKind::Enable, true));
    // No jump: every command holds where the axis stood.
    assert!(r
        .cmds
        .iter()
        .all(|c| c.position == 3.7 && c.velocity == 0.0));
    assert!(r.cmds.last().unwrap().enable);
    assert_eq!(r.plant.position(), 3.7);
    // Again: nothing to do, complete at once.
    let again = r.op(Operation::Enable).unwrap();
    assert_eq!(
        r.axis.status().op,
        OpStatus {
            id: again,
            kind: OpKind::Enable,
            ip: false,
            pc: true,
            refused: None,
        }
    );
}

#[test]
fn a_drive_that_does_not_enable_is_an_axis_fault_after_enable_timeout() {
    // enable_timeout 1 s; the plant never enables.
    let plant = PlantConfig {
        enable_delay_cycles: 100_000,
        ..op_plant(0.0)
    };
    let mut r = Rig::new(op_axis(), plant);
    r.run(1);
    let id = r.op(Operation::Enable).unwrap();
    let from = r.k - 1;
    assert!(r.run_until(2000, |s| s.faulted));
    assert_eq!(r.k - 1 - from, 1001, "the first step after 1 s");
    let s = *r.axis.status();
    assert_eq!((s.er, s.err, s.exerr), (true, 12, EX_ENABLE_TIMEOUT));
    assert_eq!((s.op.id, s.op.ip, s.op.pc), (id, false, false));
    assert!(!r.cmds.last().unwrap().enable, "the request is withdrawn");
}

#[test]
fn disable_stops_a_jog_first_then_switches_off() {
    // Unhomed jog at 10, deceleration 500: 10² / (2·500) = 0.1 to stop.
    let mut r = Rig::at(0.0);
    r.enable();
    r.op(jog(10.0)).unwrap();
    r.run(100);
    let id = r.op(Operation::Disable).unwrap();
    let at = r.cmds.last().unwrap().position;
    assert!(r.cmds.last().unwrap().enable, "still on while it stops");
    assert!(r.axis.status().stopping && r.axis.status().op.ip);
    assert!(r.run_until(100, |s| s.op.pc));
    let s = *r.axis.status();
    assert_eq!((s.op.id, s.op.kind), (id, OpKind::Disable));
    assert!(!r.cmds.last().unwrap().enable && !s.servo_action);
    let end = r.cmds.last().unwrap().position;
    assert!((end - (at + 0.1)).abs() < 1e-9, "{end} vs {at}");
    assert_eq!(s.last_stop, StopCause::Disable);
    assert!(!s.er && !s.faulted);
    // At rest it is immediate.
    let mut r = Rig::at(0.0);
    r.enable();
    r.op(Operation::Disable).unwrap();
    assert!(r.axis.status().op.pc && !r.cmds.last().unwrap().enable);
    // Nothing moves a disabled axis.
    assert_eq!(r.op(jog(1.0)), Err((ERR_SERVO_OFF, 0)));
}

#[test]
fn disable_aborts_homing_with_12_1_then_switches_off() {
    let cfg = AxisConfig {
        max_speed: 50.0,
        ..axis(HomeSequence::Switch, HomeDirection::BidirectionalForward)
    };
    let mut r = Rig::new(cfg, machine());
    r.step(home());
    assert!(r.run_until(100, |s| s.phase == Phase::Seek));
    r.run(100);
    let id = r.op(Operation::Disable).unwrap();
    let s = *r.axis.status();
    assert_eq!((s.er, s.err, s.exerr, s.ip), (true, 12, 1, false), "{s:?}");
    assert!(r.cmds.last().unwrap().enable, "decelerating first");
    assert!(r.run_until(200, |s| s.op.pc));
    assert_eq!(r.axis.status().op.id, id);
    assert!(!r.cmds.last().unwrap().enable);
    assert_eq!(r.axis.status().phase, Phase::Idle);
}

#[test]
fn a_drive_fault_mid_jog_needs_a_reset_that_never_enables() {
    // Unhomed jog; the drive faults at step 150: the next frame shows it.
    let mut r = Rig::at(0.0);
    r.enable();
    let jog_id = r.op(jog(10.0)).unwrap();
    while r.k < 150 {
        r.run(1);
    }
    r.plant.inject_fault();
    // The next frame shows it.
    r.fb = r.plant.feedback();
    r.run(1);
    let s = *r.axis.status();
    assert_eq!((s.er, s.err, s.exerr), (true, 12, EX_DRIVE_FAULT), "{s:?}");
    assert!(s.faulted && !s.jogging && !s.servo_action);
    assert_eq!(s.last_stop, StopCause::DriveFault);
    assert_eq!((s.op.id, s.op.ip, s.op.pc), (jog_id, false, false));
    let cmd = *r.cmds.last().unwrap();
    assert!(!cmd.enable && cmd.velocity == 0.0, "off, holding: {cmd:?}");
    // Everything but reset, stop, disable is refused: ERR 20.
    let faulted = Err((ERR_AXIS_FAULTED, 0));
    assert_eq!(r.op(jog(-1.0)), faulted);
    assert_eq!(r.op(move_to(0.0)), faulted);
    assert_eq!(r.op(Operation::Enable), faulted);
    assert_eq!(r.op(Operation::StreamStart), faulted);
    r.step(home());
    let s = *r.axis.status();
    assert_eq!(
        (s.er, s.err, s.ip),
        (true, ERR_AXIS_FAULTED, false),
        "{s:?}"
    );
    r.step(Request::default());
    assert!(r.op(Operation::Stop).is_ok());
    assert!(r.op(Operation::Disable).is_ok());
    // Reset: ER cleared at once; fault_reset set for at least three
    // commands and until the drive reports no fault; nothing enabled.
    let id = r.op(Operation::Reset).unwrap();
    let from = r.k - 1;
    let s = *r.axis.status();
    assert!(!s.er && !s.faulted && s.err == 0 && s.op.ip, "{s:?}");
    assert!(r.run_until(50, |s| !s.op.ip));
    let s = *r.axis.status();
    assert_eq!((s.op.id, s.op.pc), (id, true));
    let pulses: Vec<bool> = r.since(from).iter().map(|c| c.fault_reset).collect();
    assert_eq!(pulses, [true, true, true, false], "{pulses:?}");
    assert!(r.since(from).iter().all(|c| !c.enable));
    assert!(!r.fb.drive.fault && !r.fb.drive.enabled, "{:?}", r.fb.drive);
    // Then enable and jog as before.
    r.enable();
    assert!(r.op(jog(-1.0)).is_ok());
}

#[test]
fn a_fault_that_persists_comes_back_after_the_reset_window() {
    // Every frame claims a drive fault (a wire break the reset cannot cure).
    let mut r = Rig::at(0.0);
    r.frame = |_, mut fb| {
        fb.drive.fault = true;
        fb.drive.enabled = false;
        Some(fb)
    };
    r.run(2);
    let s = *r.axis.status();
    assert!(
        s.faulted && s.er && s.exerr == EX_DRIVE_FAULT,
        "at rest too: {s:?}"
    );
    let id = r.op(Operation::Reset).unwrap();
    let from = r.k - 1;
    assert!(!r.axis.status().faulted, "cleared until the window ends");
    assert!(r.run_until(2000, |s| s.faulted));
    // enable_timeout = 1 s: fault_reset held for the whole window.
    let held = r.since(from).iter().filter(|c| c.fault_reset).count();
    assert_eq!(held, 1001);
    let s = *r.axis.status();
    assert_eq!((s.op.id, s.op.ip, s.op.pc), (id, false, false));
    assert_eq!((s.err, s.exerr), (12, EX_DRIVE_FAULT));
}

#[test]
fn a_drive_fault_during_homing_needs_a_reset_before_the_next_homing() {
    // Changed by issue 15: homing used to reset the fault itself (by
    // toggling the enable); a faulted axis now refuses to home (ERR 20).
    let cfg = AxisConfig {
        max_speed: 50.0,
        ..axis(HomeSequence::Switch, HomeDirection::BidirectionalForward)
    };
    let mut r = Rig::new(cfg, machine());
    r.step(home());
    assert!(r.run_until(100, |s| s.phase == Phase::Seek));
    r.run(50);
    r.plant.inject_fault();
    r.fb = r.plant.feedback();
    r.run(1);
    let s = *r.axis.status();
    assert_eq!((s.err, s.exerr), (12, EX_DRIVE_FAULT));
    assert!(s.faulted && !s.ip);
    r.step(Request::default());
    r.step(home());
    assert_eq!(r.axis.status().err, ERR_AXIS_FAULTED);
    assert!(!r.axis.status().ip);
    r.step(Request::default());
    r.op(Operation::Reset).unwrap();
    r.run(5);
    r.step(home());
    assert!(r.axis.status().ip);
    assert!(r.run_until(60_000, |s| !s.ip));
    assert!(r.axis.status().pc, "{:?}", r.axis.status());
}

#[test]
fn a_drive_that_drops_its_power_stage_is_not_switched_on_again() {
    // From step 20 the drive reports disabled (no fault): STO, a power
    // return. The engine withdraws its request and never raises it again.
    let mut r = Rig::at(0.0);
    r.frame = |k, mut fb| {
        if k >= 20 {
            fb.drive.enabled = false;
        }
        Some(fb)
    };
    r.enable();
    r.run(30);
    let s = *r.axis.status();
    assert!(!s.servo_action && !s.er && !s.faulted, "{s:?}");
    assert!(r.cmds[25..].iter().all(|c| !c.enable));
    // In motion it is an axis fault.
    let mut r = Rig::at(0.0);
    r.frame = |k, mut fb| {
        if k >= 100 {
            fb.drive.enabled = false;
        }
        Some(fb)
    };
    r.enable();
    r.op(jog(5.0)).unwrap();
    assert!(r.run_until(200, |s| s.faulted));
    let s = *r.axis.status();
    assert_eq!((s.err, s.exerr), (12, EX_DRIVE_FAULT));
    assert_eq!(s.last_stop, StopCause::DriveFault);
}

#[test]
fn refusals_before_anything_can_move() {
    // No feedback yet: the position to hold is unknown.
    let mut r = Rig::at(0.0);
    r.frame = |_, _| None;
    assert_eq!(
        r.op(Operation::Enable),
        Err((ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST))
    );
    // A feedback-only axis has nothing to enable.
    let cfg = AxisConfig {
        configuration: AxisConfiguration::FeedbackOnly,
        home_mode: HomeMode::Passive,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.run(1);
    assert_eq!(r.op(Operation::Enable), Err((ERR_SERVO_OFF, EX_NOT_SERVO)));
    assert_eq!(r.op(jog(1.0)), Err((ERR_SERVO_OFF, EX_NOT_SERVO)));
    assert!(r.op(Operation::Disable).is_ok());
    assert!(r.op(Operation::Stop).is_ok());
    assert!(r.op(Operation::Reset).is_ok());
    // Shutdown (a level): 12/12 while it is set.
    let mut r = Rig::at(0.0);
    r.run(1);
    let shut = Request {
        shutdown: true,
        op: Some(Operation::Enable),
        ..Request::default()
    };
    r.step(shut);
    assert_eq!(
        r.axis.status().op.refused,
        Some((ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN))
    );
}

#[test]
fn shutdown_ends_a_jog_and_switches_off_at_once() {
    let mut r = Rig::at(0.0);
    r.enable();
    let id = r.op(jog(10.0)).unwrap();
    r.run(50);
    r.step(Request {
        shutdown: true,
        ..Request::default()
    });
    let s = *r.axis.status();
    assert!(!s.jogging && !s.stopping && !s.er, "{s:?}");
    assert_eq!(s.last_stop, StopCause::Shutdown);
    assert_eq!((s.op.id, s.op.ip, s.op.pc), (id, false, false));
    assert!(!r.cmds.last().unwrap().enable);
}

#[test]
fn a_virtual_axis_is_enabled_and_jogged_without_a_drive() {
    let cfg = AxisConfig {
        configuration: AxisConfiguration::Virtual,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    assert!(!r.cmds.last().unwrap().enable, "no drive to switch on");
    r.op(jog(10.0)).unwrap();
    r.run(100);
    assert!(r.axis.status().jogging && r.cmd_axis() > 0.5);
}
