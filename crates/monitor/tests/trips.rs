//! Each invariant trips on a command that breaks it — a bug in the
//! operations' code, played by changing the engine's command before the
//! monitor sees it — and the trip is what it must be: the monitor's stop
//! (category 1 from the last command it passed, at `max_deceleration` or
//! more, then the power stage off; category 0 where the power stage must
//! already be off), the engine told (ER 1021 / the invariant, faulted, its
//! motion ended), nothing enabled again until a reset and an explicit
//! enable.

mod common;

use common::{op, Rig, MS};

/// Soft limits ±10 (`max_deceleration` defaults to the homing's 500).
fn axis() -> AxisConfig {
    common::immediate_axis(10.0)
}
use motion_homing::codes::*;
use motion_homing::*;
use motion_homing::{JogSpec, MoveSpec};
use motion_monitor::{Category, Invariant, Withdrawn};
use motion_plant::PlantConfig;
use std::cell::Cell;

/// Enabled and homed at 0, at rest.
fn ready(cfg: AxisConfig) -> Rig {
    let mut r = Rig::new(cfg, PlantConfig::default());
    r.idle(3);
    r.step(op(Operation::Enable));
    r.idle(5);
    r.step(Request {
        home: true,
        ..Request::default()
    });
    r.idle(2);
    let s = r.axis.status();
    assert!(s.homed && s.servo_action && r.tripped.is_none(), "{s:?}");
    r
}

fn jog(speed: f64, accel: f64) -> Operation {
    Operation::Jog(JogSpec {
        jerk: None,
        speed,
        lease: Some((2_000 * MS) as f64 * 1e-9),
        accel: Some(accel),
        decel: Some(500.0),
    })
}

thread_local! {
    /// The first step a tamper changes (each test runs on its own thread).
    static FROM: Cell<u64> = const { Cell::new(u64::MAX) };
}

fn start_tamper_at(k: u64) {
    FROM.with(|f| f.set(k));
}

/// Steps since the tamper started (1 at its first step).
fn from(k: u64) -> Option<u64> {
    let f = FROM.with(Cell::get);
    (k >= f).then(|| k - f + 1)
}

/// Enabled, homed, jogging at `speed` for `cycles`; the tamper starts
/// with the next step, and that step is made.
fn tampered_jog(speed: f64, cycles: u64, tamper: fn(u64, &mut Command)) -> Rig {
    let mut r = ready(axis());
    r.step(op(jog(speed, 500.0)));
    r.idle(cycles);
    start_tamper_at(r.k());
    r.tamper = tamper;
    r.step(Request::default());
    r
}

/// The monitor's stop after a trip at step `at` from the last command it
/// passed: the speed never rises, it is at rest within the time
/// `max_deceleration` needs (plus a cycle), the power stage goes off once
/// at rest and stays off; the engine is faulted with the monitor's code.
fn stopped_by_the_monitor(r: &mut Rig, exerr: u16) {
    let (at, trip) = r.tripped.expect("tripped");
    assert_eq!(trip.category, Category::Stop1, "{trip:?}");
    let s = *r.axis.status();
    assert!(s.er && s.faulted, "{s:?}");
    assert_eq!((s.err, s.exerr), (ERR_MONITOR, exerr));
    assert!(!s.jogging && !s.moving && !s.streaming && !s.ip, "{s:?}");
    let mut prev = (trip.from, f64::INFINITY);
    let mut off_at = None;
    for k in 0..100 {
        let out = if k == 0 {
            r.out
        } else {
            r.step(Request::default());
            r.out
        };
        let v = (out.position - prev.0).abs() / 1e-3;
        assert!(v <= prev.1 + 1e-6, "step {k}: speed {v} after {}", prev.1);
        prev = (out.position, v);
        match (out.enable, off_at) {
            (false, None) => off_at = Some(k),
            (true, Some(o)) => panic!("asked on again at {k}, off since {o}"),
            _ => {}
        }
    }
    // from 50 u/s at most at 500 u/s²: 100 ms
    let off = off_at.expect("the power stage went off");
    assert!(off <= 100, "off after {off} cycles");
    assert!(!r.fb.drive.enabled);
    assert!(at > 0);
}

