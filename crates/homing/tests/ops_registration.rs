//! Registration (MAR / MDR) against the plant: the drive's latch exact to
//! the count on either edge of the home switch (normally open and closed)
//! and on the marker, the sampled edge within half a cycle's travel where
//! the drive has no latch, the window, during a jog, a move and a stream
//! (which run exactly as they would unarmed), disarm, homing, refusals.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;

/// Unhomed (axis = raw) on the test machine: switch over [0, 5], markers
/// at 2.5 + 10 k; `latch`: the drive latches the switch and the marker.
fn rig(start: f64, latch: bool) -> Rig {
    let cfg = AxisConfig {
        marker: true,
        marker_latch: latch,
        registration: latch,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, machine_at(start));
    r.enable();
    r
}

/// One cycle with `op`, answered in place: `Ok` when accepted.
fn ask(r: &mut Rig, op: Operation) -> Result<(), (u16, u16)> {
    let before = r.axis.status().op;
    r.step(Request {
        op: Some(op),
        ..Request::default()
    });
    let after = r.axis.status().op;
    assert_eq!((after.id, after.kind), (before.id, before.kind), "in place");
    after.refused.map_or(Ok(()), Err)
}

fn arm(input: LatchInput, edge: LatchEdge, window: Option<(f64, f64)>) -> Operation {
    Operation::Arm(ArmSpec {
        input,
        edge,
        window,
    })
}

/// A move to `target` at `speed`.
fn move_at(target: f64, speed: f64) -> Operation {
    Operation::Move(MoveSpec {
        speed: Some(speed),
        ..MoveSpec::to(target)
    })
}

/// Moves to `target` at `speed` and back at rest: the latched position.
fn latched_on_move(r: &mut Rig, target: f64, speed: f64) -> Option<f64> {
    let id = r.op(move_at(target, speed)).unwrap();
    assert!(r.run_until(30_000, |s| s.op.id == id && s.op.pc));
    let s = r.axis.status();
    assert!(!s.er, "{s:?}");
    s.registration_position
}

#[test]
fn the_drive_latch_takes_either_edge_of_the_switch_exactly() {
    for nc in [false, true] {
        for (edge, from, to, at) in [
            (LatchEdge::Rising, -3.0, 8.0, 0.0),
            (LatchEdge::Falling, -3.0, 8.0, 5.0),
            (LatchEdge::Rising, 8.0, -3.0, 5.0),
            (LatchEdge::Falling, 8.0, -3.0, 0.0),
        ] {
            let cfg = AxisConfig {
                registration: true,
                home_switch_normally_closed: nc,
                ..op_axis()
            };
            let plant = motion_plant::PlantConfig {
                switch_normally_closed: nc,
                ..machine_at(from)
            };
            let mut r = Rig::new(cfg, plant);
            r.enable();
            ask(&mut r, arm(LatchInput::Switch, edge, None)).unwrap();
            assert!(r.axis.status().registration_armed);
            assert_eq!(r.axis.status().registration_position, None);
            let got = latched_on_move(&mut r, to, 10.0);
            assert_eq!(got, Some(at), "nc {nc} {edge:?} {from} → {to}");
            assert!(!r.axis.status().registration_armed);
        }
    }
}

#[test]
fn the_drive_latch_takes_the_marker_exactly_and_the_window_passes_over_edges_outside() {
    let mut r = rig(-3.0, true);
    ask(&mut r, arm(LatchInput::Marker, LatchEdge::Rising, None)).unwrap();
    assert_eq!(latched_on_move(&mut r, 8.0, 10.0), Some(2.5));
    // 2.5 lies outside [10, 20]: 12.5 is the one.
    ask(
        &mut r,
        arm(LatchInput::Marker, LatchEdge::Falling, Some((10.0, 20.0))),
    )
    .unwrap();
    assert_eq!(latched_on_move(&mut r, -5.0, 10.0), None, "none at -7.5");
    assert!(r.axis.status().registration_armed);
    assert_eq!(latched_on_move(&mut r, 15.0, 10.0), Some(12.5));
    // The switch's rising edge at 0 outside [1, 3]: nothing latched.
    ask(
        &mut r,
        arm(LatchInput::Switch, LatchEdge::Rising, Some((1.0, 3.0))),
    )
    .unwrap();
    assert_eq!(latched_on_move(&mut r, -3.0, 10.0), None);
    assert_eq!(latched_on_move(&mut r, 8.0, 10.0), None);
    assert!(r.axis.status().registration_armed);
}

