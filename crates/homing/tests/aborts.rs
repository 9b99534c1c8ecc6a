//! Everything that ends homing early: requests, faults, bad or missing
//! feedback, timeouts, limits. Each must stop the axis, restore overridden
//! drive values, leave HomedStatus false and report the documented code.

mod common;

use common::{axis, machine, run, run_with, Outcome};
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::PlantConfig;

const T: f64 = 0.001;

fn torque_axis() -> AxisConfig {
    AxisConfig {
        home_torque_level: 30.0,
        home_torque_threshold: 20.0,
        home_torque_time: 0.01,
        torque_limit: 250.0,
        position_error_tolerance: 1.0,
        velocity_error_tolerance: 5.0,
        ..axis(HomeSequence::Torque, HomeDirection::BidirectionalForward)
    }
}

fn switch_axis() -> AxisConfig {
    AxisConfig {
        home_sequence: HomeSequence::Switch,
        ..torque_axis()
    }
}

fn assert_aborted(o: &Outcome, err: u16, exerr: u16) {
    let s = o.status;
    assert!(s.er && s.dn && !s.ip && !s.pc, "bits: {s:?}");
    assert!(!s.homed && !s.homing, "HomedStatus stays false: {s:?}");
    assert_eq!((s.err, s.exerr), (err, exerr), "{s:?}");
    let last = o.commands.last().unwrap();
    assert_eq!(last.velocity, 0.0, "axis at rest");
    assert!(o
        .commands
        .iter()
        .all(|c| c.position.is_finite() && c.velocity.is_finite()));
}

fn assert_restored(o: &Outcome, cfg: &AxisConfig) {
    let last = o.commands.last().unwrap();
    assert_eq!(last.torque_limit_positive, cfg.torque_limit);
    assert_eq!(last.torque_limit_negative, cfg.torque_limit);
    assert_eq!(last.position_error_tolerance, cfg.position_error_tolerance);
    assert_eq!(last.velocity_error_tolerance, cfg.velocity_error_tolerance);
}

/// The torque leg really overrides: otherwise the restore checks prove nothing.
#[test]
fn torque_leg_overrides_limits() {
    let cfg = torque_axis();
    let o = run(cfg, machine(), T, 60.0);
    assert!(o.status.pc);
    assert!(o
        .commands
        .iter()
        .any(|c| c.torque_limit_positive == 30.0 && c.position_error_tolerance == 0.0));
    assert_restored(&o, &cfg);
}

#[test]
fn stop_request_during_torque_seek() {
    let cfg = torque_axis();
    let o = run_with(cfg, machine(), T, 60.0, |k, _, fb, req| {
        req.stop = k >= 1000;
        Some(fb)
    });
    assert_aborted(&o, ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST);
    assert_restored(&o, &cfg);
    // Controlled stop at home deceleration from 20 u/s: 0.04 s, 0.4 units.
    let stopped_at = o.final_raw;
    let at_request = o.commands[1000].position;
    assert!(
        (stopped_at - at_request - 0.4).abs() < 0.03,
        "{stopped_at} {at_request}"
    );
}

#[test]
fn stop_while_pushing_into_the_hard_stop_releases_before_restoring() {
    let cfg = AxisConfig {
        home_torque_time: 1.0, // stay pushed long enough to be stopped there
        ..torque_axis()
    };
    let o = run_with(cfg, machine(), T, 60.0, |k, plant, fb, req| {
        req.stop = plant.position() >= 100.0 && k > 7700;
        Some(fb)
    });
    assert_aborted(&o, ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST);
    assert_restored(&o, &cfg);
    // Limits come back only once the command sits on the wall again.
    let restored_at = o
        .commands
        .iter()
        .rposition(|c| c.torque_limit_positive == 30.0)
        .unwrap()
        + 1;
    assert!((o.commands[restored_at].position - 100.0).abs() < 1e-9);
}

