//! Engine states for the engine bench, reached by real homing against
//! the sim plants (never built by hand, so they are states the engine
//! really passes through): one axis's step inputs captured mid-homing
//! ([`seek_state`], [`torque_state`]) or mid-move ([`move_state`]:
//! trapezoid or S-curve), and a whole [`Core`] of `n` axes
//! homing ([`homing_core`] of [`repeated_demo`]). The engine bench
//! (`bench/benches/engine.rs`) times these.

use motion_config::{MachineConfig, DEMO_TOML};
use motion_frames::{axis_to_command, feedback_to_axis, CommandFrame, FeedbackFrame};
use motion_homing::{
    Axis, AxisConfig, Feedback, GearSpec, HomeSequence, JogSpec, MasterFeed, Operation, Phase,
    Request,
};
use motion_plant::Plant;
use motion_supervisor::core::Core;
use motion_supervisor::shared::{Ask, Control};

/// Cycles of real homing (against the plants) before a cycle is measured.
pub const CYCLE_WARMUP: u64 = 400;

/// The built-in demo machine (`deploy/demo.toml`).
pub fn demo() -> MachineConfig {
    motion_config::parse(DEMO_TOML).expect("the built-in demo machine parses")
}

/// The inputs of one real engine step, captured mid-homing.
pub struct Captured {
    pub axis: Axis,
    pub feedback: Feedback,
    pub now: u64,
    pub request: Request,
    /// The cycle it was captured in.
    pub cycle: u64,
}

/// Homes the demo axis `name` against its plant, cycle by cycle, until
/// `stop(axis, feedback)` holds before a step: returns that step's inputs.
pub fn home_until(name: &str, mut stop: impl FnMut(&Axis, &Feedback) -> bool) -> Captured {
    let m = demo();
    let a = m
        .axes
        .iter()
        .find(|a| a.name == name)
        .expect("demo axis exists");
    let plant = Plant::new(a.sim);
    // the rung goes high in cycle 1: a rising edge
    let dt_ns = m.supervisor.cycle_ns();
    capture(Axis::new(a.engine), plant, dt_ns, 200_000, |k, axis, fb| {
        let request = Request {
            home: k >= 1,
            ..Request::default()
        };
        let now = k > 1 && stop(axis, fb);
        (request, now)
    })
    .unwrap_or_else(|| panic!("axis {name}: the state to capture was never reached"))
}

/// Steps `axis` against `plant` every `dt_ns`, for at most `cycles` cycles:
/// `next(cycle, axis, feedback)` gives the cycle's request and whether to
/// capture that step's inputs instead of taking it. `None`: never captured.
fn capture(
    mut axis: Axis,
    mut plant: Plant,
    dt_ns: u64,
    cycles: u64,
    mut next: impl FnMut(u64, &Axis, &Feedback) -> (Request, bool),
) -> Option<Captured> {
    let dt = dt_ns as f64 * 1e-9;
    let mut fb = plant.feedback();
    for k in 0..cycles {
        let now = k * dt_ns;
        let (request, take) = next(k, &axis, &fb);
        if take {
            return Some(Captured {
                axis,
                feedback: fb,
                now,
                request,
                cycle: k,
            });
        }
        let cmd = axis.step(now, Some(&fb), &request);
        fb = plant.step(&cmd, dt);
    }
    None
}

/// Axis X (switch then marker) in the middle of its first leg: seeking the
/// switch at Home Speed, past acceleration.
pub fn seek_state() -> Captured {
    home_until("X", |a, fb| {
        a.status().phase == Phase::Seek && fb.position > -10.0
    })
}

/// Axis Z (torque) pushing into its hard stop: torque over the threshold for
/// 5 cycles, the torque time (20 ms) not yet reached.
pub fn torque_state() -> Captured {
    let m = demo();
    let threshold = m
        .axes
        .iter()
        .find(|a| a.name == "Z")
        .expect("demo axis Z")
        .engine
        .home_torque_threshold;
    let mut over = 0;
    home_until("Z", move |a, fb| {
        if a.status().phase == Phase::Seek && fb.torque.abs() >= threshold {
            over += 1;
        }
        over > 5
    })
}

/// `n` axes: the demo axes repeated, starting with the moving ones
/// (X, C, Z, U, X, ...), names made unique.
pub fn repeated_demo(n: usize) -> MachineConfig {
    let d = demo();
    let axes = (0..n)
        .map(|i| {
            let mut a = d.axes[(i + 1) % d.axes.len()].clone();
            a.name = format!("{}{}", a.name, i);
            a
        })
        .collect();
    MachineConfig {
        supervisor: d.supervisor.clone(),
        ios: d.ios.clone(),
        axes,
        gantries: Vec::new(),
        warnings: Vec::new(),
    }
}

/// A core homing every axis against its plant for [`CYCLE_WARMUP`] cycles:
/// the core, the last feedback frame, a command frame and the next cycle's
/// time.
pub fn homing_core(m: &MachineConfig) -> (Core, FeedbackFrame, CommandFrame, u64) {
    let mut core = Core::new(m);
    let mut plants: Vec<Plant> = m.axes.iter().map(|a| Plant::new(a.sim)).collect();
    let mut fb = FeedbackFrame::default();
    let mut cmd = CommandFrame::default();
    let dt_ns = m.supervisor.cycle_ns();
    let dt = dt_ns as f64 * 1e-9;
    fb.header.axis_count = m.axes.len() as u32;
    for (i, (a, p)) in m.axes.iter().zip(&plants).enumerate() {
        fb.axes[i] = feedback_to_axis(&p.feedback(), a.engine.counts_per_unit);
    }
    fb.header.origin = 1;
    for k in 0..CYCLE_WARMUP {
        if k == 10 {
            let home = Ask::Home {
                mask: u64::MAX >> (64 - m.axes.len()),
                parallel: true,
                timeout_ns: 0,
            };
            core.control(Control::undated(1, home), k * dt_ns);
        }
        core.step(k * dt_ns, false, &[(k > 0).then_some(&fb)]);
        core.fill(0, &mut cmd);
        core.sent(0, k + 1, k * dt_ns);
        fb.answers_sequence = k + 1;
        for (i, (a, p)) in m.axes.iter().zip(plants.iter_mut()).enumerate() {
            let c = axis_to_command(&cmd.axes[i], a.engine.counts_per_unit);
            let f = p.step(&c, dt);
            fb.axes[i] = feedback_to_axis(&f, a.engine.counts_per_unit);
        }
    }
    (core, fb, cmd, CYCLE_WARMUP * dt_ns)
}