/// Without a drive latch: sampled, within half the travel of a cycle
/// (speed × cycle / 2), for every speed and start phase tried.
#[test]
fn without_a_drive_latch_the_edge_is_sampled_within_half_a_cycle_of_travel() {
    let mut worst: f64 = 0.0;
    for speed in [1.0, 7.3, 10.0, 19.9] {
        for phase in 0..5 {
            let from = -3.0 - 0.000_37 * phase as f64;
            for (input, edge, to, at) in [
                (LatchInput::Switch, LatchEdge::Rising, 8.0, 0.0),
                (LatchInput::Switch, LatchEdge::Falling, 8.0, 5.0),
                (LatchInput::Marker, LatchEdge::Rising, 8.0, 2.5),
            ] {
                let mut r = rig(from, false);
                ask(&mut r, arm(input, edge, None)).unwrap();
                let got = latched_on_move(&mut r, to, speed).expect("latched");
                let bound = speed * 0.001 / 2.0;
                let err = (got - at).abs();
                assert!(
                    err <= bound + 1e-9,
                    "{input:?} {edge:?} at {speed} u/s: {got} vs {at}"
                );
                worst = worst.max(err / (speed * 0.001));
            }
        }
    }
    eprintln!("sampled registration: worst error {worst:.3} × speed × cycle");
}

#[test]
fn an_edge_before_the_arming_does_not_count_and_disarm_ends_it() {
    // Armed for the falling edge while on the switch: the edge at 5.
    let mut r = rig(3.0, false);
    ask(&mut r, arm(LatchInput::Switch, LatchEdge::Falling, None)).unwrap();
    let got = latched_on_move(&mut r, 8.0, 10.0).unwrap();
    assert!((got - 5.0).abs() <= 0.005 + 1e-9, "{got}");
    // Disarmed: the edge passes unlatched, the last position stays.
    ask(&mut r, arm(LatchInput::Switch, LatchEdge::Rising, None)).unwrap();
    assert_eq!(r.axis.status().registration_position, None);
    ask(&mut r, Operation::Disarm).unwrap();
    assert!(!r.axis.status().registration_armed);
    assert_eq!(latched_on_move(&mut r, 4.0, 10.0), None);
    // Disarm with nothing armed: accepted, nothing changes.
    ask(&mut r, Operation::Disarm).unwrap();
}

/// A move (and a jog) runs exactly as it would unarmed, keeps its id and
/// ends with PC.
#[test]
fn an_armed_registration_changes_nothing_of_a_move_or_a_jog() {
    let run = |armed: bool| {
        let mut r = rig(-3.0, true);
        if armed {
            ask(&mut r, arm(LatchInput::Switch, LatchEdge::Rising, None)).unwrap();
        }
        let from = r.k as usize;
        let id = r.op(move_at(8.0, 10.0)).unwrap();
        r.run(10);
        if armed {
            // Armed again while the move runs: the move keeps its id.
            ask(&mut r, arm(LatchInput::Switch, LatchEdge::Rising, None)).unwrap();
        }
        assert!(r.run_until(5000, |s| s.op.id == id && s.op.pc));
        r.run(20);
        let s = *r.axis.status();
        let cmds: Vec<f64> = r.cmds[from..].iter().map(|c| c.position).collect();
        (cmds, s.registration_position)
    };
    let (plain, none) = run(false);
    let (armed, at) = run(true);
    assert_eq!((none, at), (None, Some(0.0)));
    assert_eq!(armed, plain, "every command the same");

    // A jog (hold to run): armed for the marker mid-jog, latched, the jog
    // still runs with its id.
    let mut r = rig(-3.0, true);
    let renew = Request {
        jog_renew: true,
        ..Request::default()
    };
    let id = r.op(jog(10.0)).unwrap();
    r.step(renew);
    ask(&mut r, arm(LatchInput::Marker, LatchEdge::Rising, None)).unwrap();
    for _ in 0..700 {
        r.step(renew);
    }
    let s = *r.axis.status();
    assert!(s.jogging && s.op.id == id && s.op.ip, "{s:?}");
    assert_eq!(s.registration_position, Some(2.5));
}

