//! The supervised setpoint stream against the plant: exact at the cycle
//! rate, interpolated at 100 Hz, every refusal code, silence, order, the
//! first setpoint judged against the command, release and stop, the
//! reference cleared while streaming.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;

const CYCLE_S: f64 = 0.001;

/// Homed at 0 and streaming (StreamStart accepted).
fn streaming() -> Rig {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    r.op(Operation::StreamStart).unwrap();
    r
}

/// 1 − cos at 1 Hz (from rest at 0): at most 2π u/s and 4π² u/s², well
/// inside max_speed 50 and stream_acceleration 10 × 500.
fn sine(t_s: f64) -> f64 {
    1.0 - (2.0 * std::f64::consts::PI * t_s).cos()
}

/// A bad setpoint made from the good one's time and position.
type Bad = fn(u64, f64) -> (u64, f64, Option<f64>);

fn refused(r: &Rig, exerr: u16) {
    let s = r.axis.status();
    assert_eq!(
        (s.er, s.err, s.exerr),
        (true, ERR_SETPOINT_REFUSED, exerr),
        "{s:?}"
    );
    assert!(s.faulted && !s.streaming, "{s:?}");
    assert_eq!(s.last_stop, StopCause::SetpointRefused);
    assert!(!s.op.ip && !s.op.pc);
}

#[test]
fn at_the_cycle_rate_every_setpoint_is_commanded_exactly_in_the_step_it_arrives() {
    let mut r = streaming();
    let id = r.axis.status().op.id;
    for k in 0..=1000u64 {
        let p = sine(k as f64 * CYCLE_S);
        let cmd = r.setpoint(k * MS, p, None);
        assert_eq!(cmd.position, p, "setpoint {k}");
        if k > 0 {
            let v = (p - sine((k - 1) as f64 * CYCLE_S)) / CYCLE_S;
            assert!(
                (cmd.velocity - v).abs() < 1e-6,
                "{k}: {} vs {v}",
                cmd.velocity
            );
        }
    }
    let s = r.axis.status();
    assert!(s.streaming && !s.er && s.op.ip && s.op.id == id, "{s:?}");
    // The plant follows one cycle behind: where the last command went.
    r.run(1);
    assert_eq!(r.plant.position(), sine(1.0));
}

#[test]
fn a_100_hz_stream_is_interpolated_linearly_to_the_cycle() {
    // Setpoints every 10 ms, arriving every tenth step: the command walks
    // from one to the next in ten equal steps, landing on each exactly.
    let mut r = streaming();
    let mut prev = 0.0;
    for k in 0..=100u64 {
        let p = sine(k as f64 * 0.01);
        let cmd = r.setpoint(k * 10 * MS, p, None);
        if k == 0 {
            assert_eq!(cmd.position, 0.0);
            prev = p;
            continue;
        }
        // The setpoint's step is the first of its segment.
        let mut steps = vec![cmd];
        for _ in 1..10 {
            steps.push(r.step(Request::default()));
        }
        for (j, c) in steps.iter().enumerate() {
            let want = prev + (p - prev) * (j + 1) as f64 / 10.0;
            assert!(
                (c.position - want).abs() < 1e-12,
                "{k}.{j}: {} vs {want}",
                c.position
            );
            let v = (p - prev) / 0.01;
            assert!((c.velocity - v).abs() < 1e-9, "{k}.{j}");
        }
        assert_eq!(steps[9].position, p, "lands on it exactly");
        prev = p;
    }
    assert!(r.axis.status().streaming);
    // Linear segments: the velocity steps at each setpoint by at most
    // 4π² u/s² × 10 ms = 0.39 u/s, i.e. 395 u/s² over one cycle.
    let a = max_accel(&r.cmds, CYCLE_S);
    assert!(a < 400.0, "{a}");
}

#[test]
fn the_feed_forward_is_commanded_as_given() {
    let mut r = streaming();
    r.setpoint(0, 0.0, Some(0.0));
    let cmd = r.setpoint(MS, 0.002, Some(2.5));
    assert_eq!((cmd.position, cmd.velocity), (0.002, 2.5));
    // Resting on it after its segment: no velocity.
    let cmd = r.step(Request::default());
    assert_eq!((cmd.position, cmd.velocity), (0.002, 0.0));
}

#[test]
fn the_first_setpoint_is_judged_against_the_command_one_cycle_later() {
    // From rest at 0, one cycle: 4000 u/s² allows 0.004 (4 u/s), 0.006 is
    // 6 u/s in one cycle, 6000 u/s² > 5000.
    let mut r = streaming();
    r.setpoint(123 * MS, 0.004, None);
    assert!(r.axis.status().streaming && !r.axis.status().er);
    assert_eq!(r.cmds.last().unwrap().position, 0.004);
    let mut r = streaming();
    r.setpoint(123 * MS, 0.006, None);
    refused(&r, EX_SETPOINT_ACCELERATION);
}

