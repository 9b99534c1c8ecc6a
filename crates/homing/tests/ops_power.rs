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
    let mut r = at_the_seek();
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
    // Changed with the operations: homing used to reset the fault itself (by
    // toggling the enable); a faulted axis now refuses to home (ERR 20).
    let mut r = at_the_seek();
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
    let (mut r, id) = jogging_with_id();
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

/// Homing, 100 steps in: seeking at 20 u/s.
fn seeking() -> Rig {
    let mut r = Rig::new(switch_homing(), machine());
    for _ in 0..100 {
        r.step(home());
    }
    assert_eq!(r.axis.status().phase, Phase::Seek);
    r
}

/// Homing's seek at 20 u/s stopped at step 100: its abort ramp (Home
/// Deceleration 500: 40 ms) runs from there.
fn ramping_after_a_stopped_homing() -> Rig {
    let mut r = seeking();
    r.step(Request {
        home: true,
        stop: true,
        ..Request::default()
    });
    let s = *r.axis.status();
    assert!(s.stopping && !s.ip && (s.err, s.exerr) == (12, 1), "{s:?}");
    assert!(r.cmds.last().unwrap().enable, "ramping down, on");
    r
}

#[test]
fn a_fault_during_homings_abort_ramp_withdraws_the_enable_and_a_reset_never_restores_it() {
    // The drive faults 5 ms into the ramp, and a reset comes 3 ms later,
    // while the ramp would still run: the enable request is withdrawn in
    // the step the fault is seen, for good (a CiA 402 drive walked from
    // Fault back to Operation enabled would be pulled to where the ramp's
    // command ended).
    let mut r = ramping_after_a_stopped_homing();
    r.run(5);
    r.plant.inject_fault();
    r.fb = r.plant.feedback();
    let seen = r.k;
    r.run(3);
    r.op(Operation::Reset).unwrap();
    r.run(100);
    assert!(
        r.since(seen).iter().all(|c| !c.enable),
        "{:?}",
        r.since(seen).iter().map(|c| c.enable).collect::<Vec<_>>()
    );
    let s = *r.axis.status();
    assert!(
        !s.stopping && s.phase == Phase::Idle && !s.servo_action,
        "{s:?}"
    );
    // Held where the axis stood, not where the ramp's command would end.
    let at = r.plant.position();
    assert!((r.cmds.last().unwrap().position - at).abs() < 1e-12);
}

#[test]
fn a_power_stage_dropped_during_homings_abort_ramp_withdraws_the_enable() {
    // STO 5 ms into the ramp (no fault): the request goes with it.
    let mut r = ramping_after_a_stopped_homing();
    r.frame = |k, mut fb| {
        if k >= 106 {
            fb.drive.enabled = false;
        }
        Some(fb)
    };
    r.run(100);
    assert!(r.since(106).iter().all(|c| !c.enable));
    let s = *r.axis.status();
    assert!(!s.stopping && !s.servo_action && !s.faulted, "{s:?}");
}

#[test]
fn a_fault_or_dropped_power_stage_withdraws_the_enable_in_every_state() {
    // Each state the engine can be in with the power stage requested on,
    // and each way the drive can go: the next command asks for it off.
    type Setup = fn() -> Rig;
    let states: [(&str, Setup); 7] = [
        ("idle", idle),
        ("enabling", || {
            let plant = PlantConfig {
                enable_delay_cycles: 100_000,
                ..op_plant(0.0)
            };
            let mut r = Rig::new(op_axis(), plant);
            r.run(1);
            r.op(Operation::Enable).unwrap();
            r.run(5);
            r
        }),
        ("seek", seeking),
        ("homing's abort ramp", ramping_after_a_stopped_homing),
        ("jogging", jogging),
        ("stopping a jog", || {
            let mut r = jogging();
            r.op(Operation::Stop).unwrap();
            r
        }),
        ("streaming", || {
            let mut r = Rig::at(0.0);
            r.enable_and_home();
            r.op(Operation::StreamStart).unwrap();
            for k in 0..20u64 {
                r.setpoint(k * MS, k as f64 * 0.001, None);
            }
            r
        }),
    ];
    for (name, setup) in states {
        for fault in [true, false] {
            if !fault && name == "enabling" {
                // Not on yet: nothing to drop.
                continue;
            }
            let mut r = setup();
            let home = r.axis.status().ip;
            let req = Request {
                home,
                ..Request::default()
            };
            if fault {
                r.plant.inject_fault();
                r.fb = r.plant.feedback();
            } else {
                r.fb.drive.enabled = false;
            }
            let cmd = r.step(req);
            assert!(!cmd.enable, "{name}, fault {fault}: {:?}", r.axis.status());
            for _ in 0..50 {
                let cmd = r.step(req);
                assert!(!cmd.enable, "{name}, fault {fault}: enabled again");
            }
        }
    }
}

