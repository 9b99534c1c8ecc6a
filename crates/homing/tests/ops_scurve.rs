//! S-curve jogs, moves and their stops, and MCD `change`, cycle by cycle
//! against the plant: between two commands the speed stays within its
//! cap, the acceleration within its bounds and the change of acceleration
//! within the jerk (third difference of the commanded positions / T³); a
//! move ends bit for bit on its target; a normal stop keeps the jerk, a
//! fault's stop does not; a change re-plans from the exact state (no step
//! in position, velocity or acceleration) and is refused where it cannot
//! be kept; the travel limits are never crossed.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;

const CYCLE_S: f64 = 0.001;

/// Largest |third difference| / cycle³ of the commanded positions: the
/// jerk the drive was asked for.
fn max_jerk(cmds: &[Command]) -> f64 {
    cmds.windows(4)
        .map(|w| {
            (w[3].position - 3.0 * w[2].position + 3.0 * w[1].position - w[0].position).abs()
                / (CYCLE_S * CYCLE_S * CYCLE_S)
        })
        .fold(0.0, f64::max)
}

/// Rounding of positions around 10 units, seen through a third
/// difference over a 1 ms cycle (a few ulps of 10 / 1e-9 s³).
const JERK_ROUNDING: f64 = 0.1;

/// Rounding of a planned position near 10 units: far below a count (1e-3).
const ROUNDING: f64 = 1e-9;

/// A jog at `speed` (a = d = 500, lease 500 ms) with `jerk`.
fn jog_j(speed: f64, jerk: f64) -> Operation {
    Operation::Jog(JogSpec {
        speed,
        accel: Some(500.0),
        decel: Some(500.0),
        lease: Some(0.5),
        jerk: Some(jerk),
    })
}

/// A move to `target` at 20 (a = d = 500) with `jerk`.
fn move_j(target: f64, jerk: f64) -> Operation {
    Operation::Move(MoveSpec {
        jerk: Some(jerk),
        ..move_spec(target)
    })
}

fn renew() -> Request {
    Request {
        jog_renew: true,
        ..Request::default()
    }
}

/// One cycle with a change: answered in place (the running operation's id
/// unchanged), `Err` with the refusal.
fn change(r: &mut Rig, c: ChangeSpec) -> Result<(), (u16, u16)> {
    let before = r.axis.status().op;
    r.step(Request {
        op: Some(Operation::Change(c)),
        ..Request::default()
    });
    let after = r.axis.status().op;
    assert_eq!(after.id, before.id, "a change keeps the motion's id");
    match after.refused {
        None => Ok(()),
        Some(code) => Err(code),
    }
}

/// Enabled and homed at 0, at rest: the rig and the cycle of its last
/// command before any motion (where `since` starts to see it all).
fn homed_at_rest() -> (Rig, u64) {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let from = r.k - 1;
    (r, from)
}

#[test]
fn an_s_curve_jog_keeps_its_bounds_and_rests_exactly_on_the_limit() {
    // Homed, limits ±10, jog +20 at a = d = 500 with jerk 20 000: the
    // acceleration ramps over 500 / 20 000 = 25 ms instead of stepping.
    let (mut r, from) = homed_at_rest();
    let id = r.op(jog_j(20.0, 20_000.0)).unwrap();
    for _ in 0..2000 {
        r.step(renew());
        if !r.axis.status().jogging {
            break;
        }
    }
    let s = *r.axis.status();
    assert_eq!((s.op.id, s.op.pc), (id, true), "{s:?}");
    assert_eq!(s.last_stop, StopCause::SoftLimit);
    assert_eq!(r.cmd_axis(), 10.0, "on the limit, exactly");
    let cmds = r.since(from);
    assert!(cmds.iter().all(|c| c.position <= 10.0), "never past it");
    assert!(max_speed(cmds, CYCLE_S) <= 20.0 + 1e-6);
    assert!(max_accel(cmds, CYCLE_S) <= 500.0 + 1e-3);
    let j = max_jerk(cmds);
    assert!(j <= 20_000.0 + JERK_ROUNDING, "jerk {j}");
    // A trapezoid's would step the acceleration: 500 / 1 ms per cycle.
    assert!(j > 10_000.0, "the jerk is used: {j}");
}

