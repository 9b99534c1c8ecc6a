//! The cycle monitor against jerk-limited motion: an S-curve's stop, its
//! lease running out, a change that adds a jerk or lowers the speed, a
//! slower supersede — each builds its deceleration up at the jerk, and the
//! monitor allows that ramp-in (`Allowed::hold_ns`) and never trips (it
//! tripped on every one of them before: its speed bound decayed at the
//! deceleration at once).

mod common;
use common::{op, Rig};

/// Soft limits ±`lim`, `max_deceleration` 100.
fn axis(lim: f64) -> AxisConfig {
    AxisConfig {
        max_deceleration: 100.0,
        ..common::immediate_axis(lim)
    }
}
use motion_homing::*;
use motion_plant::PlantConfig;

fn ready(lim: f64) -> Rig {
    let mut r = Rig::new(axis(lim), PlantConfig::default());
    r.step(op(Operation::Enable));
    r.idle(50);
    let rung = Request {
        home: true,
        ..Request::default()
    };
    for _ in 0..200 {
        r.step(rung);
    }
    r.idle(10);
    assert!(r.axis.status().homed, "homed");
    r
}
fn jog(speed: f64, decel: f64, jerk: Option<f64>) -> Operation {
    Operation::Jog(JogSpec {
        speed,
        lease: Some(0.2),
        accel: Some(200.0),
        decel: Some(decel),
        jerk,
    })
}

/// `n` cycles of a jog held: its lease renewed every 50.
fn hold(r: &mut Rig, n: u64) {
    for k in 0..n {
        r.step(Request {
            jog_renew: k % 50 == 0,
            ..Request::default()
        });
    }
}

#[test]
fn scurve_jog_stop_vs_monitor() {
    let mut r = ready(1000.0);
    r.step(op(jog(20.0, 100.0, Some(500.0))));
    hold(&mut r, 400);
    r.step(op(Operation::Stop));
    r.idle(1000);
    assert!(r.tripped.is_none());
}

#[test]
fn scurve_jog_lease_end_vs_monitor() {
    let mut r = ready(1000.0);
    r.step(op(jog(20.0, 100.0, Some(500.0))));
    r.idle(1500);
    assert!(r.tripped.is_none());
}

#[test]
fn change_adds_jerk_then_stop() {
    let mut r = ready(1000.0);
    r.step(op(jog(20.0, 100.0, None)));
    hold(&mut r, 300);
    r.step(op(Operation::Change(ChangeSpec {
        speed: None,
        accel: None,
        decel: None,
        jerk: Some(300.0),
    })));
    hold(&mut r, 100);
    r.step(op(Operation::Stop));
    r.idle(1000);
    assert!(r.tripped.is_none());
}

#[test]
fn change_slower_on_scurve_jog() {
    let mut r = ready(1000.0);
    r.step(op(Operation::Jog(JogSpec {
        speed: 20.0,
        lease: Some(5.0),
        accel: Some(100.0),
        decel: Some(100.0),
        jerk: Some(1000.0),
    })));
    r.idle(1000);
    r.step(op(Operation::Change(ChangeSpec {
        speed: Some(5.0),
        accel: None,
        decel: None,
        jerk: None,
    })));
    r.idle(1000);
}

#[test]
fn supersede_slower_scurve_move() {
    let mut r = ready(1000.0);
    let mv = |target: f64, speed: f64| {
        Operation::Move(MoveSpec {
            target,
            relative: false,
            speed: Some(speed),
            accel: Some(100.0),
            decel: Some(100.0),
            supersede: true,
            jerk: Some(1000.0),
        })
    };
    r.step(op(mv(500.0, 20.0)));
    r.idle(1000);
    r.step(op(mv(500.0, 5.0)));
    r.idle(1000);
}