#[test]
fn every_refusal_stops_the_axis_with_its_code() {
    // Moving at 5 u/s (0.005 per 1 ms setpoint) when the bad one comes: the
    // stop continues the last command at max_deceleration 500:
    // 5² / (2·500) = 0.025 beyond it.
    let cases: [(&str, Bad, u16); 6] = [
        (
            "not finite",
            |t, _| (t, f64::NAN, None),
            EX_SETPOINT_NOT_FINITE,
        ),
        (
            "ff not finite",
            |t, p| (t, p + 0.005, Some(f64::INFINITY)),
            EX_SETPOINT_NOT_FINITE,
        ),
        (
            "outside",
            |t, _| (t, 10.5, None),
            EX_SETPOINT_OUTSIDE_LIMITS,
        ),
        ("too fast", |t, p| (t, p + 0.06, None), EX_SETPOINT_SPEED),
        (
            "ff too fast",
            |t, p| (t, p + 0.005, Some(51.0)),
            EX_SETPOINT_SPEED,
        ),
        (
            "out of order",
            |t, p| (t - MS, p + 0.005, None),
            EX_SETPOINT_OUT_OF_ORDER,
        ),
    ];
    for (name, bad, exerr) in cases {
        let mut r = streaming();
        // Up to 5 u/s at 1000 u/s², then cruise.
        let (mut p, mut v) = (0.0, 0.0);
        for k in 0..100u64 {
            v = f64::min(v + 1.0, 5.0);
            p += v * CYCLE_S;
            r.setpoint(k * MS, p, None);
        }
        let last = r.cmds.last().unwrap().position;
        let (t, q, ff) = bad(100 * MS, p);
        r.setpoint(t, q, ff);
        refused(&r, exerr);
        assert!(r.run_until(100, |s| !s.stopping), "{name}");
        let end = r.cmds.last().unwrap().position;
        assert!(
            (end - (last + 0.025)).abs() < 1e-9,
            "{name}: {end} vs {last}"
        );
        assert!(r.cmds.last().unwrap().enable, "{name}: a controlled stop");
    }
    // A change of velocity above stream_acceleration (5000): from rest,
    // 0.004 then 0.004 + 0.0095 (4 → 9.5 u/s in 1 ms: 5500 u/s²).
    let mut r = streaming();
    r.setpoint(0, 0.004, None);
    r.setpoint(MS, 0.0135, None);
    refused(&r, EX_SETPOINT_ACCELERATION);
    // The time equal to the previous one is out of order too.
    let mut r = streaming();
    r.setpoint(5 * MS, 0.0, None);
    r.setpoint(5 * MS, 0.0, None);
    refused(&r, EX_SETPOINT_OUT_OF_ORDER);
}

#[test]
fn a_silent_stream_stops_after_stream_timeout() {
    // stream_timeout 50 ms, counted from when the command reached the last
    // setpoint: a 100 ms segment does not time out while it runs.
    let mut r = streaming();
    r.setpoint(0, 0.0, None);
    r.setpoint(100 * MS, 0.1, None);
    let reached = r.k - 1 + 99;
    assert!(r.run_until(1000, |s| s.faulted));
    assert_eq!(r.k - 1, reached + 51, "the first step after 50 ms of rest");
    refused(&r, EX_SETPOINT_STALE);
    assert_eq!(
        r.cmds.last().unwrap().position,
        0.1,
        "already at rest there"
    );
    // A stream that never sends anything stops as well.
    let mut r = streaming();
    assert!(r.run_until(100, |s| s.faulted));
    refused(&r, EX_SETPOINT_STALE);
}