#[test]
fn a_jog_commanded_faster_than_asked_trips_the_velocity_check() {
    let mut r = tampered_jog(5.0, 100, |k, c| {
        if let Some(n) = from(k) {
            c.position += n as f64 * 0.002;
            c.velocity += 2.0;
        }
    });
    let (_, trip) = r.tripped.expect("tripped");
    assert_eq!(trip.invariant, Invariant::Velocity);
    assert!(
        (trip.value - 7.0).abs() < 1e-9 && (trip.bound - 5.0).abs() < 1e-3,
        "{trip:?}"
    );
    assert_eq!(r.axis.status().last_stop, StopCause::Monitor);
    assert!(
        r.axis.status().homed,
        "the reference stays: {:?}",
        r.axis.status()
    );
    stopped_by_the_monitor(&mut r, EX_MONITOR_VELOCITY);
}

#[test]
fn a_position_step_beyond_the_speed_bound_trips_the_step_check_and_reset_enables_nothing() {
    let mut r = tampered_jog(5.0, 100, |k, c| {
        if let Some(n) = from(k) {
            c.position += n as f64 * 0.002;
        }
    });
    let (_, trip) = r.tripped.expect("tripped");
    assert_eq!(trip.invariant, Invariant::Step);
    assert!((trip.value - 7.0).abs() < 1e-6, "{trip:?}");
    stopped_by_the_monitor(&mut r, EX_MONITOR_STEP);
    // reset clears it like any axis fault; nothing comes on by itself
    r.tamper = |_, _| {};
    r.step(op(Operation::Reset));
    assert!(r.monitor.tripped().is_none());
    assert!(!r.axis.status().er);
    for _ in 0..50 {
        r.step(Request::default());
        assert!(!r.out.enable && !r.fb.drive.enabled);
    }
    r.step(op(Operation::Enable));
    r.idle(5);
    assert!(r.axis.status().servo_action);
    r.step(op(jog(-5.0, 500.0)));
    r.idle(50);
    assert_eq!(r.monitor.trips(), 1, "a normal jog after the reset passes");
}

#[test]
fn an_acceleration_spike_within_the_speed_cap_trips_the_acceleration_check() {
    let mut r = ready(axis());
    // accelerating at 100 towards 20: 1 u/s more in one cycle is 1000 u/s²
    r.step(op(Operation::Move(MoveSpec {
        jerk: None,
        target: 9.0,
        relative: false,
        speed: Some(20.0),
        accel: Some(100.0),
        decel: Some(100.0),
        supersede: false,
    })));
    r.idle(50);
    start_tamper_at(r.k());
    r.tamper = |k, c| {
        if let Some(n) = from(k) {
            c.position += n as f64 * 0.001;
        }
    };
    r.step(Request::default());
    let (_, trip) = r.tripped.expect("tripped");
    assert_eq!(trip.invariant, Invariant::Acceleration, "{trip:?}");
    assert!(
        (trip.value - 1100.0).abs() < 1.0 && trip.bound == 500.0,
        "{trip:?}"
    );
    stopped_by_the_monitor(&mut r, EX_MONITOR_ACCELERATION);
}

#[test]
fn a_command_beyond_a_soft_limit_trips_and_the_stop_ends_on_the_limit() {
    let cfg = AxisConfig {
        stream_acceleration: 100_000.0,
        ..axis()
    };
    let mut r = ready(cfg);
    r.step(op(Operation::StreamStart));
    // a program at 1 kHz to 9.99 at 10 u/s: inside
    r.tamper = |_, c| {
        if c.position > 9.0 {
            c.position += (c.position - 9.0) * 0.1;
        }
    };
    let mut p = 0.0;
    let mut t = 0;
    let mut send = |r: &mut Rig, dp: f64| {
        p += dp;
        t += MS;
        r.step(Request {
            setpoint: Some(Setpoint {
                t_ns: t,
                position: p,
                velocity: None,
            }),
            ..Request::default()
        });
    };
    send(&mut r, 0.0);
    send(&mut r, 0.005);
    for _ in 0..998 {
        send(&mut r, 0.01);
    }
    send(&mut r, 0.005);
    r.idle(100);
    let (_, trip) = r.tripped.expect("tripped");
    assert_eq!(trip.invariant, Invariant::SoftLimit, "{trip:?}");
    assert!(trip.value > 10.0 && trip.bound == 10.0, "{trip:?}");
    let s = r.axis.status();
    assert_eq!((s.err, s.exerr), (ERR_MONITOR, EX_MONITOR_SOFT_LIMIT));
    assert!(!s.streaming);
    // the monitor's stop ended on the limit, never beyond
    assert!(r.out_axis() <= 10.0 + 1e-9, "{}", r.out_axis());
    assert!(r.plant.position() <= 10.0 + 1e-9 && !r.out.enable);
}

