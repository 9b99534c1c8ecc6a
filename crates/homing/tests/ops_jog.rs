//! MAJ, hold to run, cycle by cycle against the plant: speed caps, the
//! lease, software overtravel with hand-worked stopping distances, the
//! reference changing under a jog, and every refusal of a jog.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;

const CYCLE_S: f64 = 0.001;

/// A request that renews the jog's lease.
fn renew() -> Request {
    Request {
        jog_renew: true,
        ..Request::default()
    }
}

/// Steps, renewing the lease, until `done` (at most `max`).
fn renewing_until(r: &mut Rig, max: u64, done: impl Fn(&Status) -> bool) -> bool {
    for _ in 0..max {
        r.step(renew());
        if done(r.axis.status()) {
            return true;
        }
    }
    false
}

#[test]
fn a_homed_jog_comes_to_rest_exactly_on_the_travel_limit() {
    // Homed at 0, limits ±10, jog +20 u/s, acceleration and deceleration
    // 500 u/s². By hand: accelerating takes 20 / 500 = 0.04 s over
    // 20² / (2·500) = 0.4; stopping takes the same 0.4, so the deceleration
    // begins at 10 − 0.4 = 9.6; cruising from 0.4 to 9.6 takes 9.2 / 20 =
    // 0.46 s. At rest on 10.0 after 0.04 + 0.46 + 0.04 = 0.54 s.
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let id = r.op(jog(20.0)).unwrap();
    let from = r.k - 1;
    assert!(renewing_until(&mut r, 1000, |s| !s.jogging));
    let s = *r.axis.status();
    assert_eq!(s.op.id, id);
    assert!(s.op.pc && !s.op.ip, "ended normally: {:?}", s.op);
    assert!(!s.er && !s.faulted && s.homed && s.servo_action, "{s:?}");
    assert_eq!(s.last_stop, StopCause::SoftLimit);
    let cmds = r.since(from);
    let ended = cmds.len() as f64 * CYCLE_S;
    assert!((ended - 0.54).abs() <= 0.0015, "at rest after {ended} s");
    assert_eq!(r.cmd_axis(), 10.0, "on the limit, exactly");
    assert!(cmds.iter().all(|c| c.position <= 10.0), "never past it");
    // Where the deceleration began: the last command at full speed.
    let cruise_end = cmds
        .windows(2)
        .filter(|w| (w[1].position - w[0].position) / CYCLE_S > 20.0 - 1e-6)
        .map(|w| w[1].position)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!((9.58..=9.6 + 1e-9).contains(&cruise_end), "{cruise_end}");
    assert!(max_speed(cmds, CYCLE_S) <= 20.0 + 1e-6);
    assert!(max_accel(cmds, CYCLE_S) <= 500.0 + 1e-3);
    r.run(5);
    assert_eq!(r.plant.position(), 10.0, "the plant rests there too");
    // Towards the limit reached: refused 13/4; away: accepted.
    assert_eq!(
        r.op(jog(5.0)),
        Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET))
    );
    assert!(r.op(jog(-5.0)).is_ok());
}

#[test]
fn a_stop_ends_a_jog_normally_after_its_stopping_distance() {
    // At 20 u/s with deceleration 500: 20² / (2·500) = 0.4 further.
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let id = r.op(jog(-20.0)).unwrap();
    for _ in 0..100 {
        r.step(renew());
    }
    let stop = r.op(Operation::Stop).unwrap();
    let at = r.cmds.last().unwrap().position;
    assert!(r.axis.status().stopping && !r.axis.status().jogging);
    assert!(r.run_until(100, |s| !s.stopping));
    let s = *r.axis.status();
    assert!(
        (r.cmd_axis() - (at - 0.4)).abs() < 1e-9,
        "{} vs {at}",
        r.cmd_axis()
    );
    assert!(!s.er && s.homed && s.servo_action, "{s:?}");
    assert_eq!(s.last_stop, StopCause::Operator);
    assert_eq!((s.op.id, s.op.pc), (stop, true));
    assert_ne!(id, stop);
    // The drive stays enabled, holding.
    assert!(r.cmds.last().unwrap().enable);
}

