//! Engine + plant in a loop, one cycle at a time, and the machine most
//! engine tests home on.
#![allow(dead_code)]

use motion_homing::*;
use motion_plant::{Plant, PlantConfig};

/// The test machine (raw units): hard stops at -100 and +100, the home
/// switch over [0, 5], markers every 10 at 2.5 (... -7.5, 2.5, 12.5 ...);
/// the axis starts at `start`.
pub fn machine_at(start: f64) -> PlantConfig {
    PlantConfig {
        start,
        switch: Some((0.0, 5.0)),
        marker_every: 10.0,
        marker_at: 2.5,
        hard_stop: Some((-100.0, 100.0)),
        ..PlantConfig::default()
    }
}

/// The test machine with limit switches: the negative one actuated at or
/// below -90, the positive one at or above 90 (10 units before the hard
/// stops).
pub fn limit_machine_at(start: f64) -> PlantConfig {
    PlantConfig {
        overtravel: Some((-90.0, 90.0)),
        ..machine_at(start)
    }
}

/// The test machine with the axis at -50: a forward search meets the switch.
pub fn machine() -> PlantConfig {
    machine_at(-50.0)
}

/// An axis homing `seq` in direction `dir` on the test machine: 1000 counts
/// per unit, a marker, home speed V = 20, return speed R = 2, acceleration
/// and deceleration 500, travel limits ±100.
pub fn axis(seq: HomeSequence, dir: HomeDirection) -> AxisConfig {
    AxisConfig {
        counts_per_unit: 1000.0,
        marker: true,
        home_sequence: seq,
        home_direction: dir,
        home_speed: 20.0,
        home_return_speed: 2.0,
        home_acceleration: 500.0,
        home_deceleration: 500.0,
        travel_limits: Some((-100.0, 100.0)),
        ..AxisConfig::default()
    }
}

/// The request to home, and nothing else.
pub fn home() -> Request {
    Request {
        home: true,
        ..Request::default()
    }
}

/// Every step of a run of fixed length: the command and status after it,
/// and the position the plant reported before it (`seen[k]`: what the
/// engine saw at step k unless the frame was withheld or rewritten).
pub struct Steps {
    pub cmd: Vec<Command>,
    pub st: Vec<Status>,
    pub seen: Vec<f64>,
}

/// Homes from step 0 and steps engine and plant `n` times, `cycle_ns`
/// apart. `frame(k, previous command, feedback)` is the frame the engine
/// sees at step k (`None`: withheld).
pub fn steps(
    cfg: AxisConfig,
    plant: PlantConfig,
    cycle_ns: u64,
    n: usize,
    mut frame: impl FnMut(usize, &Command, Feedback) -> Option<Feedback>,
) -> Steps {
    let mut axis = Axis::new(cfg);
    let mut plant = Plant::new(plant);
    let mut fb = plant.feedback();
    let req = home();
    let mut s = Steps {
        cmd: Vec::new(),
        st: Vec::new(),
        seen: Vec::new(),
    };
    let mut last = Command::default();
    for k in 0..n {
        let seen = frame(k, &last, fb);
        last = axis.step(k as u64 * cycle_ns, seen.as_ref(), &req);
        s.cmd.push(last);
        s.st.push(*axis.status());
        s.seen.push(fb.position);
        fb = plant.step(&last, cycle_ns as f64 * 1e-9);
    }
    s
}

/// Result of one homing run.
pub struct Outcome {
    pub status: Status,
    pub final_raw: f64,
    pub final_axis: f64,
    /// Every command, in order (one per cycle).
    pub commands: Vec<Command>,
    /// Axis position the engine assigns to the event point.
    pub axis_at_event: Option<f64>,
    pub cycles: usize,
    pub axis: Axis,
}

/// Runs homing from the plant's power-up state until the instruction is done
/// and the axis is at rest, then lets the plant settle for a few cycles.
pub fn run(cfg: AxisConfig, plant: PlantConfig, cycle_s: f64, max_s: f64) -> Outcome {
    run_with(cfg, plant, cycle_s, max_s, |_, _, fb, _| Some(fb))
}