#[test]
fn the_power_stage_asked_on_after_a_drive_fault_is_switched_off_at_once_and_stays_off() {
    let mut r = ready(axis());
    r.idle(10);
    start_tamper_at(r.k());
    r.plant.inject_fault();
    r.tamper = |k, c| {
        if from(k).is_some() {
            c.enable = true;
        }
    };
    r.idle(2);
    let (_, trip) = r.tripped.expect("tripped");
    assert_eq!(
        (trip.invariant, trip.category),
        (Invariant::Enable, Category::Stop0)
    );
    assert!(!r.out.enable, "off in the cycle it tripped");
    let s = r.axis.status();
    assert_eq!((s.err, s.exerr), (ERR_MONITOR, EX_MONITOR_ENABLE));
    // a fault reset at the drive: never asked on again (category 0:
    // never re-enabled to brake), whatever the engine's command says
    r.plant.reset_fault();
    for _ in 0..300 {
        r.step(Request::default());
        assert!(!r.out.enable && !r.fb.drive.enabled);
    }
}

#[test]
fn a_disable_that_leaves_the_power_stage_on_at_rest_trips() {
    let mut r = ready(axis());
    r.step(op(jog(5.0, 500.0)));
    r.idle(50);
    start_tamper_at(r.k());
    r.tamper = |k, c| {
        if from(k).is_some() {
            c.enable = true;
        }
    };
    r.step(op(Operation::Disable));
    // 5 u/s at 500 u/s²: 10 ms to rest, then at most three cycles
    for _ in 0..10 {
        r.step(Request::default());
    }
    assert!(r.tripped.is_none(), "the stop may take its time");
    r.idle(10);
    let (at, trip) = r.tripped.expect("tripped");
    assert_eq!(trip.invariant, Invariant::Enable);
    assert_eq!(trip.withdrawn, Some(Withdrawn::Disabled));
    assert!(at <= FROM.with(Cell::get) + 16, "tripped at {at}");
    assert!(!r.out.enable);
}

#[test]
fn a_command_that_is_not_a_number_is_never_sent() {
    let mut r = tampered_jog(-5.0, 30, |k, c| {
        if from(k).is_some() {
            c.position = f64::NAN;
        }
    });
    let (_, trip) = r.tripped.expect("tripped");
    assert_eq!(trip.invariant, Invariant::NotFinite);
    assert!(r.out.position.is_finite() && r.out.velocity.is_finite());
    stopped_by_the_monitor(&mut r, EX_MONITOR_NOT_FINITE);
}

#[test]
fn a_trip_while_homing_ends_the_homing_as_a_failure() {
    let cfg = AxisConfig {
        home_sequence: HomeSequence::Switch,
        home_return_speed: 2.0,
        ..axis()
    };
    let plant = PlantConfig {
        start: -5.0,
        switch: Some((0.0, 5.0)),
        ..PlantConfig::default()
    };
    let mut r = Rig::new(cfg, plant);
    r.idle(3);
    let rung = Request {
        home: true,
        ..Request::default()
    };
    for _ in 0..100 {
        r.step(rung);
    }
    assert_eq!(r.axis.status().phase, Phase::Seek);
    start_tamper_at(r.k());
    r.tamper = |k, c| {
        if let Some(n) = from(k) {
            c.position += n as f64 * 0.01;
        }
    };
    r.step(rung);
    let s = *r.axis.status();
    assert!(s.er && !s.ip && !s.homed && s.dn && s.faulted, "{s:?}");
    assert_eq!((s.err, s.exerr), (ERR_MONITOR, EX_MONITOR_STEP));
    assert_eq!(s.phase, Phase::Idle);
    r.tamper = |_, _| {};
    stopped_by_the_monitor(&mut r, EX_MONITOR_STEP);
}