#[test]
fn an_s_curve_move_ends_exactly_on_its_target_within_its_bounds() {
    let (mut r, from) = homed_at_rest();
    let id = r.op(move_j(7.25, 10_000.0)).unwrap();
    assert!(r.run_until(3000, |s| !s.moving));
    let s = *r.axis.status();
    assert_eq!((s.op.id, s.op.pc, s.er), (id, true, false), "{s:?}");
    assert_eq!(r.cmd_axis(), 7.25, "bit for bit");
    let cmds = r.since(from);
    assert!(max_speed(cmds, CYCLE_S) <= 20.0 + 1e-6);
    assert!(max_accel(cmds, CYCLE_S) <= 500.0 + 1e-3);
    let j = max_jerk(cmds);
    assert!(
        (5_000.0..=10_000.0 + JERK_ROUNDING).contains(&j),
        "jerk {j}"
    );
    assert!(cmds.iter().all(|c| c.position <= 7.25), "no overshoot");
    r.run(5);
    assert_eq!(r.cmd_axis(), 7.25, "and stays there");
}

#[test]
fn the_axis_jerk_is_the_default_and_a_request_overrides_it() {
    let cfg = AxisConfig {
        jerk: 8_000.0,
        ..op_axis()
    };
    let mut r = Rig::new(cfg, op_plant(0.0));
    r.enable_and_home();
    let from = r.k - 1;
    r.op(move_to(5.0)).unwrap();
    assert!(r.run_until(3000, |s| !s.moving));
    let j = max_jerk(r.since(from));
    assert!((4_000.0..=8_000.0 + JERK_ROUNDING).contains(&j), "{j}");
    // jerk 0 given: a trapezoid, whatever the axis says.
    let from = r.k - 1;
    r.op(move_j(0.0, 0.0)).unwrap();
    assert!(r.run_until(3000, |s| !s.moving));
    assert!(max_jerk(r.since(from)) > 100_000.0);
}

#[test]
fn a_bad_jerk_is_refused_with_13_8() {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let bad = (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_JERK);
    for j in [-1.0, f64::INFINITY, f64::NEG_INFINITY, 1e13] {
        assert_eq!(r.op(jog_j(5.0, j)), Err(bad), "{j}");
        assert_eq!(r.op(move_j(5.0, j)), Err(bad), "{j}");
    }
    assert!(!r.axis.status().jogging && !r.axis.status().moving);
}

/// Jogs unhomed at `speed` with `jerk` for 300 ms, then `end` ends it;
/// the commands from the jog's start to rest.
fn jog_then(end: impl FnOnce(&mut Rig), speed: f64, jerk: f64) -> (Rig, u64) {
    let mut r = Rig::at(0.0);
    r.enable();
    let from = r.k;
    r.op(jog_j(speed, jerk)).unwrap();
    for _ in 0..300 {
        r.step(renew());
    }
    end(&mut r);
    assert!(r.run_until(2000, |s| !s.stopping && !s.jogging));
    (r, from)
}

#[test]
fn a_normal_stop_keeps_the_jerk() {
    // MAS.
    let (r, from) = jog_then(|r| assert!(r.op(Operation::Stop).is_ok()), 15.0, 5_000.0);
    assert_eq!(r.axis.status().last_stop, StopCause::Operator);
    let j = max_jerk(r.since(from));
    assert!(j <= 5_000.0 + JERK_ROUNDING, "stop's jerk {j}");
    // The lease running out.
    let (r, from) = jog_then(|_| {}, -15.0, 5_000.0);
    assert_eq!(r.axis.status().last_stop, StopCause::LeaseExpired);
    assert!(max_jerk(r.since(from)) <= 5_000.0 + JERK_ROUNDING);
    // A disable's stop.
    let (r, from) = jog_then(|r| assert!(r.op(Operation::Disable).is_ok()), 15.0, 5_000.0);
    assert_eq!(r.axis.status().last_stop, StopCause::Disable);
    assert!(max_jerk(r.since(from)) <= 5_000.0 + JERK_ROUNDING);
}

/// Unhomed and enabled at 0, jogging at 15 u/s with `jerk` towards a
/// limit switch at 3.
fn jogging_towards_a_switch(jerk: f64) -> Rig {
    let plant = motion_plant::PlantConfig {
        overtravel: Some((-3.0, 3.0)),
        ..op_plant(0.0)
    };
    let mut r = Rig::new(op_axis(), plant);
    r.enable();
    r.op(jog_j(15.0, jerk)).unwrap();
    r
}

/// Steps with `request()` (at most 2000 cycles) until the limit switch
/// has tripped and the stop it began has ended: the cycle of the step
/// it tripped in, `None` if it never tripped.
fn stopped_by_the_switch(r: &mut Rig, request: impl Fn() -> Request) -> Option<u64> {
    let mut tripped = None;
    for _ in 0..2000 {
        r.step(request());
        let s = *r.axis.status();
        if tripped.is_none() && s.last_stop == StopCause::LimitSwitch {
            tripped = Some(r.k - 1);
        }
        if tripped.is_some() && !s.stopping {
            break;
        }
    }
    tripped
}