#[test]
fn a_request_stop_ends_the_jog_and_gives_it_pc() {
    let (mut r, id) = jogging_with_id();
    r.step(Request {
        stop: true,
        ..Request::default()
    });
    assert!(r.run_until(100, |s| !s.stopping));
    let s = r.axis.status();
    assert_eq!((s.op.id, s.op.ip, s.op.pc), (id, false, true));
    assert_eq!(s.last_stop, StopCause::Operator);
}

#[test]
fn the_lease_keeps_a_renewed_jog_and_stops_one_that_is_not() {
    // Unhomed (no limits), 10 u/s, lease 100 ms, renewed every 50 ms for
    // a second: it still runs. Then no renewal: it stops normally once
    // the lease has run out — the first step after 100 ms — within
    // 10² / (2·500) = 0.1 of where it was then.
    let mut r = Rig::at(0.0);
    r.enable();
    let lease = Operation::Jog(JogSpec {
        speed: 10.0,
        accel: Some(500.0),
        decel: Some(500.0),
        lease: Some(secs(100 * MS)),
        jerk: None,
    });
    let id = r.op(lease).unwrap();
    for k in 1..=1000 {
        r.step(Request {
            jog_renew: k % 50 == 0,
            ..Request::default()
        });
    }
    assert!(r.axis.status().jogging, "renewed: {:?}", r.axis.status());
    // The last renewal was at the 1000th step: runs until 100 ms after it.
    let renewed_at = r.k - 1;
    assert!(r.run_until(200, |s| !s.jogging));
    let stopped_at = r.k - 1;
    assert_eq!(stopped_at - renewed_at, 101, "first step after the lease");
    let at = r.cmds.last().unwrap().position;
    assert!(r.run_until(100, |s| !s.stopping));
    let s = *r.axis.status();
    assert!((r.cmds.last().unwrap().position - (at + 0.1)).abs() < 1e-9);
    assert_eq!(s.last_stop, StopCause::LeaseExpired);
    assert!(!s.er && !s.faulted, "a lease is not an error: {s:?}");
    assert_eq!((s.op.id, s.op.pc), (id, true));
}

#[test]
fn unhomed_jogs_are_capped_and_not_limited() {
    let mut r = Rig::at(0.0);
    r.enable();
    // Cap: unhomed_speed defaults to home_speed 20.
    let speed = (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_SPEED);
    assert_eq!(r.op(jog(20.5)), Err(speed));
    assert!(r.op(jog(20.0)).is_ok());
    // No soft limit: runs past 10 (the travel limit) unhomed.
    for _ in 0..2000 {
        r.step(renew());
    }
    assert!(r.cmd_axis() > 30.0, "{}", r.cmd_axis());
    assert!(r.axis.status().jogging);
    // Homed, up to max_speed (50); above it refused.
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    assert_eq!(r.op(jog(50.5)), Err(speed));
    assert!(r.op(jog(-50.0)).is_ok());
}

