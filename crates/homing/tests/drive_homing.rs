//! Homing done by the drive (`drive_homing`) and a lost drive, cycle by
//! cycle against a scripted drive: the engine asks (`Command::drive_home`),
//! follows the drive's position while it homes, takes the home event at the
//! drive's position 0 after it redefined its position (a jump the
//! plausibility rule must not refuse), waits for the hand-back and moves to
//! Home Position; errors, a refusal of homing mode and a stop end it as the
//! other legs do.
//!
//! Hand-worked numbers: the drive starts at raw 40.0, homes at 2 u/s
//! towards its home point 10 units away (raw 50.0 in the old frame), stops
//! 0.25 past it and redefines its position: it then reads 0.25. Home
//! Position 100, Home Offset 1: the event (the drive's 0) reads 99, the
//! move home goes to raw 1.0 and the axis reads 100 there.

use motion_homing::codes::*;
use motion_homing::*;

const MS: u64 = 1_000_000;

fn axis_cfg() -> AxisConfig {
    AxisConfig {
        counts_per_unit: 1000.0,
        drive_homing: true,
        home_sequence: HomeSequence::Switch,
        home_direction: HomeDirection::BidirectionalForward,
        home_speed: 2.0,
        home_return_speed: 1.0,
        home_acceleration: 100.0,
        home_deceleration: 100.0,
        home_position: 100.0,
        home_offset: 1.0,
        cycle_ns: MS,
        ..AxisConfig::default()
    }
}

/// The drive as the engine sees it.
struct Drive {
    raw: f64,
    enabled: bool,
    homing: DriveHoming,
    /// Cycles of the drive's own homing so far.
    cycles: u32,
}

impl Drive {
    fn feedback(&self) -> Feedback {
        Feedback {
            position: self.raw,
            drive: DriveState {
                enabled: self.enabled,
                fault: false,
            },
            drive_homing: self.homing,
            ..Feedback::default()
        }
    }

    /// One cycle of a well-behaved drive answering `cmd`.
    fn answer(&mut self, cmd: &Command) {
        self.enabled = cmd.enable;
        if cmd.drive_home {
            self.homing.active = true;
            self.cycles += 1;
            if self.cycles <= 5_000 {
                // 10 units at 2 u/s, then 0.25 to stop: a jump to 0.25
                self.raw += 0.002;
            } else if !self.homing.attained {
                self.raw = 0.25;
                self.homing.attained = true;
            }
        } else if self.homing.active {
            // hands back one cycle after the request dropped
            self.homing = DriveHoming::default();
        } else if cmd.enable {
            self.raw = cmd.position;
        }
    }
}

fn run(axis: &mut Axis, drive: &mut Drive, from: u64, cycles: u64, req: &Request) -> Command {
    let mut cmd = Command::default();
    for k in from..from + cycles {
        cmd = axis.step(k * MS, Some(&drive.feedback()), req);
        drive.answer(&cmd);
    }
    cmd
}

/// A drive at raw `raw`, disabled, not homing.
fn drive_at(raw: f64) -> Drive {
    Drive {
        raw,
        enabled: false,
        homing: DriveHoming::default(),
        cycles: 0,
    }
}

fn home() -> Request {
    Request {
        home: true,
        ..Request::default()
    }
}

#[test]
fn the_drive_homes_then_the_engine_moves_to_home_position() {
    assert_eq!(
        plan::plan_for(&axis_cfg()),
        [plan::Leg::DriveHomes, plan::Leg::MoveHome]
    );
    let mut axis = Axis::new(axis_cfg());
    assert!(
        axis.config_errors().is_empty(),
        "{:?}",
        axis.config_errors()
    );
    let mut d = drive_at(40.0);
    run(&mut axis, &mut d, 0, 5, &Request::default());
    // start: enable, then the drive's leg asks the drive to home
    let mut asked = None;
    for k in 5..100 {
        let cmd = axis.step(k * MS, Some(&d.feedback()), &home());
        d.answer(&cmd);
        if cmd.drive_home {
            asked = Some(k);
            // the command follows the actual position (no jump on hand-back)
            assert!((cmd.position - d.raw).abs() < 0.01, "{cmd:?} {}", d.raw);
            break;
        }
    }
    assert!(asked.is_some(), "never asked the drive to home");
    assert_eq!(axis.status().phase, Phase::DriveHoming);
    // the drive homes (5 s) and jumps to 0.25: no ERR 12/44
    let cmd = run(&mut axis, &mut d, 100, 5_010, &home());
    assert!(!cmd.drive_home, "request dropped after home attained");
    let s = *axis.status();
    assert!(!s.er, "{s:?}");
    assert_eq!(s.event_raw, Some(0.0));
    assert_eq!(s.implausible.jumps, 0);
    // then the move home: 0.75 units at 1 u/s
    run(&mut axis, &mut d, 5_110, 2_000, &home());
    let s = *axis.status();
    assert!(s.pc && s.homed && !s.er, "{s:?}");
    assert!(
        (d.raw - 1.0).abs() < 1e-9,
        "rests at event + offset: {}",
        d.raw
    );
    assert!((axis.axis_position().unwrap() - 100.0).abs() < 1e-9);
}