#[test]
fn a_faults_stop_does_not_keep_the_jerk() {
    // Unhomed towards a limit switch at 3: the trip stops the axis at
    // max_deceleration (500) with jerk 0 — the shortest stop, v²/2d past
    // where it began — and ER 12 / 43.
    let mut r = jogging_towards_a_switch(2_000.0);
    let k = stopped_by_the_switch(&mut r, renew).expect("the limit switch stopped it");
    let s = *r.axis.status();
    assert_eq!((s.er, s.err, s.exerr), (true, 12, EX_OVERTRAVEL));
    let cmds = &r.cmds[(k - 1) as usize..];
    let v = (cmds[1].position - cmds[0].position) / CYCLE_S;
    let end = r.cmds.last().unwrap().position;
    // The trapezoid's stop from the state the fault's step started from.
    let shortest = v * v / (2.0 * 500.0);
    assert!(
        end - cmds[0].position <= shortest + v * CYCLE_S + 1e-9,
        "stopped within {} of {}, shortest {shortest}",
        end - cmds[0].position,
        cmds[0].position
    );
    // The acceleration stepped: a jerk the S-curve would never ask for.
    assert!(max_jerk(cmds) > 100_000.0, "{}", max_jerk(cmds));
}

#[test]
fn a_fault_during_an_s_curve_stop_replans_it_without_jerk() {
    // Unhomed at 15 u/s with jerk 1000 (its stop takes ≈ 1.8 units), a
    // stop at 2 would end ≈ 3.8: past the limit switch at 3. The switch
    // trips during the S-curve stop: a fault, which does not let the
    // gentle stop run on but stops with jerk 0 (the acceleration steps).
    let mut r = jogging_towards_a_switch(1_000.0);
    while r.cmds.last().unwrap().position < 2.0 {
        r.step(renew());
    }
    r.op(Operation::Stop).unwrap();
    let k = stopped_by_the_switch(&mut r, Request::default)
        .expect("the switch tripped during the stop");
    let s = *r.axis.status();
    assert_eq!((s.er, s.err, s.exerr), (true, 12, EX_OVERTRAVEL), "{s:?}");
    let tail = &r.cmds[(k - 2) as usize..];
    assert!(max_jerk(tail) > 100_000.0, "{}", max_jerk(tail));
    assert!(r.cmds.last().unwrap().position < 3.5);
}

#[test]
fn a_change_replans_from_the_exact_state_without_a_step() {
    // A long S-curve move; changed while it accelerates (the acceleration
    // is neither 0 nor its bound) to a lower speed and jerk, then again
    // while it cruises.
    let mut r = Rig::new(
        AxisConfig {
            travel_limits: Some((-100.0, 100.0)),
            ..op_axis()
        },
        op_plant(0.0),
    );
    r.enable_and_home();
    let from = r.k - 1;
    let id = r
        .op(Operation::Move(MoveSpec {
            speed: Some(40.0),
            ..spec_of(move_j(60.0, 4_000.0))
        }))
        .unwrap();
    r.run(30);
    let before = r.cmds.len();
    let slower = ChangeSpec {
        speed: Some(10.0),
        jerk: Some(3_000.0),
        ..ChangeSpec::none()
    };
    assert_eq!(change(&mut r, slower), Ok(()));
    assert!(r.axis.status().moving);
    r.run(5);
    // Across the change: the jerk of the two plans, nothing more.
    let around = &r.cmds[before - 4..before + 4];
    assert!(
        max_jerk(around) <= 4_000.0 + JERK_ROUNDING,
        "{}",
        max_jerk(around)
    );
    r.run(1500);
    let v = (r.cmds.last().unwrap().position - r.cmds[r.cmds.len() - 2].position) / CYCLE_S;
    assert!((v - 10.0).abs() < 1e-6, "cruising at the new speed: {v}");
    let cruise = r.cmds.len();
    assert_eq!(
        change(
            &mut r,
            ChangeSpec {
                speed: Some(30.0),
                decel: Some(250.0),
                ..ChangeSpec::none()
            }
        ),
        Ok(())
    );
    assert!(r.run_until(10_000, |s| !s.moving));
    let s = *r.axis.status();
    assert_eq!(
        (s.op.id, s.op.pc, s.op.kind),
        (id, true, OpKind::Move),
        "{s:?}"
    );
    assert_eq!(r.cmd_axis(), 60.0, "on the target, bit for bit");
    let cmds = r.since(from);
    assert!(max_speed(cmds, CYCLE_S) <= 40.0 + 1e-6);
    assert!(max_accel(cmds, CYCLE_S) <= 500.0 + 1e-3);
    assert!(max_jerk(cmds) <= 4_000.0 + JERK_ROUNDING);
    let after = &r.cmds[cruise - 3..];
    assert!(max_speed(after, CYCLE_S) <= 30.0 + 1e-6);
    assert!(max_jerk(after) <= 3_000.0 + JERK_ROUNDING);
}

