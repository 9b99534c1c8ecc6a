//! The following error of the sim plant for the same move, trapezoid
//! against S-curve: the demo machine's axis X homed where it stands, then
//! a move of `--distance` at its home speed, acceleration and
//! deceleration (20 units/s, 500 units/s²), once with jerk 0 and once for
//! each `--jerk`. The engine and the plant are stepped together at the
//! machine's cycle (1 ms), with no daemon, so the figures are exact and the
//! same on every host.
//!
//! Per move: its duration; the following error `command − actual` (the
//! actual position is the plant's answer to the previous cycle's command,
//! as the supervisor sees it) — its largest magnitude, and the largest
//! second difference of it from cycle to cycle (the plant follows in one
//! cycle, so the error is v·T and this is the commanded jerk × T³: the
//! kick a drive's loop sees where the acceleration steps); and the plant's
//! torque (inertia, friction and load terms, % rated) — its largest change
//! per cycle.
//!
//! `cargo run --release -p motion-bench --bin following [-- --distance 40 --jerk 5000 --jerk 20000]`

use clap::Parser;
use motion_config::{parse, DEMO_TOML};
use motion_homing::{Axis, AxisConfig, HomeSequence, MoveSpec, Operation, Request};
use motion_plant::Plant;

#[derive(Parser)]
#[command(about = "Following error of the sim plant: the same move, trapezoid against S-curve")]
struct Opts {
    /// Length of the move, units.
    #[arg(long, default_value_t = 40.0)]
    distance: f64,
    /// Jerks of the S-curve moves, units/s³ (each one a row).
    #[arg(long, default_values_t = vec![5_000.0, 20_000.0, 100_000.0])]
    jerk: Vec<f64>,
}

/// What one move measured.
struct Row {
    jerk: f64,
    duration_s: f64,
    max_error: f64,
    max_error_jolt: f64,
    max_torque_step: f64,
}

/// Runs the move with `jerk` and measures it.
fn measure(
    cfg: AxisConfig,
    sim: motion_plant::PlantConfig,
    cycle_ns: u64,
    distance: f64,
    jerk: f64,
) -> Row {
    // Immediate homing derives no speed bound: the homing speed is it.
    let mut axis = Axis::new(AxisConfig {
        home_sequence: HomeSequence::Immediate,
        max_speed: cfg.max_speed.max(cfg.home_speed),
        ..cfg
    });
    let mut plant = Plant::new(sim);
    let dt = cycle_ns as f64 * 1e-9;
    let mut fb = plant.feedback();
    let mut started = None;
    let (mut max_error, mut max_error_jolt, mut max_torque_step) = (0.0f64, 0.0f64, 0.0f64);
    // The previous error, its change, and the previous torque.
    let mut prev: Option<(f64, Option<f64>, f64)> = None;
    for k in 0..1_000_000u64 {
        let s = *axis.status();
        let mut req = Request {
            home: s.servo_action,
            ..Request::default()
        };
        if k == 1 {
            req.op = Some(Operation::Enable);
        }
        if s.homed && s.servo_action && started.is_none() {
            started = Some(k);
            req.op = Some(Operation::Move(MoveSpec {
                target: distance,
                relative: true,
                jerk: Some(jerk),
                ..MoveSpec::to(0.0)
            }));
        }
        let cmd = axis.step(k * cycle_ns, Some(&fb), &req);
        if started == Some(k) {
            let op = axis.status().op;
            assert!(
                op.refused.is_none(),
                "the move was refused: {:?}",
                op.refused
            );
        }
        if let Some(k0) = started {
            // `fb` is what the engine saw: the answer to the last command.
            let error = cmd.position - fb.position;
            let torque = fb.torque;
            max_error = max_error.max(error.abs());
            let mut change = None;
            if let Some((e0, c0, t0)) = prev {
                change = Some(error - e0);
                if let Some(c0) = c0 {
                    max_error_jolt = max_error_jolt.max((error - e0 - c0).abs());
                }
                max_torque_step = max_torque_step.max((torque - t0).abs());
            }
            prev = Some((error, change, torque));
            if k > k0 + 1 && !axis.status().moving && error == 0.0 {
                return Row {
                    jerk,
                    duration_s: (k - k0) as f64 * dt,
                    max_error,
                    max_error_jolt,
                    max_torque_step,
                };
            }
        }
        fb = plant.step(&cmd, dt);
    }
    panic!("the move of jerk {jerk} never ended");
}

fn main() {
    let o = Opts::parse();
    let m = parse(DEMO_TOML).expect("the built-in demo machine parses");
    let x = m.axes.iter().find(|a| a.name == "X").expect("demo axis X");
    let cycle_ns = m.supervisor.cycle_ns();
    let e = &x.engine;
    println!(
        "demo axis X: a move of {} units at {} units/s, acceleration {} / deceleration {} units/s², cycle {} ms",
        o.distance,
        e.home_speed,
        e.home_acceleration,
        e.home_deceleration,
        cycle_ns as f64 / 1e6
    );
    println!(
        "{:>12} {:>10} {:>22} {:>26} {:>24}",
        "jerk u/s³",
        "time s",
        "max |cmd − actual| u",
        "max |Δ² error| per cycle u",
        "max |Δ torque| per cycle %"
    );
    for jerk in std::iter::once(0.0).chain(o.jerk.iter().copied()) {
        let r = measure(*e, x.sim, cycle_ns, o.distance, jerk);
        let name = if r.jerk == 0.0 {
            "0 (trapezoid)".to_string()
        } else {
            format!("{}", r.jerk)
        };
        println!(
            "{name:>12} {:>10.3} {:>22.6} {:>26.6} {:>24.3}",
            r.duration_s, r.max_error, r.max_error_jolt, r.max_torque_step
        );
    }
}
