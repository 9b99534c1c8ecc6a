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

/// Enabled, not homed, streaming (`stream_unhomed`).
fn unhomed_streaming() -> Rig {
    let cfg = AxisConfig {
        stream_unhomed: true,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable();
    r.op(Operation::StreamStart).unwrap();
    r
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
    // stop continues the last command at the larger of max_deceleration
    // (500) and stream_acceleration (5000): 5² / (2·5000) = 0.0025 beyond.
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
            (end - (last + 0.0025)).abs() < 1e-9,
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
    // stream_timeout 50 ms, counted from when the last setpoint arrived —
    // not from the end of its segment: a 100 ms segment with nothing after
    // it stops half-way (at 0.05, then its stop: 1² / (2·5000)).
    let mut r = streaming();
    r.setpoint(0, 0.0, None);
    r.setpoint(100 * MS, 0.1, None);
    let arrived = r.k - 1;
    assert!(r.run_until(1000, |s| s.faulted));
    assert_eq!(r.k - 1, arrived + 51, "the first step after 50 ms");
    refused(&r, EX_SETPOINT_STALE);
    assert!(r.run_until(100, |s| !s.stopping));
    let end = r.cmds.last().unwrap().position;
    assert!((end - (0.051 + 1.0 / 10_000.0)).abs() < 1e-9, "{end}");
    // Setpoints every 40 ms (less than 50) keep it going, at rest too.
    let mut r = streaming();
    for k in 0..10u64 {
        r.setpoint(k * 40 * MS, 0.0, None);
        r.run(39);
    }
    assert!(r.axis.status().streaming && !r.axis.status().er);
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
    let mut r = unhomed_streaming();
    for k in 0..50u64 {
        r.setpoint(k * MS, k as f64 * 0.001, None);
    }
    let s = r.axis.status();
    assert!(s.streaming && !s.homed && !s.er, "{s:?}");
}

#[test]
fn release_stops_at_once_and_a_program_at_rest_ends_on_its_last_setpoint() {
    // 100 Hz ramp to 2 u/s, then down to rest on a last setpoint; the
    // program waits for its segment (10 ms) and releases: the axis is on
    // it, at rest, normally.
    let mut r = streaming();
    let mut p = 0.0;
    let speeds: Vec<f64> = (0..60)
        .map(|k: i32| 0.02 * f64::min(f64::from(k.min(59 - k)) / 10.0, 1.0))
        .collect();
    for (k, dp) in speeds.iter().enumerate() {
        p += dp;
        r.setpoint(k as u64 * 10 * MS, p, None);
        r.run(9);
    }
    let id = r.op(Operation::StreamEnd).unwrap();
    assert!(r.run_until(100, |s| !s.stopping));
    let s = *r.axis.status();
    assert_eq!(r.cmds.last().unwrap().position, p);
    assert_eq!((s.op.id, s.op.kind, s.op.pc), (id, OpKind::StreamEnd, true));
    assert!(!s.er && !s.streaming && s.servo_action);
    assert_eq!(s.last_stop, StopCause::Released);
    assert!(max_accel(&r.cmds, CYCLE_S) <= 5000.0 + 1e-3);
    // Released while moving (2 u/s, its last setpoint 0.02 ahead): it stops
    // from where the command is at the stream's deceleration (5000),
    // 2² / 10 000 = 0.0004 on — not at the setpoint.
    let mut r = streaming();
    let mut p = 0.0;
    for k in 0..50u64 {
        p += 0.02 * f64::min(k as f64 / 10.0, 1.0);
        r.setpoint(k * 10 * MS, p, None);
        r.run(9);
    }
    r.setpoint(50 * 10 * MS, p + 0.02, None);
    let at = r.cmds.last().unwrap().position;
    r.op(Operation::StreamEnd).unwrap();
    assert!(r.run_until(100, |s| !s.stopping));
    let end = r.cmds.last().unwrap().position;
    assert!((end - (at + 0.0004)).abs() < 1e-9, "{at} → {end}");
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
    // Stop: at the stream's deceleration from the last command, normally.
    let mut r = streaming();
    for k in 0..100u64 {
        r.setpoint(k * MS, k as f64 * 0.005, None);
    }
    let last = r.cmds.last().unwrap().position;
    let stop = r.op(Operation::Stop).unwrap();
    assert!(r.run_until(100, |s| !s.stopping));
    let s = *r.axis.status();
    assert!((r.cmds.last().unwrap().position - (last + 0.0025)).abs() < 1e-9);
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
        Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_NO_MAX_SPEED))
    );
    // Unhomed with stream_unhomed but no unhomed cap (no unhomed_speed, no
    // home_speed): nothing could move it.
    let cfg = AxisConfig {
        stream_unhomed: true,
        home_speed: 0.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable();
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

/// One hour, ns.
const HOUR: u64 = 3_600_000 * MS;

/// The commands from step `from` on obey the stream's limits on the
/// cycle's timeline: speed within `vmax`, change of velocity between two
/// cycles within `accel` × cycle.
fn within_limits(r: &Rig, from: u64, vmax: f64, accel: f64) {
    let cmds = r.since(from);
    let v = max_speed(cmds, CYCLE_S);
    assert!(v <= vmax * (1.0 + 1e-9), "speed {v} > {vmax}");
    let a = max_accel(cmds, CYCLE_S);
    assert!(a <= accel * (1.0 + 1e-6), "acceleration {a} > {accel}");
}

#[test]
fn a_setpoint_is_never_followed_faster_or_harder_than_the_limits_whatever_its_timestamps() {
    // The program's clock says an hour from 0 to 9, then 1 ms at rest on
    // 9: each passes the checks on the program's timeline; on the cycle's
    // the last asks for 9 units in one cycle. Nothing of it reaches the
    // drive: the axis would lag it by far more than it can stop in.
    let mut r = streaming();
    let from = r.k - 1;
    r.setpoint(0, 0.0, None);
    r.setpoint(HOUR, 9.0, None);
    r.setpoint(HOUR + MS, 9.0, None);
    refused(&r, EX_SETPOINT_ACCELERATION);
    assert!(r.run_until(100, |s| !s.stopping));
    within_limits(&r, from, 50.0, 5000.0);
    assert!(r.cmds.last().unwrap().position.abs() < 1e-4, "did not move");
    // The same trick in two steps, and a catch-up faster than max_speed:
    // followed within the limits, or refused — never faster or harder.
    for (t, p) in [(2 * MS, 0.003), (30 * MS, 0.9), (31 * MS, 2.0)] {
        let mut r = streaming();
        let from = r.k - 1;
        r.setpoint(0, 0.0, None);
        r.run(5);
        r.setpoint(t, p, None);
        r.run(300);
        within_limits(&r, from, 50.0, 5000.0);
    }
}

#[test]
fn an_honest_stream_with_sparse_setpoints_is_followed_within_the_limits() {
    // Setpoints 20 ms apart, reversing at full speed: 50 → −50 u/s in one
    // setpoint, 5000 u/s² on the program's timeline (within the bound) but
    // one cycle on the linear interpolation. The command rounds the corner
    // at 5000 u/s² — or refuses if it cannot keep up — never harder.
    let mut r = streaming();
    let from = r.k - 1;
    let path = [0.0, 0.5, 1.5, 2.5, 1.5, 0.5, -0.5, -1.5, -0.5, 0.5];
    for (k, &p) in path.iter().enumerate() {
        r.setpoint(k as u64 * 20 * MS, p, None);
        r.run(19);
    }
    r.run(200);
    within_limits(&r, from, 50.0, 5000.0);
    // A 1 Hz (1 − cos) at 50 Hz: corners of 0.8 u/s, which the command
    // takes in one cycle (5 u/s allowed): on every setpoint exactly.
    let mut r = streaming();
    let from = r.k - 1;
    for k in 0..=50u64 {
        let p = sine(k as f64 * 0.02);
        r.setpoint(k * 20 * MS, p, None);
        r.run(19);
        assert_eq!(r.cmds.last().unwrap().position, p, "{k}");
    }
    let s = r.axis.status();
    assert!(s.streaming && !s.er, "{s:?}");
    within_limits(&r, from, 50.0, 5000.0);
}

#[test]
fn a_late_setpoint_brakes_the_command_within_the_limits() {
    // 1 kHz at 30 u/s, then one setpoint 5 cycles late: the command does
    // not stop dead on the last one (30 000 u/s² in one cycle); it brakes
    // at stream_acceleration and catches up when the stream resumes.
    let mut r = streaming();
    let from = r.k - 1;
    let (mut p, mut v) = (0.0, 0.0);
    for k in 0..200u64 {
        if k == 100 {
            r.run(5);
        }
        v = f64::min(v + 2.0, 30.0);
        p += v * CYCLE_S;
        r.setpoint(k * MS, p, None);
    }
    let s = r.axis.status();
    assert!(s.streaming && !s.er, "{s:?}");
    within_limits(&r, from, 50.0, 5000.0);
}

/// Streaming, a setpoint at 0, then one 10 s ahead at 9 (0.9 u/s).
fn far_ahead() -> Rig {
    let mut r = streaming();
    r.setpoint(0, 0.0, None);
    r.setpoint(10_000 * MS, 9.0, None);
    r
}

#[test]
fn a_program_that_falls_silent_is_stopped_from_its_last_setpoints_arrival() {
    // A setpoint 10 s ahead (0.9 u/s), then nothing: the axis stops
    // stream_timeout (50 ms) after it arrived, not at the end of its
    // segment — a hung program runs out nothing.
    let mut r = far_ahead();
    let arrived = r.k - 1;
    assert!(r.run_until(1000, |s| s.faulted), "{:?}", r.axis.status());
    assert_eq!(r.k - 1, arrived + 51, "the first step after 50 ms");
    refused(&r, EX_SETPOINT_STALE);
    assert!(r.run_until(100, |s| !s.stopping));
    // 0.9 u/s for 51 ms, then 0.9² / (2 × 5000) to stop.
    let end = r.cmds.last().unwrap().position;
    assert!(end <= 0.9 * 0.051 + 1e-4 && end > 0.0, "{end}");
}

#[test]
fn a_released_stream_stops_at_once_however_far_its_last_setpoint_lies() {
    // The owner asks for 9 units 10 s away and is gone (released, or its
    // death noticed): the axis stops now, at the stream's deceleration.
    let mut r = far_ahead();
    r.run(20);
    let id = r.op(Operation::StreamEnd).unwrap();
    let at = r.cmds[r.cmds.len() - 2].position;
    assert!(r.run_until(100, |s| !s.stopping), "{:?}", r.axis.status());
    let s = *r.axis.status();
    assert_eq!((s.op.id, s.op.pc, s.er), (id, true, false));
    assert_eq!(s.last_stop, StopCause::Released);
    let end = r.cmds.last().unwrap().position;
    assert!(end - at <= 0.9 * CYCLE_S + 1e-4, "{at} → {end}");
}

#[test]
fn a_fault_mid_stream_stops_inside_the_travel_limits_at_a_deceleration_that_can() {
    // The program cruises at 40 u/s towards the limit at 10 and brakes at
    // stream_acceleration (5000) to rest on it: 0.16 from 9.84 (a
    // trapezoid sampled every cycle). Feedback goes bad while it brakes —
    // not a number, lost (noticed feedback_timeout later: from 9.45 on),
    // or a jump — which clears HomedStatus in the same step. The stop keeps
    // the travel limits that applied when it began and brakes hard enough:
    // at max_deceleration (500) it would end 1.4 beyond the limit.
    type Frame = fn(u64, Feedback) -> Option<Feedback>;
    let bad: [(&str, f64, Frame, u16); 3] = [
        (
            "not a number",
            9.85,
            |_, mut fb| {
                fb.position = f64::NAN;
                Some(fb)
            },
            EX_FEEDBACK_INVALID,
        ),
        ("lost", 9.45, |_, _| None, EX_FEEDBACK_LOST),
        (
            "a jump",
            9.85,
            |_, mut fb| {
                fb.position += 5.0;
                Some(fb)
            },
            EX_FEEDBACK_IMPLAUSIBLE,
        ),
    ];
    let path = profile::Profile::move_to(0, 0.0, 0.0, 10.0, 40.0, 5000.0, 5000.0);
    for (name, from, frame, exerr) in bad {
        let mut r = streaming();
        let mut t = 0;
        while !r.axis.status().faulted && t < 1000 * MS {
            let p = path.sample(t).0;
            r.setpoint(t, p, None);
            if p >= from {
                r.frame = frame;
            }
            t += MS;
        }
        let s = *r.axis.status();
        assert!(s.faulted && !s.homed, "{name}: {s:?}");
        assert_eq!((s.err, s.exerr), (12, exerr), "{name}");
        let at = r.cmds.last().unwrap().position;
        assert!(at < 9.99, "{name}: faulted at {at}, still braking");
        r.run(300);
        // What the drive was asked to follow (once the feedback is lost and
        // the axis at rest, the power stage is requested off and the
        // command shows where the feedback, bad or not, says it is).
        let on: Vec<Command> = r.cmds.iter().filter(|c| c.enable).copied().collect();
        let most = on.iter().map(|c| c.position).fold(f64::MIN, f64::max);
        assert!(most <= 10.0 + 1e-9, "{name}: commanded {most}");
        let a = max_accel(&on, CYCLE_S);
        assert!(a <= 5000.0 * (1.0 + 1e-6), "{name}: acceleration {a}");
    }
}

#[test]
fn an_unhomed_stream_obeys_unhomed_speed() {
    // stream_unhomed: not homed, the cap is unhomed_speed (20 here, from
    // home_speed) as for jog and move, not max_speed (50).
    let mut r = unhomed_streaming();
    let from = r.k - 1;
    let (mut p, mut v) = (0.0, 0.0);
    for k in 0..100u64 {
        v = f64::min(v + 1.0, 30.0);
        p += v * CYCLE_S;
        r.setpoint(k * MS, p, None);
    }
    refused(&r, EX_SETPOINT_SPEED);
    assert!(r.run_until(100, |s| !s.stopping));
    within_limits(&r, from, 20.0, 5000.0);
    // A setpoint's feed-forward above the cap is refused as well.
    let mut r = unhomed_streaming();
    r.setpoint(0, 0.0, Some(25.0));
    refused(&r, EX_SETPOINT_SPEED);
}