/// As [`run`], with a hook called before every engine step that may alter or
/// drop (None) the feedback frame, poke the plant, or change the request:
/// `hook(cycle, plant, feedback, request) -> feedback seen by the engine`.
pub fn run_with(
    cfg: AxisConfig,
    plant_cfg: PlantConfig,
    cycle_s: f64,
    max_s: f64,
    mut hook: impl FnMut(usize, &mut Plant, Feedback, &mut Request) -> Option<Feedback>,
) -> Outcome {
    let cycle_ns = (cycle_s * 1e9).round() as u64;
    let mut axis = Axis::new(cfg);
    let mut plant = Plant::new(plant_cfg);
    let mut fb = plant.feedback();
    let mut req = home();
    let mut commands = Vec::new();
    let max = (max_s / cycle_s) as usize;
    let mut settle = None;
    let mut k = 0;
    loop {
        let now = k as u64 * cycle_ns;
        let seen = hook(k, &mut plant, fb, &mut req);
        let cmd = axis.step(now, seen.as_ref(), &req);
        commands.push(cmd);
        fb = plant.step(&cmd, cycle_s);
        let st = axis.status();
        let at_rest = cmd.velocity == 0.0;
        if settle.is_none() && !st.ip && st.phase == Phase::Idle && at_rest && k > 0 {
            settle = Some(k + 5);
        }
        if settle == Some(k) {
            break;
        }
        k += 1;
        assert!(
            k < max,
            "homing did not finish in {max_s} s: {:?}",
            axis.status()
        );
    }
    let status = *axis.status();
    let final_raw = plant.position();
    Outcome {
        status,
        final_raw,
        final_axis: axis.to_axis(final_raw),
        commands,
        axis_at_event: status.event_raw.map(|e| axis.to_axis(e)),
        cycles: k,
        axis,
    }
}

// ----------------------------------------------------------------------
// Operations around homing: power, reset, jog, move, stream
// ----------------------------------------------------------------------

/// 1 ms.
pub const MS: u64 = 1_000_000;

/// The axis most operation tests run: homes immediately at 0 (so HomedStatus
/// is one step away), 1000 counts per unit, home speed 20 (the unhomed cap),
/// acceleration and deceleration 500, max_speed 50, travel limits ±10, a
/// 1 ms cycle.
pub fn op_axis() -> AxisConfig {
    AxisConfig {
        counts_per_unit: 1000.0,
        home_sequence: HomeSequence::Immediate,
        home_speed: 20.0,
        home_acceleration: 500.0,
        home_deceleration: 500.0,
        travel_limits: Some((-10.0, 10.0)),
        max_speed: 50.0,
        cycle_ns: MS,
        ..AxisConfig::default()
    }
}

/// The plant behind it: at rest at `start`, no sensors, the default
/// two-cycle enable delay.
pub fn op_plant(start: f64) -> PlantConfig {
    PlantConfig {
        start,
        ..PlantConfig::default()
    }
}

/// Engine and plant stepped together, one cycle per step, with every
/// command and status kept.
pub struct Rig {
    pub axis: Axis,
    pub plant: Plant,
    pub fb: Feedback,
    /// The next step's index (its time is `k * cycle_ns`).
    pub k: u64,
    pub cycle_ns: u64,
    pub cmds: Vec<Command>,
    pub sts: Vec<Status>,
    /// Rewrites the frame the engine sees (None: withheld).
    pub frame: fn(u64, Feedback) -> Option<Feedback>,
}

fn pass(_: u64, fb: Feedback) -> Option<Feedback> {
    Some(fb)
}

impl Rig {
    pub fn new(cfg: AxisConfig, plant: PlantConfig) -> Self {
        let plant = Plant::new(plant);
        Self {
            axis: Axis::new(cfg),
            fb: plant.feedback(),
            plant,
            k: 0,
            cycle_ns: if cfg.cycle_ns > 0 { cfg.cycle_ns } else { MS },
            cmds: Vec::new(),
            sts: Vec::new(),
            frame: pass,
        }
    }

    /// `op_axis()` on `op_plant(start)`.
    pub fn at(start: f64) -> Self {
        Self::new(op_axis(), op_plant(start))
    }

    pub fn now(&self) -> u64 {
        self.k * self.cycle_ns
    }

    /// One cycle with `req`: the engine's command (the plant applies it).
    pub fn step(&mut self, req: Request) -> Command {
        let seen = (self.frame)(self.k, self.fb);
        let cmd = self.axis.step(self.now(), seen.as_ref(), &req);
        self.fb = self.plant.step(&cmd, self.cycle_ns as f64 * 1e-9);
        self.cmds.push(cmd);
        self.sts.push(*self.axis.status());
        self.k += 1;
        cmd
    }

    /// `n` cycles of an empty request.
    pub fn run(&mut self, n: u64) {
        for _ in 0..n {
            self.step(Request::default());
        }
    }

    /// Cycles until `done(status)` holds after one (at most `max`): true if
    /// it did.
    pub fn run_until(&mut self, max: u64, done: impl Fn(&Status) -> bool) -> bool {
        for _ in 0..max {
            self.step(Request::default());
            if done(self.axis.status()) {
                return true;
            }
        }
        false
    }