#[test]
fn a_drive_homing_error_or_refused_homing_mode_is_12_46() {
    // error bit
    let mut axis = Axis::new(axis_cfg());
    let mut d = drive_at(0.0);
    run(&mut axis, &mut d, 0, 5, &Request::default());
    run(&mut axis, &mut d, 5, 50, &home());
    d.homing.error = true;
    let fb = d.feedback();
    axis.step(55 * MS, Some(&fb), &home());
    let s = *axis.status();
    assert!(s.er && !s.ip, "{s:?}");
    assert_eq!((s.err, s.exerr), (ERR_SERVO_MESSAGE, EX_DRIVE_HOMING_ERROR));

    // a drive that never reports homing mode: refused after DRIVE_ACK_NS
    let mut axis = Axis::new(axis_cfg());
    let fb = Feedback {
        position: 3.0,
        drive: DriveState {
            enabled: true,
            fault: false,
        },
        ..Feedback::default()
    };
    let mut k = 0;
    while axis.status().ip || k < 6 {
        let req = if k < 5 { Request::default() } else { home() };
        axis.step(k * MS, Some(&fb), &req);
        k += 1;
        assert!(k < 3_000, "still waiting: {:?}", axis.status());
    }
    let s = *axis.status();
    assert_eq!((s.err, s.exerr), (ERR_SERVO_MESSAGE, EX_DRIVE_HOMING_ERROR));
    assert!(k * MS > axis::drive_homing::DRIVE_ACK_NS, "{k}");
}

#[test]
fn a_stop_drops_the_request_and_the_command_follows_the_drive_to_rest() {
    let mut axis = Axis::new(axis_cfg());
    let mut d = drive_at(0.0);
    run(&mut axis, &mut d, 0, 5, &Request::default());
    run(&mut axis, &mut d, 5, 100, &home());
    let stop = Request {
        home: true,
        stop: true,
        ..Request::default()
    };
    let cmd = axis.step(105 * MS, Some(&d.feedback()), &stop);
    assert!(!cmd.drive_home);
    let s = *axis.status();
    assert_eq!(
        (s.err, s.exerr),
        (ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST)
    );
    // the drive still hands back (decelerating on its own): followed
    d.homing.active = true;
    for k in 106..120 {
        d.raw += 0.001;
        let cmd = axis.step(k * MS, Some(&d.feedback()), &home());
        assert!((cmd.position - d.raw).abs() < 1e-12, "follows: {cmd:?}");
    }
}

#[test]
fn a_lost_drive_is_named_and_judged_afresh_when_it_is_back() {
    let cfg = AxisConfig {
        drive_homing: false,
        feedback_timeout_ns: 10 * MS,
        max_speed: 10.0,
        ..axis_cfg()
    };
    let mut axis = Axis::new(cfg);
    let fb = |raw: f64| Feedback {
        position: raw,
        drive: DriveState {
            enabled: true,
            fault: false,
        },
        ..Feedback::default()
    };
    for k in 0..5 {
        axis.step(k * MS, Some(&fb(0.0)), &Request::default());
    }
    for k in 5..10 {
        axis.step(k * MS, Some(&fb(0.0)), &home());
    }
    assert!(axis.status().ip);
    let lost = Request {
        home: true,
        drive_lost: true,
        ..Request::default()
    };
    for k in 10..30 {
        axis.step(k * MS, None, &lost);
    }
    let s = *axis.status();
    assert!(s.drive_lost && s.er && !s.homed, "{s:?}");
    assert_eq!((s.err, s.exerr), (ERR_SERVO_MESSAGE, EX_DRIVE_LOST));
    // back, power-cycled: its encoder restarted 500 units away; taken
    axis.step(30 * MS, Some(&fb(500.0)), &Request::default());
    let s = *axis.status();
    assert!(!s.drive_lost, "{s:?}");
    assert_eq!(s.implausible.jumps, 0);
    assert_eq!(axis.raw_position(), Some(500.0));
    // an I/O process that goes silent without saying so: 12/40 as before
    let mut axis = Axis::new(cfg);
    for k in 0..5 {
        axis.step(k * MS, Some(&fb(0.0)), &Request::default());
    }
    for k in 5..10 {
        axis.step(k * MS, Some(&fb(0.0)), &home());
    }
    for k in 10..30 {
        axis.step(k * MS, None, &home());
    }
    let s = *axis.status();
    assert_eq!(
        (s.err, s.exerr, s.drive_lost),
        (12, EX_FEEDBACK_LOST, false)
    );
}