#[test]
fn unhome_during_a_jog_drops_the_limit_and_slows_to_the_cap() {
    // Homed at 0, jogging +40 (above the unhomed cap 20) from -9.
    let cfg = AxisConfig {
        home_position: -9.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    let fast = Operation::Jog(JogSpec {
        speed: 40.0,
        accel: Some(500.0),
        decel: Some(500.0),
        lease: Some(secs(5_000 * MS)),
        jerk: None,
    });
    r.op(fast).unwrap();
    r.run(100);
    assert!(r.axis.clear_homed());
    // It slows down to 20 with its deceleration (40 → 20: 40 ms), then
    // cruises: no limit at 10 any more.
    r.run(100);
    let v = (r.cmds[r.cmds.len() - 1].position - r.cmds[r.cmds.len() - 2].position) / CYCLE_S;
    assert!((v - 20.0).abs() < 1e-6, "{v}");
    r.run(1000);
    let s = r.axis.status();
    assert!(s.jogging && !s.homed && !s.er, "{s:?}");
    assert!(r.cmd_axis() > 10.0, "{}", r.cmd_axis());
    assert!(max_accel(&r.cmds, CYCLE_S) <= 500.0 + 1e-3);
}

#[test]
fn a_jog_replaces_a_jog_and_may_not_replace_a_move() {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let first = r.op(jog(10.0)).unwrap();
    r.run(100);
    let second = r.op(jog(-10.0)).unwrap();
    assert_ne!(first, second);
    // Reverses with the new jog's deceleration (no jump).
    r.run(200);
    assert!(max_accel(&r.cmds, CYCLE_S) <= 500.0 + 1e-3);
    assert!(r.axis.status().jogging);
    r.op(Operation::Stop).unwrap();
    assert!(r.run_until(100, |s| !s.stopping));
    r.op(move_to(5.0)).unwrap();
    assert_eq!(r.op(jog(5.0)), Err((ERR_EXECUTION_COLLISION, 0)));
    assert!(r.axis.status().moving, "the move goes on");
}

#[test]
fn a_jog_checks_every_operand() {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let j = |speed: f64, accel: f64, decel: f64, lease_ns: u64| {
        Operation::Jog(JogSpec {
            speed,
            accel: Some(accel),
            decel: Some(decel),
            lease: Some(secs(lease_ns)),
            jerk: None,
        })
    };
    let p = ERR_PARAMETER_OUT_OF_RANGE;
    for (op, code) in [
        (j(0.0, 500.0, 500.0, 500 * MS), (p, EX_PARAM_SPEED)),
        (j(f64::NAN, 500.0, 500.0, 500 * MS), (p, EX_PARAM_SPEED)),
        (
            j(f64::INFINITY, 500.0, 500.0, 500 * MS),
            (p, EX_PARAM_SPEED),
        ),
        (j(1e308, 500.0, 500.0, 500 * MS), (p, EX_PARAM_SPEED)),
        (j(5.0, 0.0, 500.0, 500 * MS), (p, EX_PARAM_ACCELERATION)),
        (j(5.0, -1.0, 500.0, 500 * MS), (p, EX_PARAM_ACCELERATION)),
        (
            j(5.0, f64::NAN, 500.0, 500 * MS),
            (p, EX_PARAM_ACCELERATION),
        ),
        (j(5.0, 500.0, 0.0, 500 * MS), (p, EX_PARAM_DECELERATION)),
        // Above max_deceleration (= home_deceleration 500 by default).
        (j(5.0, 500.0, 501.0, 500 * MS), (p, EX_PARAM_DECELERATION)),
        (j(5.0, 500.0, 500.0, 49 * MS), (p, EX_PARAM_LEASE)),
        (j(5.0, 500.0, 500.0, 5_001 * MS), (p, EX_PARAM_LEASE)),
        (j(5.0, 500.0, 500.0, 0), (p, EX_PARAM_LEASE)),
    ] {
        assert_eq!(r.op(op), Err(code), "{op:?}");
        let s = r.axis.status();
        assert!(
            !s.jogging && !s.er && !s.faulted,
            "a refusal changes nothing"
        );
    }
    assert!(r.op(j(5.0, 500.0, 500.0, 50 * MS)).is_ok());
}

#[test]
fn a_jog_needs_an_enabled_axis_that_is_not_homing() {
    // Not enabled: servo off.
    let mut r = Rig::at(0.0);
    r.run(2);
    assert_eq!(r.op(jog(5.0)), Err((ERR_SERVO_OFF, 0)));
    // Homing in process: 16 (a switch homing seeking its switch).
    let mut r = at_the_seek();
    assert_eq!(r.op(jog(5.0)), Err((ERR_HOME_IN_PROCESS, 0)));
    assert_eq!(r.op(move_to(5.0)), Err((ERR_HOME_IN_PROCESS, 0)));
    assert_eq!(r.op(Operation::StreamStart), Err((ERR_HOME_IN_PROCESS, 0)));
    assert_eq!(r.op(Operation::Enable), Err((ERR_HOME_IN_PROCESS, 0)));
    assert_eq!(r.op(Operation::Reset), Err((ERR_HOME_IN_PROCESS, 0)));
    assert!(r.axis.status().ip, "homing goes on");
}

#[test]
fn home_is_refused_while_jogging_and_takes_over_a_stop() {
    let mut r = Rig::at(0.0);
    r.enable();
    r.op(jog(10.0)).unwrap();
    r.run(20);
    r.step(home());
    let s = *r.axis.status();
    assert!(s.er && s.err == ERR_EXECUTION_COLLISION && !s.ip, "{s:?}");
    assert!(s.jogging && !s.faulted, "the jog goes on: {s:?}");
    // Stopped: a home (a new rising edge) takes the stop over and homes.
    r.step(Request::default());
    r.op(Operation::Stop).unwrap();
    r.step(home());
    let s = *r.axis.status();
    assert!(s.homed && s.pc && !s.stopping, "{s:?}");
}
