//! An engine, its monitor and a plant stepped together, one cycle per
//! step: what the supervisor's cycle does for one axis, without frames.

#![allow(dead_code)]

use motion_homing::{Axis, AxisConfig, Command, Feedback, HomeSequence, Operation, Request};
use motion_monitor::{Cycle, Monitor, Trip};
use motion_plant::{Plant, PlantConfig};

pub const MS: u64 = 1_000_000;

pub struct Rig {
    pub axis: Axis,
    pub monitor: Monitor,
    pub plant: Plant,
    pub fb: Feedback,
    /// The next step's time, ns.
    pub now: u64,
    pub cycle_ns: u64,
    /// The monitor's output of the last step.
    pub out: Command,
    /// A trip the engine was told of: the step and the trip.
    pub tripped: Option<(u64, Trip)>,
    /// Changes the engine's command of step `k` before the monitor sees it
    /// (a bug in the operations' code, played).
    pub tamper: fn(u64, &mut Command),
}

fn untouched(_: u64, _: &mut Command) {}

impl Rig {
    pub fn new(cfg: AxisConfig, plant: PlantConfig) -> Self {
        let plant = Plant::new(plant);
        Self {
            monitor: Monitor::new(&cfg),
            axis: Axis::new(cfg),
            fb: plant.feedback(),
            plant,
            now: 0,
            cycle_ns: MS,
            out: Command::default(),
            tripped: None,
            tamper: untouched,
        }
    }

    /// One cycle `late` cycles after the previous one (1: on time).
    pub fn step_late(&mut self, req: Request, late: u64) -> Command {
        let fb = self.fb;
        let mut cmd = self.axis.step(self.now, Some(&fb), &req);
        (self.tamper)(self.now / self.cycle_ns, &mut cmd);
        let trips = self.monitor.trips();
        self.out = self.monitor.check(&Cycle {
            now_ns: self.now,
            feedback: Some(&fb),
            request: &req,
            status: self.axis.status(),
            reference: self.axis.reference_offset(),
            command: &cmd,
            io_restarted: false,
        });
        if self.monitor.trips() != trips {
            let t = *self.monitor.tripped().expect("a new trip is in force");
            self.axis.monitor_tripped(self.now, t.code());
            self.tripped.get_or_insert((self.now / self.cycle_ns, t));
        }
        let dt = (late * self.cycle_ns) as f64 * 1e-9;
        self.fb = self.plant.step(&self.out, dt);
        self.now += late * self.cycle_ns;
        cmd
    }

    pub fn step(&mut self, req: Request) -> Command {
        self.step_late(req, 1)
    }

    pub fn idle(&mut self, n: u64) {
        for _ in 0..n {
            self.step(Request::default());
        }
    }

    /// The step index of the next step.
    pub fn k(&self) -> u64 {
        self.now / self.cycle_ns
    }

    /// Axis position of the last command sent.
    pub fn out_axis(&self) -> f64 {
        self.axis.to_axis(self.out.position)
    }
}

/// A servo axis homed where it stands (Immediate), soft limits ±`lim`,
/// `max_speed` 50, Home Speed 20, accelerations 500.
pub fn immediate_axis(lim: f64) -> AxisConfig {
    AxisConfig {
        counts_per_unit: 1000.0,
        home_sequence: HomeSequence::Immediate,
        home_speed: 20.0,
        home_acceleration: 500.0,
        home_deceleration: 500.0,
        travel_limits: Some((-lim, lim)),
        max_speed: 50.0,
        cycle_ns: MS,
        ..AxisConfig::default()
    }
}

/// A request carrying operation `o`.
pub fn op(o: Operation) -> Request {
    Request {
        op: Some(o),
        ..Request::default()
    }
}