#[test]
fn a_fault_during_a_reset_is_a_fault() {
    // Jogging at 10 u/s, a reset is accepted (nothing to clear): a drive
    // fault in the next cycle is an axis fault at once — the jog ends and
    // the power stage is requested off — not hidden for enable_timeout
    // while the command runs away from a drive that no longer follows.
    for late in [0u64, 1, 5, 300] {
        let mut r = jogging();
        let reset = r.op(Operation::Reset).unwrap();
        r.run(late);
        r.plant.inject_fault();
        r.fb = r.plant.feedback();
        r.run(1);
        let s = *r.axis.status();
        assert!(s.faulted && s.er && !s.jogging, "{late}: {s:?}");
        assert_eq!((s.err, s.exerr), (12, EX_DRIVE_FAULT), "{late}");
        assert_eq!(s.last_stop, StopCause::DriveFault);
        if late <= 1 {
            // A reset still pulsing ends with it (not PC): the new fault
            // needs one of its own.
            assert_eq!((s.op.id, s.op.ip, s.op.pc), (reset, false, false));
        }
        assert!(!r.cmds.last().unwrap().enable, "{late}");
        // The command holds where the axis stood.
        r.run(100);
        let gap = (r.cmds.last().unwrap().position - r.plant.position()).abs();
        assert!(gap < 1e-9, "{late}: {gap}");
    }
    // Resets one after the other do not hide it either.
    let mut r = Rig::at(0.0);
    r.enable();
    r.op(jog(10.0)).unwrap();
    for _ in 0..3 {
        r.run(20);
        r.op(Operation::Reset).unwrap();
    }
    r.plant.inject_fault();
    r.fb = r.plant.feedback();
    r.run(1);
    assert!(r.axis.status().faulted && !r.axis.status().jogging);
}

#[test]
fn a_lost_drive_or_a_restarted_io_process_withdraws_the_enable_in_every_state() {
    // The drive is gone (the I/O process says so, for longer than the
    // feedback-loss rule tolerates) or its I/O process was restarted (its
    // drives start off): in every state the enable request is withdrawn
    // and not raised again when the drive is back — a drive coming back
    // would otherwise be switched on by a request left standing.
    type Setup = fn() -> Rig;
    let states: [(&str, Setup); 5] = [
        ("idle, enabled", idle),
        ("homed by an active homing", || {
            let mut r = Rig::new(switch_homing(), machine());
            r.step(home());
            assert!(r.run_until(60_000, |s| s.dn));
            assert!(r.axis.status().homed && r.cmds.last().unwrap().enable);
            r
        }),
        ("seek", seeking),
        ("homing's abort ramp", ramping_after_a_stopped_homing),
        ("jogging", jogging),
    ];
    for (name, setup) in states {
        for restart in [false, true] {
            let mut r = setup();
            let home = r.axis.status().ip;
            if restart {
                let now = r.now();
                r.axis.reconnected(now);
            } else {
                // lost for longer than feedback_timeout (10 ms) tolerates
                r.frame = |_, _| None;
                for _ in 0..20 {
                    r.step(Request {
                        home,
                        drive_lost: true,
                        ..Request::default()
                    });
                }
                r.frame = |_, fb| Some(fb);
            }
            let from = r.k;
            for _ in 0..50 {
                r.step(Request {
                    home,
                    ..Request::default()
                });
            }
            assert!(
                r.since(from).iter().all(|c| !c.enable),
                "{name}, restart {restart}: {:?}",
                r.axis.status()
            );
            let s = r.axis.status();
            assert!(
                !s.jogging && !s.stopping && !s.servo_action,
                "{name}: {s:?}"
            );
        }
    }
}

#[test]
fn lost_feedback_withdraws_the_enable_once_nothing_is_left_to_stop() {
    // The I/O process goes silent (killed, hung): at rest the enable
    // request is withdrawn as soon as the loss rule trips; in motion the
    // stop at max_deceleration runs first (the drive may still follow),
    // then it is withdrawn. A new I/O process never gets a standing
    // request.
    for moving in [false, true] {
        let mut r = if moving { jogging() } else { idle() };
        r.frame = |_, _| None;
        assert!(r.run_until(200, |s| !s.feedback_ok), "lost");
        assert!(r.run_until(200, |s| !s.stopping && !s.jogging));
        r.run(1);
        assert!(!r.cmds.last().unwrap().enable, "moving {moving}");
        r.frame = |_, fb| Some(fb);
        let from = r.k;
        r.run(50);
        assert!(r.since(from).iter().all(|c| !c.enable), "moving {moving}");
        assert!(!r.axis.status().servo_action);
    }
}

#[test]
fn a_stop_asked_while_a_disable_waits_for_rest_still_switches_the_power_off() {
    // Jogging; a disable (it stops first, then the power stage goes off),
    // a reset, a stop while the jog still ramps down: the stop answers in
    // the disable's place, and at rest the power stage goes off all the
    // same (before: the stop's wait replaced the disable's, the power
    // stage stayed on, and the cycle monitor tripped on it).
    let mut r = Rig::new(op_axis(), op_plant(0.0));
    r.enable_and_home();
    r.op(jog(5.0)).unwrap();
    r.run(200);
    assert!(r.axis.status().jogging);
    r.op(Operation::Disable).unwrap();
    r.op(Operation::Reset).unwrap();
    r.op(Operation::Stop).unwrap();
    assert!(r.run_until(2000, |s| !s.jogging && !s.stopping && s.op.pc));
    r.run(5);
    assert!(!r.cmds.last().unwrap().enable, "the power stage stayed on");
    assert!(!r.axis.status().servo_action);
}
