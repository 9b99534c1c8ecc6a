//! Property tests of the operations around homing, over random sequences
//! of operations, setpoints, renewals and idle time:
//!
//! * no jog, move or stream ever commands a position outside
//!   `travel_limits` on a homed linear axis (to within 1e-9 units of
//!   floating-point rounding: the limits are compared in axis coordinates,
//!   the command is raw);
//! * every command stays finite whatever the operations' numbers and the
//!   setpoints are (NaN, ±inf, ±1e308, subnormals, any lease or time).

mod common;

use common::*;
use motion_homing::*;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// One input of a run: a step with an operation, a setpoint or a renewal,
/// or idle cycles.
#[derive(Clone, Debug)]
enum Input {
    Op(Operation),
    /// Program time advance (ns) and change of the program's velocity
    /// (the position moves on at it; or to an absolute position with
    /// `jump`), optional feed-forward.
    Setpoint {
        dt_ns: u64,
        dv: f64,
        jump: Option<f64>,
        velocity: Option<f64>,
    },
    Renew,
    Idle(u16),
}

fn runner(cases: u32) -> TestRunner {
    TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    })
}

/// The operations without parameters, each as likely as the others.
fn bare_op() -> impl Strategy<Value = Operation> {
    prop::sample::select(vec![
        Operation::StreamStart,
        Operation::StreamEnd,
        Operation::Stop,
        Operation::Reset,
        Operation::Enable,
        Operation::Disable,
    ])
}

/// Operations with numbers a user might give, limits crossed often.
fn sane_op() -> impl Strategy<Value = Operation> {
    let dynamics = (1.0..60.0f64, 50.0..5000.0f64, 50.0..6000.0f64);
    prop_oneof![
        2 => (dynamics.clone(), any::<bool>(), 50u64..600).prop_map(|((s, a, d), neg, lease)| {
            Operation::Jog(JogSpec {
                speed: if neg { -s } else { s },
                accel: Some(a),
                decel: Some(d),
                lease: Some(secs(lease * MS)), jerk: None, })
        }),
        2 => (dynamics, -15.0..15.0f64, any::<bool>(), any::<bool>()).prop_map(
            |((speed, accel, decel), target, relative, supersede)| Operation::Move(MoveSpec {
                target,
                relative,
                speed: Some(speed),
                accel: Some(accel),
                decel: Some(decel),
                supersede, jerk: None, })
        ),
        6 => bare_op(),
    ]
}

fn sane_inputs() -> impl Strategy<Value = Vec<Input>> {
    let input = prop_oneof![
        3 => sane_op().prop_map(Input::Op),
        6 => (
            1u64..20,
            -8.0..8.0f64,
            prop::option::weighted(0.03, -12.0..12.0f64),
            prop::option::weighted(0.2, -60.0..60.0f64),
        )
            .prop_map(|(ms, dv, jump, velocity)| Input::Setpoint {
                dt_ns: ms * MS,
                dv,
                jump,
                velocity,
            }),
        1 => Just(Input::Renew),
        2 => (1u16..300).prop_map(Input::Idle),
    ];
    prop::collection::vec(input, 1..60)
}

/// Runs `inputs` on `r`, calling `check` after every step with the command.
fn play(
    r: &mut Rig,
    inputs: &[Input],
    mut check: impl FnMut(&Rig, &Command) -> Result<(), String>,
) -> Result<(), String> {
    let mut t_ns: u64 = 0;
    let mut pos = r.cmd_axis();
    let mut v = 0.0;
    let mut one = |r: &mut Rig, req: Request| -> Result<(), String> {
        let cmd = r.step(req);
        check(r, &cmd)
    };
    for input in inputs {
        match *input {
            Input::Op(op) => one(
                r,
                Request {
                    op: Some(op),
                    ..Request::default()
                },
            )?,
            Input::Setpoint {
                dt_ns,
                dv,
                jump,
                velocity,
            } => {
                t_ns = t_ns.wrapping_add(dt_ns);
                v = (v + dv).clamp(-60.0, 60.0);
                pos = jump.unwrap_or(pos + v * (dt_ns as f64 * 1e-9));
                one(
                    r,
                    Request {
                        setpoint: Some(Setpoint {
                            t_ns,
                            position: pos,
                            velocity,
                        }),
                        ..Request::default()
                    },
                )?
            }
            Input::Renew => one(
                r,
                Request {
                    jog_renew: true,
                    ..Request::default()
                },
            )?,
            Input::Idle(n) => {
                for _ in 0..n {
                    one(r, Request::default())?;
                }
            }
        }
    }
    Ok(())
}