/// The spec of a move operation.
fn spec_of(op: Operation) -> MoveSpec {
    match op {
        Operation::Move(m) => m,
        _ => unreachable!(),
    }
}

#[test]
fn a_change_of_a_jog_keeps_its_direction_and_its_lease() {
    let mut r = Rig::at(0.0);
    r.enable();
    let id = r.op(jog_j(-5.0, 0.0)).unwrap();
    r.run(50);
    let faster = ChangeSpec {
        speed: Some(15.0),
        jerk: Some(10_000.0),
        ..ChangeSpec::none()
    };
    assert_eq!(change(&mut r, faster), Ok(()));
    for _ in 0..200 {
        r.step(renew());
    }
    let n = r.cmds.len();
    let v = (r.cmds[n - 1].position - r.cmds[n - 2].position) / CYCLE_S;
    assert!((v + 15.0).abs() < 1e-6, "{v}");
    assert_eq!(r.axis.status().op.id, id);
    assert!(r.axis.status().jogging);
    // Not renewed: its lease still ends it, with the new jerk.
    let from = r.k;
    assert!(r.run_until(2000, |s| !s.jogging && !s.stopping));
    assert_eq!(r.axis.status().last_stop, StopCause::LeaseExpired);
    assert!(max_jerk(r.since(from)) <= 10_000.0 + JERK_ROUNDING);
}

#[test]
fn a_change_is_refused_where_it_cannot_be_kept() {
    let none = ChangeSpec::none();
    // A change any running motion could take.
    let slower = ChangeSpec {
        speed: Some(1.0),
        ..none
    };
    let nothing = (ERR_EXECUTION_COLLISION, EX_NOTHING_TO_CHANGE);
    let range = |ex| Err((ERR_PARAMETER_OUT_OF_RANGE, ex));
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    // Nothing runs.
    assert_eq!(change(&mut r, none), Err(nothing));
    // Operands, on a running jog: each refused, the jog unchanged.
    r.op(jog_j(5.0, 0.0)).unwrap();
    for (c, why) in [
        (
            ChangeSpec {
                speed: Some(0.0),
                ..none
            },
            range(EX_PARAM_SPEED),
        ),
        (
            ChangeSpec {
                speed: Some(-5.0),
                ..none
            },
            range(EX_PARAM_SPEED),
        ),
        (
            ChangeSpec {
                speed: Some(51.0),
                ..none
            },
            range(EX_PARAM_SPEED),
        ),
        (
            ChangeSpec {
                accel: Some(0.0),
                ..none
            },
            range(EX_PARAM_ACCELERATION),
        ),
        (
            ChangeSpec {
                decel: Some(501.0),
                ..none
            },
            range(EX_PARAM_DECELERATION),
        ),
        (
            ChangeSpec {
                jerk: Some(-1.0),
                ..none
            },
            range(EX_PARAM_JERK),
        ),
        (
            ChangeSpec {
                jerk: Some(f64::INFINITY),
                ..none
            },
            range(EX_PARAM_JERK),
        ),
    ] {
        assert_eq!(change(&mut r, c), why, "{c:?}");
        r.step(renew());
    }
    assert!(r.axis.status().jogging);
    // Stopping: nothing to change.
    r.op(Operation::Stop).unwrap();
    assert_eq!(change(&mut r, slower), Err(nothing));
    assert!(r.run_until(1000, |s| !s.stopping));
    // A stream: its program owns the dynamics.
    r.op(Operation::StreamStart).unwrap();
    assert_eq!(change(&mut r, slower), Err((ERR_EXECUTION_COLLISION, 0)));
    r.op(Operation::StreamEnd).unwrap();
    assert!(r.run_until(1000, |s| !s.stopping && !s.streaming));
    // Homing in process: 16.
    let mut h = Rig::new(
        AxisConfig {
            max_speed: 50.0,
            cycle_ns: MS,
            ..axis(
                HomeSequence::SwitchThenMarker,
                HomeDirection::BidirectionalForward,
            )
        },
        machine(),
    );
    h.enable();
    h.step(home());
    h.run(10);
    assert!(h.axis.status().ip);
    assert_eq!(change(&mut h, slower), Err((ERR_HOME_IN_PROCESS, 0)));
}