#[test]
fn timeout_aborts_with_1015() {
    let cfg = AxisConfig {
        home_timeout: 0.5,
        ..torque_axis()
    };
    let o = run(cfg, machine(), T, 60.0);
    assert_aborted(&o, ERR_TIMEOUT, 0);
    assert_restored(&o, &cfg);
    let s = o.status;
    let took = s.finished_ns.unwrap() - s.started_ns;
    assert!((500_000_000..=501_000_000).contains(&took), "{took}");
}

#[test]
fn drive_fault_disables_and_restores_at_once() {
    let cfg = torque_axis();
    let mut faulted_at = None;
    let o = run_with(cfg, machine(), T, 60.0, |k, plant, fb, _| {
        if k == 1500 {
            plant.inject_fault();
            faulted_at = Some(k);
        }
        Some(fb)
    });
    assert_aborted(&o, ERR_SERVO_MESSAGE, EX_DRIVE_FAULT);
    assert_restored(&o, &cfg);
    assert!(!o.commands.last().unwrap().enable);
    // Reported on the first frame that shows the fault, restored in that cycle.
    let k = faulted_at.unwrap() + 1;
    assert_eq!(o.commands[k + 1].torque_limit_positive, cfg.torque_limit);
}

#[test]
fn feedback_lost_aborts_after_the_timeout_plus_one_cycle() {
    let cfg = switch_axis();
    let o = run_with(cfg, machine(), T, 60.0, |k, _, fb, _| {
        (k < 1200).then_some(fb)
    });
    assert_aborted(&o, ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST);
    assert!(!o.status.feedback_ok);
    // feedback_timeout_ns = 10 ms. The last frame is seen at step 1199;
    // steps 1200..=1209 fill the bucket to exactly 10 ms (not above), step
    // 1210 to 11 ms: the gap is then 1210 - 1199 = 11 ms.
    assert_eq!(o.status.finished_ns, Some(1210 * 1_000_000));
    assert_eq!(o.status.lost_after_ns, Some(11_000_000));
}

#[test]
fn a_tenth_of_the_frames_lost_is_tolerated() {
    let cfg = switch_axis();
    // Every 10th frame lost: +1 ms, then 9 x 0.25 ms drained, so the bucket
    // never holds more than 1 ms. Homing completes; the switch error bound
    // doubles where the samples around the edge are two cycles apart:
    // R x 2T / 2 = 2 x 0.002 / 2 = 0.002.
    let o = run_with(cfg, machine(), T, 60.0, |k, _, fb, _| {
        (k % 10 != 9).then_some(fb)
    });
    assert!(o.status.pc, "{:?}", o.status);
    assert!(o.status.event_raw.unwrap().abs() <= 2.0 * 0.001 * 2.0 / 2.0 + 1e-9);
    assert_eq!(o.status.lost_after_ns, None);
}

#[test]
fn nan_feedback_aborts_and_names_the_attribute() {
    for (attr, poke) in [
        ("feedback.position", 0usize),
        ("feedback.velocity", 1),
        ("feedback.torque", 2),
        ("feedback.position", 3),
    ] {
        let cfg = switch_axis();
        let o = run_with(cfg, machine(), T, 60.0, |k, _, mut fb, _| {
            if k == 900 {
                match poke {
                    0 => fb.position = f64::NAN,
                    1 => fb.velocity = f64::INFINITY,
                    2 => fb.torque = f64::NEG_INFINITY,
                    _ => fb.position = 1e300,
                }
            }
            Some(fb)
        });
        assert_aborted(&o, ERR_SERVO_MESSAGE, EX_FEEDBACK_INVALID);
        assert_eq!(o.status.bad_attribute, Some(attr));
    }
}

#[test]
fn search_limit_stops_a_search_that_finds_nothing() {
    let cfg = switch_axis();
    let plant = PlantConfig {
        switch: None,
        hard_stop: Some((-1000.0, 1000.0)),
        ..machine()
    };
    let o = run(cfg, plant, T, 60.0);
    assert_aborted(&o, ERR_SEARCH_LIMIT, Phase::Seek as u16);
    // Derived limit: 1.1 x (100 - -100) = 220 from the start at -50.
    let travelled_before_stop = o.final_raw - -50.0 - 0.4;
    assert!(
        (travelled_before_stop - 220.0).abs() < 0.05,
        "{travelled_before_stop}"
    );
}