#[test]
fn clearing_the_reference_stops_the_stream_unless_stream_unhomed() {
    let mut r = streaming();
    for k in 0..50u64 {
        r.setpoint(k * MS, 0.0, None);
    }
    assert!(r.axis.clear_homed());
    r.setpoint(50 * MS, 0.0, None);
    refused(&r, EX_SETPOINT_NOT_HOMED);
    // stream_unhomed: the stream goes on; it may even start unhomed.
    let cfg = AxisConfig {
        stream_unhomed: true,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable();
    r.op(Operation::StreamStart).unwrap();
    for k in 0..50u64 {
        r.setpoint(k * MS, k as f64 * 0.001, None);
    }
    let s = r.axis.status();
    assert!(s.streaming && !s.homed && !s.er, "{s:?}");
}

#[test]
fn release_lands_on_the_last_setpoint_and_stop_stops_at_once() {
    // 100 Hz ramp to 2 u/s, then a last setpoint; released right after it
    // arrived (its segment just begun): the axis lands on it exactly, at
    // rest, normally.
    let mut r = streaming();
    let mut p = 0.0;
    for k in 0..50u64 {
        p += 0.02 * f64::min(k as f64 / 10.0, 1.0);
        r.setpoint(k * 10 * MS, p, None);
        r.run(9);
    }
    p += 0.02;
    r.setpoint(50 * 10 * MS, p, None);
    let id = r.op(Operation::StreamEnd).unwrap();
    assert!(r.run_until(100, |s| !s.stopping));
    let s = *r.axis.status();
    assert_eq!(r.cmds.last().unwrap().position, p);
    assert_eq!((s.op.id, s.op.kind, s.op.pc), (id, OpKind::StreamEnd, true));
    assert!(!s.er && !s.streaming && s.servo_action);
    assert_eq!(s.last_stop, StopCause::Released);
    assert!(max_accel(&r.cmds, CYCLE_S) <= 500.0 + 1e-3);
    // A stream end with nothing streaming: accepted, nothing to do.
    let id = r.op(Operation::StreamEnd).unwrap();
    assert_eq!(
        r.axis.status().op,
        OpStatus {
            id,
            kind: OpKind::StreamEnd,
            ip: false,
            pc: true,
            refused: None,
        }
    );
    // Stop: at max_deceleration from the last command, normally.
    let mut r = streaming();
    for k in 0..100u64 {
        r.setpoint(k * MS, k as f64 * 0.005, None);
    }
    let last = r.cmds.last().unwrap().position;
    let stop = r.op(Operation::Stop).unwrap();
    assert!(r.run_until(100, |s| !s.stopping));
    let s = *r.axis.status();
    assert!((r.cmds.last().unwrap().position - (last + 0.025)).abs() < 1e-9);
    assert_eq!((s.op.id, s.op.pc, s.er), (stop, true, false));
    assert_eq!(s.last_stop, StopCause::Operator);
}

#[test]
fn a_stream_start_needs_an_idle_enabled_homed_axis() {
    let mut r = Rig::at(0.0);
    r.enable();
    assert_eq!(
        r.op(Operation::StreamStart),
        Err((ERR_SETPOINT_REFUSED, EX_SETPOINT_NOT_HOMED))
    );
    r.step(home());
    r.step(Request::default());
    r.op(jog(5.0)).unwrap();
    assert_eq!(
        r.op(Operation::StreamStart),
        Err((ERR_EXECUTION_COLLISION, 0))
    );
    r.op(Operation::Stop).unwrap();
    assert_eq!(
        r.op(Operation::StreamStart),
        Err((ERR_EXECUTION_COLLISION, 0)),
        "still stopping"
    );
    assert!(r.run_until(100, |s| !s.stopping));
    r.op(Operation::StreamStart).unwrap();
    // Streaming: jog and move collide; a second start too.
    assert_eq!(r.op(jog(5.0)), Err((ERR_EXECUTION_COLLISION, 0)));
    assert_eq!(r.op(move_to(1.0)), Err((ERR_EXECUTION_COLLISION, 0)));
    assert_eq!(
        r.op(Operation::StreamStart),
        Err((ERR_EXECUTION_COLLISION, 0))
    );
    // Not enabled.
    let mut r = Rig::at(0.0);
    r.run(1);
    r.step(home());
    assert_eq!(r.op(Operation::StreamStart), Err((ERR_SERVO_OFF, 0)));
    // No speed bound at all (immediate homing, no max_speed).
    let cfg = AxisConfig {
        max_speed: 0.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    assert_eq!(
        r.op(Operation::StreamStart),
        Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_SPEED))
    );
}

#[test]
fn a_cyclic_stream_wraps_the_shortest_way() {
    let cfg = AxisConfig {
        travel: TravelMode::Cyclic,
        unwind: 360.0,
        travel_limits: None,
        max_speed: 1000.0,
        home_acceleration: 5000.0,
        home_deceleration: 5000.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    r.op(Operation::StreamStart).unwrap();
    // 0, 0.2, 0.4 ... degrees: through 359.8 → 0 without a jump.
    let mut a: f64 = 0.0;
    for k in 0..4000u64 {
        let v = f64::min(k as f64 * 0.2, 200.0);
        a = (a + v * 0.001).rem_euclid(360.0);
        r.setpoint(k * MS, a, None);
    }
    let s = r.axis.status();
    assert!(s.streaming && !s.er, "{s:?}");
    assert!(r.cmds.last().unwrap().position > 360.0, "unwrapped raw");
    assert!((r.cmd_axis() - a).abs() < 1e-6);
    assert!(max_speed(&r.cmds, CYCLE_S) <= 200.0 + 1e-6);
}