/// Homed at 0, jogging at 20 u/s (a = d = 500, trapezoid) towards the
/// travel limit 10, renewed until its command is at `at` or past it: the
/// rig and the first cycle after homing.
fn jogging_to_the_limit_past(at: f64) -> (Rig, u64) {
    let mut r = Rig::at(0.0);
    r.enable_and_home();
    let from = r.k;
    r.op(jog(20.0)).unwrap();
    while r.cmd_axis() < at {
        r.step(renew());
    }
    (r, from)
}

#[test]
fn a_deceleration_that_cannot_stop_inside_the_limit_is_refused() {
    // Homed jog +20 towards the limit 10 (a = d = 500): at 8 its stop needs
    // 0.4; a deceleration of 100 would need 2 and end at 10+: refused
    // 13 / 4, and the jog still rests exactly on the limit.
    let (mut r, from) = jogging_to_the_limit_past(8.0);
    // The softer deceleration, then a jerk so soft its stop runs past the
    // limit: both refused.
    let softer = ChangeSpec {
        decel: Some(100.0),
        ..ChangeSpec::none()
    };
    let soft_jerk = ChangeSpec {
        jerk: Some(100.0),
        ..ChangeSpec::none()
    };
    for c in [softer, soft_jerk] {
        assert_eq!(
            change(&mut r, c),
            Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET)),
            "{c:?}"
        );
    }
    while r.axis.status().jogging {
        r.step(renew());
    }
    assert_eq!(r.cmd_axis(), 10.0);
    assert!(r.since(from).iter().all(|c| c.position <= 10.0));
}

#[test]
fn a_supersede_whose_s_curve_stop_would_cross_the_limit_is_refused() {
    // Cruising at 20 towards 10, at 8: a move back to 0 must first stop.
    // With jerk 1000 that stop takes 2·√(20/1000) ≈ 0.28 s and ≈ 2.8
    // units — past the limit; the trapezoid's v²/2d = 0.4 would not be.
    let (mut r, _) = jogging_to_the_limit_past(8.0);
    let back = Operation::Move(MoveSpec {
        supersede: true,
        ..spec_of(move_j(0.0, 1_000.0))
    });
    assert_eq!(
        r.op(back),
        Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET))
    );
    // Earlier, at 5, the same move fits (ends ≈ 7.8): accepted, and it
    // never passes the limit on its way back.
    let (mut r, from) = jogging_to_the_limit_past(5.0);
    r.op(back).unwrap();
    assert!(r.run_until(5000, |s| !s.moving));
    assert_eq!(r.cmd_axis(), 0.0);
    assert!(r.since(from).iter().all(|c| c.position <= 10.0));
}

#[test]
fn s_curve_jogs_never_cross_the_travel_limits() {
    // Every jerk from soft to stiff, both directions: a stiff jog at 20
    // towards one limit, reversed at 7 units from the start by a jog with
    // that jerk towards the other — whose stop at its jerk must fit before
    // the near limit (else refused 13 / 4, and the first jog rests on its
    // limit). At rest on a limit, never beyond.
    for jerk in [50.0, 300.0, 2_000.0, 20_000.0, 1e6] {
        for dir in [1.0, -1.0] {
            let mut r = Rig::at(0.0);
            r.enable_and_home();
            let from = r.k;
            r.op(jog_j(-dir * 20.0, 1e6)).unwrap();
            while r.cmd_axis().abs() < 7.0 && r.axis.status().jogging {
                r.step(renew());
            }
            let end = match r.op(jog_j(dir * 20.0, jerk)) {
                Ok(_) => dir * 10.0,
                Err(code) => {
                    assert_eq!(code, (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_TARGET));
                    -dir * 10.0
                }
            };
            while r.axis.status().jogging || r.axis.status().stopping {
                r.step(renew());
            }
            assert_eq!(r.cmd_axis(), end, "jerk {jerk} dir {dir}");
            // An S-curve that turns back may sample its approach a few ulps
            // past the target before landing on it bit for bit: rounding,
            // a millionth of a count here, never a count.
            assert!(
                r.since(from)
                    .iter()
                    .all(|c| c.position.abs() <= 10.0 + ROUNDING),
                "jerk {jerk} dir {dir}"
            );
        }
    }
}