#[test]
fn shutdown_during_homing() {
    let cfg = switch_axis();
    let o = run_with(cfg, machine(), T, 60.0, |k, _, fb, req| {
        req.shutdown = k >= 800;
        Some(fb)
    });
    assert_eq!((o.status.err, o.status.exerr), (12, 12));
    assert!(o.status.er && !o.status.homed && !o.commands.last().unwrap().enable);
}

#[test]
fn overtravel_in_the_direction_of_travel_aborts() {
    let cfg = switch_axis();
    let plant = PlantConfig {
        switch: None,
        overtravel: Some((-60.0, 60.0)),
        ..machine()
    };
    let o = run(cfg, plant, T, 60.0);
    assert_aborted(&o, ERR_SERVO_MESSAGE, EX_OVERTRAVEL);
}

#[test]
fn drive_that_never_enables() {
    let cfg = switch_axis();
    let plant = PlantConfig {
        enable_delay_cycles: 100_000,
        ..machine()
    };
    let o = run(cfg, plant, T, 60.0);
    assert_eq!((o.status.err, o.status.exerr), (12, EX_ENABLE_TIMEOUT));
}

#[test]
fn feedback_loss_clears_homed_when_idle() {
    let cfg = AxisConfig::default(); // immediate
    let mut axis = Axis::new(cfg);
    let fb = Feedback::default();
    let home = Request {
        home: true,
        ..Request::default()
    };
    const MS: u64 = 1_000_000;
    axis.step(0, Some(&fb), &home);
    assert!(axis.status().homed && axis.status().pc);
    // 1 ms steps: ten missing steps make exactly the 10 ms timeout, tolerated.
    for k in 1..=10 {
        axis.step(k * MS, None, &home);
        assert!(axis.status().homed, "within the timeout at {k} ms");
    }
    axis.step(11 * MS, None, &home);
    assert!(!axis.status().homed);
    assert_eq!(axis.status().lost_after_ns, Some(11 * MS));
}

#[test]
fn restart_after_an_error_homes() {
    let cfg = switch_axis();
    let mut axis = Axis::new(cfg);
    let mut plant = motion_plant::Plant::new(machine());
    let mut fb = plant.feedback();
    let mut homed_at = None;
    for k in 0..20_000u64 {
        // First attempt stopped at 500, released, second rising edge at 1000.
        let req = Request {
            home: !(500..1000).contains(&k),
            stop: (500..510).contains(&k),
            ..Request::default()
        };
        let cmd = axis.step(k * 1_000_000, Some(&fb), &req);
        fb = plant.step(&cmd, T);
        if k == 600 {
            assert_eq!(axis.status().err, 12);
        }
        if axis.status().pc && homed_at.is_none() {
            homed_at = Some(k);
        }
    }
    assert!(homed_at.is_some(), "{:?}", axis.status());
    assert!(!axis.status().er);
}

#[test]
fn refused_start_when_feedback_never_arrived() {
    let mut axis = Axis::new(switch_axis());
    let req = Request {
        home: true,
        ..Request::default()
    };
    let cmd = axis.step(0, None, &req);
    assert!(axis.status().er && !axis.status().ip);
    assert_eq!(
        (axis.status().err, axis.status().exerr),
        (12, EX_FEEDBACK_LOST)
    );
    assert!(!cmd.enable);
}

#[test]
fn en_follows_the_rung() {
    let mut axis = Axis::new(AxisConfig::default());
    let fb = Feedback::default();
    let on = Request {
        home: true,
        ..Request::default()
    };
    axis.step(0, Some(&fb), &on);
    assert!(axis.status().en && axis.status().dn && axis.status().pc);
    axis.step(1, Some(&fb), &on);
    assert!(axis.status().en, "EN stays while the rung is true");
    axis.step(2, Some(&fb), &Request::default());
    assert!(!axis.status().en, "EN clears when the rung drops after DN");
}