    /// One cycle with `op`: `Ok(id)` when accepted, `Err(code)` when refused.
    pub fn op(&mut self, op: Operation) -> Result<u32, (u16, u16)> {
        let before = self.axis.status().op.id;
        self.step(Request {
            op: Some(op),
            ..Request::default()
        });
        let st = self.axis.status().op;
        if st.id != before {
            assert_eq!(st.refused, None);
            Ok(st.id)
        } else {
            Err(st.refused.expect("neither accepted nor refused"))
        }
    }

    /// One cycle with a setpoint.
    pub fn setpoint(&mut self, t_ns: u64, position: f64, velocity: Option<f64>) -> Command {
        self.step(Request {
            setpoint: Some(Setpoint {
                t_ns,
                position,
                velocity,
            }),
            ..Request::default()
        })
    }

    /// Enabled and at rest: the enable accepted and the drive on.
    pub fn enable(&mut self) {
        self.run(1);
        self.op(Operation::Enable).expect("enable accepted");
        assert!(
            self.run_until(100, |s| s.servo_action && s.op.pc),
            "{:?}",
            self.axis.status()
        );
    }

    /// Enabled and homed (immediate: Home Position where it stands).
    pub fn enable_and_home(&mut self) {
        self.enable();
        self.step(home());
        self.step(Request::default());
        let s = self.axis.status();
        assert!(s.homed && s.pc && s.servo_action, "{s:?}");
    }

    /// Axis position of the last command.
    pub fn cmd_axis(&self) -> f64 {
        self.axis.to_axis(self.cmds.last().unwrap().position)
    }

    /// Commands from step `from` on.
    pub fn since(&self, from: u64) -> &[Command] {
        &self.cmds[from as usize..]
    }
}

/// `ns` in seconds (a lease as an operation's spec carries it).
pub fn secs(ns: u64) -> f64 {
    ns as f64 * 1e-9
}

/// A jog at `speed` with acceleration and deceleration 500 and a 500 ms lease.
pub fn jog(speed: f64) -> Operation {
    Operation::Jog(JogSpec {
        speed,
        accel: Some(500.0),
        decel: Some(500.0),
        lease: Some(secs(500 * MS)),
        jerk: None,
    })
}

/// A switch homing on the test machine, with a speed bound.
pub fn switch_homing() -> AxisConfig {
    AxisConfig {
        max_speed: 50.0,
        ..axis(HomeSequence::Switch, HomeDirection::BidirectionalForward)
    }
}

/// [`switch_homing`] on the [`machine`], homing just begun: in its seek.
pub fn at_the_seek() -> Rig {
    let mut r = Rig::new(switch_homing(), machine());
    r.step(home());
    assert!(r.run_until(100, |s| s.phase == Phase::Seek));
    r
}

/// Unhomed, enabled at 0 and at rest ([`Rig::at`]).
pub fn idle() -> Rig {
    let mut r = Rig::at(0.0);
    r.enable();
    r
}

/// [`idle`], then jogging at 10 u/s for 50 steps (past its acceleration):
/// the rig and the jog's operation id.
pub fn jogging_with_id() -> (Rig, u32) {
    let mut r = idle();
    let id = r.op(jog(10.0)).unwrap();
    r.run(50);
    (r, id)
}

/// [`jogging_with_id`] without the id.
pub fn jogging() -> Rig {
    jogging_with_id().0
}

/// The move most tests give: to `target` (axis position) at 20,
/// acceleration and deceleration 500, a trapezoid, not superseding.
pub fn move_spec(target: f64) -> MoveSpec {
    MoveSpec {
        target,
        relative: false,
        speed: Some(20.0),
        accel: Some(500.0),
        decel: Some(500.0),
        supersede: false,
        jerk: None,
    }
}

/// A move to `target` (axis position) at 20, acceleration and deceleration 500.
pub fn move_to(target: f64) -> Operation {
    Operation::Move(move_spec(target))
}

/// Largest |second difference| / cycle² of the commanded positions: the
/// acceleration the drive was asked for.
pub fn max_accel(cmds: &[Command], cycle_s: f64) -> f64 {
    cmds.windows(3)
        .map(|w| (w[2].position - 2.0 * w[1].position + w[0].position).abs() / (cycle_s * cycle_s))
        .fold(0.0, f64::max)
}

/// Largest |first difference| / cycle of the commanded positions.
pub fn max_speed(cmds: &[Command], cycle_s: f64) -> f64 {
    cmds.windows(2)
        .map(|w| (w[1].position - w[0].position).abs() / cycle_s)
        .fold(0.0, f64::max)
}

/// A property runner of `cases` cases, without failure files: a failing
/// case is printed whole, to be turned into a test of its own.
pub fn runner(cases: u32) -> proptest::test_runner::TestRunner {
    proptest::test_runner::TestRunner::new(proptest::test_runner::Config {
        cases,
        failure_persistence: None,
        ..proptest::test_runner::Config::default()
    })
}