/// Homed at 3 (axis = raw + 3), streaming across the switch: the position
/// is in axis coordinates, the stream never disturbed.
#[test]
fn during_a_stream_the_position_is_latched_in_axis_coordinates() {
    let cfg = AxisConfig {
        registration: true,
        home_position: 3.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, machine_at(-2.0));
    r.enable_and_home();
    r.op(Operation::StreamStart).unwrap();
    ask(&mut r, arm(LatchInput::Switch, LatchEdge::Rising, None)).unwrap();
    // 3 u/s from axis 3 (raw -2) to axis 9 (raw 4).
    let t0 = r.now();
    for k in 1..=2000u64 {
        let p = (3.0 + 3.0 * k as f64 * 0.001).min(9.0);
        r.setpoint(t0 + k * MS, p, None);
    }
    let s = *r.axis.status();
    assert!(s.streaming && !s.er, "{s:?}");
    assert_eq!(s.registration_position, Some(5.0), "raw 0 + 3");
}

#[test]
fn refusals_and_homing() {
    // Virtual: no inputs.
    let v = AxisConfig {
        configuration: AxisConfiguration::Virtual,
        ..op_axis()
    };
    let mut r = Rig::new(v, op_plant(0.0));
    r.run(2);
    let sw = arm(LatchInput::Switch, LatchEdge::Rising, None);
    assert_eq!(
        ask(&mut r, sw),
        Err((ERR_REGISTRATION_REFUSED, EX_REGISTRATION_NO_FEEDBACK_DEVICE))
    );
    // No marker on the axis.
    let mut r = Rig::new(op_axis(), machine_at(-3.0));
    r.run(2);
    assert_eq!(
        ask(&mut r, arm(LatchInput::Marker, LatchEdge::Rising, None)),
        Err((ERR_REGISTRATION_REFUSED, EX_REGISTRATION_NO_MARKER))
    );
    // Windows.
    for (w, exerr) in [
        ((f64::NAN, 1.0), EX_REGISTRATION_WINDOW_NOT_FINITE),
        ((0.0, f64::INFINITY), EX_REGISTRATION_WINDOW_NOT_FINITE),
        ((2.0, 1.0), EX_REGISTRATION_WINDOW_EMPTY),
    ] {
        let op = arm(LatchInput::Switch, LatchEdge::Rising, Some(w));
        assert_eq!(ask(&mut r, op), Err((ERR_REGISTRATION_REFUSED, exerr)));
        assert!(!r.axis.status().registration_armed);
    }
    // A point window is a window; a faulted axis may still be armed
    // (registration only watches).
    ask(
        &mut r,
        arm(LatchInput::Switch, LatchEdge::Rising, Some((1.0, 1.0))),
    )
    .unwrap();

    // Homing in process: refused (16); a homing that starts disarms.
    let cfg = AxisConfig {
        marker: true,
        ..axis(HomeSequence::Switch, HomeDirection::BidirectionalForward)
    };
    let mut r = Rig::new(cfg, machine_at(-20.0));
    r.run(2);
    ask(&mut r, sw).unwrap();
    r.step(home());
    let s = *r.axis.status();
    assert!(s.ip && !s.registration_armed, "{s:?}");
    assert_eq!(ask(&mut r, sw), Err((ERR_HOME_IN_PROCESS, 0)));
    assert!(r.run_until(20_000, |s| s.dn));
    assert!(r.axis.status().pc);
    assert_eq!(r.axis.status().registration_position, None);
}