/// `N phase, ...`: how many of the core's axes are in each phase.
pub fn phases(core: &Core) -> String {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for a in core.axes() {
        let n = a.status().phase.name();
        match counts.iter_mut().find(|c| c.0 == n) {
            Some(c) => c.1 += 1,
            None => counts.push((n, 1)),
        }
    }
    counts
        .iter()
        .map(|(n, k)| format!("{k} {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Axis X of the demo machine homed where it stands (immediate), enabled,
/// and ten cycles into a move of +40 units at its home speed and
/// acceleration — in the acceleration phase, where an S-curve samples a
/// segment with jerk: `jerk` 0 plans a trapezoid, above 0 an S-curve.
pub fn move_state(jerk: f64) -> Captured {
    use motion_homing::{HomeSequence, MoveSpec, Operation};
    let m = demo();
    let a = m.axes.iter().find(|a| a.name == "X").expect("demo axis X");
    // Immediate homing derives no speed bound: the homing speed is it.
    let axis = Axis::new(motion_homing::AxisConfig {
        home_sequence: HomeSequence::Immediate,
        max_speed: a.engine.max_speed.max(a.engine.home_speed),
        ..a.engine
    });
    let plant = Plant::new(a.sim);
    let mut started = None;
    capture(
        axis,
        plant,
        m.supervisor.cycle_ns(),
        10_000,
        |k, axis, _| {
            let s = *axis.status();
            let mut request = Request {
                home: s.servo_action,
                ..Request::default()
            };
            if k == 1 {
                request.op = Some(Operation::Enable);
            }
            if s.homed && s.servo_action && started.is_none() {
                started = Some(k);
                request.op = Some(Operation::Move(MoveSpec {
                    target: 40.0,
                    relative: true,
                    jerk: Some(jerk),
                    ..MoveSpec::to(0.0)
                }));
            }
            let now = started.is_some_and(|s0| k == s0 + 10);
            if now {
                assert!(axis.status().moving, "the move runs");
            }
            (request, now)
        },
    )
    .expect("axis X: the move never started")
}

/// A master jogging (a trapezoid at its cruise, 10 u/s) and a slave geared
/// to it at ratio 2, both homed at 0 against their plants: the inputs of
/// the next step of each (the slave's request carries the master's news of
/// that step, as the cycle hands it). `(master, slave)`.
pub fn geared_state() -> (Captured, Captured) {
    const T: u64 = 1_000_000;
    let cfg = AxisConfig {
        counts_per_unit: 1000.0,
        home_sequence: HomeSequence::Immediate,
        home_speed: 20.0,
        home_acceleration: 500.0,
        home_deceleration: 500.0,
        travel_limits: Some((-100.0, 100.0)),
        max_speed: 50.0,
        cycle_ns: T,
        ..AxisConfig::default()
    };
    let plant = motion_plant::PlantConfig::default();
    let (mut m, mut s) = (Axis::new(cfg), Axis::new(cfg));
    let (mut mp, mut sp) = (Plant::new(plant), Plant::new(plant));
    let (mut mfb, mut sfb) = (mp.feedback(), sp.feedback());
    let op = |o: Operation| Request {
        op: Some(o),
        ..Request::default()
    };
    let script = |k: u64| match k {
        1 => (op(Operation::Enable), op(Operation::Enable)),
        20 => {
            let home = Request {
                home: true,
                ..Request::default()
            };
            (home, home)
        }
        30 => (
            Request::default(),
            op(Operation::Gear(GearSpec::to(0, 2.0))),
        ),
        40 => (
            op(Operation::Jog(JogSpec {
                lease: Some(5.0),
                ..JogSpec::at(10.0)
            })),
            Request::default(),
        ),
        _ => (Request::default(), Request::default()),
    };
    let feed = |m: &Axis| MasterFeed {
        commanded: m.last_command().position,
        actual: m.raw_position(),
        accel: m.acceleration_bound(),
        stopped: false,
        faulted: m.status().faulted,
    };
    for k in 0..200u64 {
        let (mreq, sreq) = script(k);
        let mc = m.step(k * T, Some(&mfb), &mreq);
        let sreq = Request {
            master: Some(feed(&m)),
            ..sreq
        };
        let sc = s.step(k * T, Some(&sfb), &sreq);
        (mfb, sfb) = (mp.step(&mc, 1e-3), sp.step(&sc, 1e-3));
    }
    assert!(m.status().jogging && s.status().gearing, "a geared pair");
    let k = 200u64;
    let master = Captured {
        axis: m.clone(),
        feedback: mfb,
        now: k * T,
        request: Request::default(),
        cycle: k,
    };
    m.step(k * T, Some(&mfb), &Request::default());
    let slave = Captured {
        axis: s,
        feedback: sfb,
        now: k * T,
        request: Request {
            master: Some(feed(&m)),
            ..Request::default()
        },
        cycle: k,
    };
    (master, slave)
}