#[test]
fn no_operation_commands_a_position_outside_the_travel_limits_of_a_homed_linear_axis() {
    let machine = (
        -9.9..9.9f64,                                        // where it homes
        prop::sample::select(&[500.0, 2000.0, 5000.0][..]),  // max_deceleration
        prop::sample::select(&[0.0, 1000.0, 100_000.0][..]), // stream_acceleration
    );
    runner(256)
        .run(
            &(machine, sane_inputs()),
            |((at, max_dec, stream_acc), inputs)| {
                let cfg = AxisConfig {
                    home_position: at,
                    max_deceleration: max_dec,
                    stream_acceleration: stream_acc,
                    ..op_axis()
                };
                let mut r = Rig::new(cfg, op_plant(0.0));
                r.enable_and_home();
                let res = play(&mut r, &inputs, |r, cmd| {
                    let s = r.axis.status();
                    if !s.homed {
                        return Err(format!("lost HomedStatus: {s:?}"));
                    }
                    let x = r.axis.to_axis(cmd.position);
                    if !(-10.0 - 1e-9..=10.0 + 1e-9).contains(&x) {
                        return Err(format!("commanded {x} at step {}: {s:?}", r.k - 1));
                    }
                    Ok(())
                });
                prop_assert!(res.is_ok(), "{}", res.unwrap_err());
                Ok(())
            },
        )
        .unwrap();
}

#[test]
fn a_stream_stopped_at_speed_near_a_travel_limit_stops_inside_it() {
    // A program heads for a limit at up to 50 u/s, decelerating late and
    // hard (up to its 100 000 u/s² bound, far above max_deceleration), and
    // is cut off at a random moment: a bad setpoint, an operator stop, a
    // release, silence. However the axis is stopped, it stays inside.
    let case = (
        (any::<bool>(), 5.0..50.0f64, 100.0..100_000.0f64, 1u64..20),
        (0u8..4, 0.0..1.0f64),
        prop::sample::select(&[500.0, 2000.0][..]),
    );
    runner(256)
        .run(&case, |((up, vmax, acc, ms), (how, when), max_dec)| {
            let cfg = AxisConfig {
                max_deceleration: max_dec,
                stream_acceleration: 100_000.0,
                ..op_axis()
            };
            let mut r = Rig::new(cfg, op_plant(0.0));
            r.enable_and_home();
            r.op(Operation::StreamStart).unwrap();
            let dir = if up { 1.0 } else { -1.0 };
            let dt = ms as f64 * 1e-3;
            // Plan: accelerate at `acc` to `vmax`, decelerate at `acc` to
            // rest exactly on the limit; cut off after `when` of the way.
            let brake = vmax * vmax / (2.0 * acc);
            let (mut p, mut v, mut t) = (0.0f64, 0.0f64, 0u64);
            let mut out = Vec::new();
            while (10.0 - p.abs()) > 1e-9 {
                let left = 10.0 - p * dir;
                v = if left <= brake + v * dt {
                    (2.0 * acc * (left - v * dt).max(0.0)).sqrt().min(v)
                } else {
                    (v + acc * dt).min(vmax)
                };
                p = (p + dir * v.max(1e-3) * dt).clamp(-10.0, 10.0);
                t += ms * MS;
                out.push((t, p));
            }
            let cut = ((out.len() as f64 * when) as usize).min(out.len() - 1);
            for &(t, p) in &out[..cut] {
                r.setpoint(t, p, None);
                for _ in 1..ms {
                    r.run(1);
                }
            }
            let t = out[cut].0;
            match how {
                0 => {
                    r.setpoint(t, f64::NAN, None);
                }
                1 => {
                    r.op(Operation::Stop).unwrap();
                }
                2 => {
                    r.op(Operation::StreamEnd).unwrap();
                }
                _ => {}
            }
            r.run(200);
            prop_assert!(!r.axis.status().stopping);
            for (k, c) in r.cmds.iter().enumerate() {
                let x = r.axis.to_axis(c.position);
                prop_assert!(
                    (-10.0 - 1e-9..=10.0 + 1e-9).contains(&x),
                    "step {k}: {x} ({:?})",
                    r.axis.status()
                );
            }
            Ok(())
        })
        .unwrap();
}

/// Numbers that break arithmetic.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => prop::sample::select(&[
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e308,
            -1e308,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            0.0,
            -0.0,
        ][..]),
        2 => -1e6..1e6f64,
        1 => any::<f64>(),
    ]
}

/// A wild number, or left out (the axis's default then applies).
fn maybe_wild() -> impl Strategy<Value = Option<f64>> {
    proptest::option::of(wild())
}

fn wild_op() -> impl Strategy<Value = Operation> {
    prop_oneof![
        2 => (wild(), maybe_wild(), maybe_wild(), maybe_wild()).prop_map(
            |(speed, accel, decel, lease)| Operation::Jog(JogSpec {
                speed,
                lease,
                accel,
                decel, jerk: None, })
        ),
        2 => (wild(), any::<bool>(), maybe_wild(), maybe_wild(), maybe_wild(), any::<bool>())
            .prop_map(|(target, relative, speed, accel, decel, supersede)| {
                Operation::Move(MoveSpec {
                    target,
                    relative,
                    speed,
                    accel,
                    decel,
                    supersede, jerk: None, })
            }),
        6 => bare_op(),
    ]
}

