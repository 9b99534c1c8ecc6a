//! Hardware limit switches (the plant's `overtravel`) and the stops that
//! must end inside the software travel limits, with hand-worked distances.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::PlantConfig;

/// The switches trip beyond ±12 (the plant's `overtravel`: strictly
/// outside the interval); max_deceleration 2000.
fn switched() -> (AxisConfig, PlantConfig) {
    (
        AxisConfig {
            max_deceleration: 2000.0,
            ..op_axis()
        },
        PlantConfig {
            overtravel: Some((-12.0, 12.0)),
            ..op_plant(0.0)
        },
    )
}

/// A jog that runs for seconds.
fn long_jog(speed: f64) -> Operation {
    Operation::Jog(JogSpec {
        speed,
        accel: Some(500.0),
        decel: Some(500.0),
        lease: Some(secs(5_000 * MS)),
        jerk: None,
    })
}

#[test]
fn a_jog_into_a_limit_switch_stops_at_max_deceleration_as_a_fault() {
    // Unhomed (no soft limits), jog +20. The first command at or beyond 12
    // (a limit switch is actuated at its end, `[axis.sim] limit_switches`) is
    // applied by the plant; the next frame shows the switch; in that step
    // the stop begins from the command state there (20 u/s) at
    // max_deceleration 2000: 20² / (2·2000) = 0.1 further, not the jog's
    // 0.4.
    let (cfg, plant) = switched();
    let mut r = Rig::new(cfg, plant);
    r.enable();
    let id = r.op(long_jog(20.0)).unwrap();
    assert!(r.run_until(2000, |s| s.faulted));
    let s = *r.axis.status();
    assert_eq!((s.er, s.err, s.exerr), (true, 12, EX_OVERTRAVEL), "{s:?}");
    assert!(s.limit_positive && !s.limit_negative && !s.jogging && s.stopping);
    assert_eq!(s.last_stop, StopCause::LimitSwitch);
    assert_eq!((s.op.id, s.op.ip, s.op.pc), (id, false, false));
    let n = r.cmds.len();
    let first_beyond = r.cmds.iter().position(|c| c.position >= 12.0).unwrap();
    assert_eq!(first_beyond, n - 2, "seen one frame later");
    let at = r.cmds[n - 1].position;
    assert!(r.run_until(100, |s| !s.stopping));
    let end = r.cmds.last().unwrap().position;
    assert!((end - (at + 0.1)).abs() < 1e-9, "{end} vs {at}");
    assert!(
        r.cmds.last().unwrap().enable,
        "a controlled stop: still enabled"
    );
    // Faulted: towards refused (20); reset; towards refused (9); away allowed.
    assert_eq!(r.op(long_jog(1.0)), Err((ERR_AXIS_FAULTED, 0)));
    r.op(Operation::Reset).unwrap();
    r.run(5);
    let overtravel = Err((ERR_OVERTRAVEL_CONDITION, 0));
    assert_eq!(r.op(long_jog(1.0)), overtravel);
    assert_eq!(r.op(move_to(20.0)), overtravel);
    assert!(r.op(long_jog(-5.0)).is_ok());
    assert!(r.run_until(2000, |s| !s.limit_positive));
    assert!(!r.axis.status().faulted && r.axis.status().jogging);
}

#[test]
fn a_move_away_from_a_tripped_switch_is_allowed() {
    let (cfg, plant) = switched();
    let plant = PlantConfig {
        start: -12.5,
        ..plant
    };
    let mut r = Rig::new(cfg, plant);
    r.enable();
    assert!(r.axis.status().limit_negative);
    assert_eq!(r.op(move_to(-13.0)), Err((ERR_OVERTRAVEL_CONDITION, 0)));
    assert_eq!(r.op(long_jog(-1.0)), Err((ERR_OVERTRAVEL_CONDITION, 0)));
    r.op(move_to(-11.0)).unwrap();
    assert!(r.run_until(1000, |s| s.op.pc));
    assert!(!r.axis.status().limit_negative && !r.axis.status().er);
}

#[test]
fn limit_switches_off_ignores_the_inputs() {
    let (cfg, plant) = switched();
    let cfg = AxisConfig {
        limit_switches: false,
        ..cfg
    };
    let mut r = Rig::new(cfg, plant);
    r.enable();
    r.op(long_jog(20.0)).unwrap();
    r.run(1000);
    let s = *r.axis.status();
    assert!(r.plant.feedback().overtravel_positive, "the plant trips");
    assert!(s.jogging && !s.er && !s.limit_positive, "{s:?}");
}

#[test]
fn homing_ignores_the_switches_when_the_axis_has_none() {
    // A switch homing whose search passes a tripped limit input: 12/43
    // with limit_switches, homes without.
    let base = AxisConfig {
        max_speed: 50.0,
        ..axis(HomeSequence::Switch, HomeDirection::BidirectionalForward)
    };
    let plant = PlantConfig {
        overtravel: Some((-60.0, -40.0)),
        ..machine()
    };
    let o = run(base, plant, 0.001, 60.0);
    assert_eq!((o.status.err, o.status.exerr), (12, EX_OVERTRAVEL));
    let o = run(
        AxisConfig {
            limit_switches: false,
            ..base
        },
        plant,
        0.001,
        60.0,
    );
    assert!(o.status.pc, "{:?}", o.status);
}

#[test]
fn every_stop_of_an_operation_ends_inside_the_travel_limits() {
    // Homed, a stream at 40 u/s towards +10 with stream_acceleration
    // 100 000 u/s², while max_deceleration is 500: a refused setpoint at
    // 9.8 would need 40² / (2·500) = 1.6 to stop at max_deceleration —
    // past the limit. A stream's stop brakes at the larger of the two
    // (40² / 200 000 = 0.008), and never ends outside.
    let cfg = AxisConfig {
        stream_acceleration: 100_000.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    r.op(Operation::StreamStart).unwrap();
    // Ramp up to 40 u/s at 2000 u/s², then cruise: one setpoint per cycle.
    let (mut p, mut v, mut t) = (0.0, 0.0, 0u64);
    while p < 9.8 {
        t += MS;
        v = f64::min(v + 2.0, 40.0);
        p += v * 0.001;
        r.setpoint(t, p, None);
    }
    assert!(r.axis.status().streaming, "{:?}", r.axis.status());
    let at = r.cmd_axis();
    r.setpoint(t + MS, f64::NAN, None);
    let s = *r.axis.status();
    assert_eq!(
        (s.err, s.exerr),
        (ERR_SETPOINT_REFUSED, EX_SETPOINT_NOT_FINITE)
    );
    assert!(r.run_until(200, |s| !s.stopping));
    assert!(
        (r.cmd_axis() - (at + 0.008)).abs() < 1e-9,
        "{}",
        r.cmd_axis()
    );
    assert!(r.cmds.iter().all(|c| c.position <= 10.0));
}