fn wild_inputs() -> impl Strategy<Value = Vec<Input>> {
    let input = prop_oneof![
        3 => wild_op().prop_map(Input::Op),
        4 => (any::<u64>(), wild(), prop::option::of(wild()), prop::option::of(wild())).prop_map(
            |(dt_ns, dv, jump, velocity)| Input::Setpoint { dt_ns, dv, jump, velocity }
        ),
        1 => Just(Input::Renew),
        2 => (1u16..100).prop_map(Input::Idle),
    ];
    prop::collection::vec(input, 1..60)
}

#[test]
fn every_command_stays_finite_for_any_operation_or_setpoint() {
    let travel = prop_oneof![
        Just((TravelMode::Linear, 0.0, Some((-10.0, 10.0)))),
        Just((TravelMode::Linear, 0.0, None)),
        Just((TravelMode::Cyclic, 360.0, None)),
    ];
    runner(256)
        .run(
            &(travel, any::<bool>(), wild_inputs()),
            |((travel, unwind, limits), unhomed, inputs)| {
                let cfg = AxisConfig {
                    travel,
                    unwind,
                    travel_limits: limits,
                    stream_unhomed: unhomed,
                    ..op_axis()
                };
                let mut r = Rig::new(cfg, op_plant(0.0));
                r.enable();
                if !unhomed {
                    r.step(home());
                }
                let res = play(&mut r, &inputs, |r, c| {
                    let finite = [
                        c.position,
                        c.velocity,
                        c.torque_limit_positive,
                        c.torque_limit_negative,
                        c.position_error_tolerance,
                        c.velocity_error_tolerance,
                    ]
                    .iter()
                    .all(|x| x.is_finite());
                    if !finite {
                        return Err(format!("step {}: {c:?}", r.k - 1));
                    }
                    if r.plant.feedback().drive.fault {
                        // The plant faults on a command it cannot execute.
                        return Err(format!("the drive faulted at step {}: {c:?}", r.k - 1));
                    }
                    Ok(())
                });
                prop_assert!(res.is_ok(), "{}", res.unwrap_err());
                Ok(())
            },
        )
        .unwrap();
}

/// A program's setpoint with its own idea of time: the program-time step
/// (any: a microsecond, a cycle, an hour), where it lies (a random walk
/// or a jump), and how many cycles pass before the next one arrives.
#[derive(Clone, Debug)]
struct Timed {
    dt_ns: u64,
    step: f64,
    jump: Option<f64>,
    wait: u8,
}

fn timed() -> impl Strategy<Value = Timed> {
    let dt = prop_oneof![
        4 => (1u64..30).prop_map(|ms| ms * MS),
        1 => Just(1_000u64),
        1 => Just(3_600_000 * MS),
        1 => 1u64..10_000_000_000,
    ];
    (
        dt,
        -0.08..0.08f64,
        prop::option::weighted(0.05, -9.9..9.9f64),
        0u8..30,
    )
        .prop_map(|(dt_ns, step, jump, wait)| Timed {
            dt_ns,
            step,
            jump,
            wait,
        })
}

#[test]
fn a_stream_is_never_followed_faster_or_harder_than_its_limits_whatever_its_timestamps() {
    // Whatever the timestamps say, the command sampled each cycle keeps
    // |Δv| ≤ stream_acceleration × cycle and |v| ≤ max_speed — also while
    // it stops (a fault's stop brakes at the larger of max_deceleration
    // and stream_acceleration: here both 5000) — and stays inside the
    // travel limits.
    runner(512)
        .run(&prop::collection::vec(timed(), 1..80), |inputs| {
            let cfg = AxisConfig {
                max_deceleration: 5000.0,
                ..op_axis()
            };
            let mut r = Rig::new(cfg, op_plant(0.0));
            r.enable_and_home();
            r.op(Operation::StreamStart).unwrap();
            let from = r.k as usize - 1;
            let (mut t, mut p) = (0u64, 0.0f64);
            for s in &inputs {
                t = t.saturating_add(s.dt_ns);
                p = s.jump.unwrap_or((p + s.step).clamp(-9.9, 9.9));
                r.setpoint(t, p, None);
                r.run(u64::from(s.wait));
            }
            r.run(300);
            let cmds = &r.cmds[from..];
            let v = max_speed(cmds, 1e-3);
            prop_assert!(v <= 50.0 * (1.0 + 1e-9), "speed {v}");
            let a = max_accel(cmds, 1e-3);
            prop_assert!(a <= 5000.0 * (1.0 + 1e-6), "acceleration {a}");
            for c in cmds {
                prop_assert!(c.position.abs() <= 10.0 + 1e-9, "{}", c.position);
            }
            Ok(())
        })
        .unwrap();
}
