//! A Core with simulated I/O processes in place: plants per axis and one
//! frame pair per I/O process, stepped cycle by cycle without threads or
//! IPC (for the core's and the keeper's tests).

use super::*;
use crate::shared::{Ack, Ask, Control};
use motion_frames::feedback_to_axis;
use motion_plant::Plant;

pub const MS: u64 = 1_000_000;

/// A Core, plants per axis and one frame pair per I/O process.
#[derive(Clone)]
pub struct Bench {
    pub m: MachineConfig,
    pub core: Core,
    pub plants: Vec<Plant>,
    pub cmd: Vec<CommandFrame>,
    pub fb: Vec<FeedbackFrame>,
    pub seq: Vec<u64>,
    pub origin: Vec<u64>,
    /// I/O processes that answer.
    pub alive: Vec<bool>,
    pub k: u64,
    pub acks: Vec<Ack>,
    /// Setpoint frames for the next cycle's intake.
    pub setpoints: Vec<motion_frames::SetpointFrame>,
    /// The cycle monitor may trip (a test that feeds garbage, or checks a
    /// trip); otherwise every cycle asserts that it did not: the monitor
    /// never trips in normal operation.
    pub allow_trips: bool,
}

/// The session key of a [`Bench`]'s core (its setpoint frames carry it).
pub const KEY: [u64; 2] = [0x5eed, 0xcafe];

impl Bench {
    pub fn new(toml: &str) -> Self {
        let m = motion_config::parse(toml).unwrap_or_else(|p| panic!("{p:#?}"));
        let ios = m.ios.len();
        Self {
            core: Core::new(&m).with_session_key(KEY),
            plants: m.axes.iter().map(|a| Plant::new(a.sim)).collect(),
            cmd: vec![CommandFrame::ZERO; ios],
            fb: vec![FeedbackFrame::ZERO; ios],
            seq: vec![0; ios],
            origin: (1..=ios as u64).collect(),
            alive: vec![true; ios],
            k: 0,
            acks: Vec::new(),
            setpoints: Vec::new(),
            allow_trips: false,
            m,
        }
    }

    pub fn control(&mut self, c: Control) {
        if let Some(a) = self.core.control(c, self.k * MS) {
            self.acks.push(a);
        }
    }

    /// `ask` as request `id`, with no deadline.
    pub fn ask(&mut self, id: u32, ask: Ask) {
        self.control(Control::undated(id, ask));
    }

    /// One cycle: the setpoint frames queued are taken, the core steps on
    /// last cycle's answers, publishes, answers the operations of the step,
    /// and every live I/O process answers (its plants advance one cycle).
    pub fn cycle(&mut self) {
        let now = self.k * MS;
        self.core.setpoints_begin();
        for f in std::mem::take(&mut self.setpoints) {
            self.core.setpoints_take(&f);
        }
        let frames: Vec<Option<&FeedbackFrame>> = (0..self.fb.len())
            .map(|k| (self.alive[k] && self.seq[k] > 0).then_some(&self.fb[k]))
            .collect();
        self.core.step(now, false, &frames);
        let acks = &mut self.acks;
        self.core.answers(|a| acks.push(a));
        if !self.allow_trips {
            for (i, slot) in self.core.axes().iter().enumerate() {
                assert!(
                    slot.trip().is_none(),
                    "cycle {}: the monitor tripped on axis {i}: {:?}\n{:?}",
                    self.k,
                    slot.trip(),
                    slot.status()
                );
            }
        }
        let dt = self.m.supervisor.cycle_us as f64 * 1e-6;
        for k in 0..self.cmd.len() {
            self.core.fill(k, &mut self.cmd[k]);
            self.seq[k] += 1;
            self.core.sent(k, self.seq[k], now);
            if !self.alive[k] {
                continue;
            }
            let axes = self.m.axes_of(k);
            let f = &mut self.fb[k];
            f.header.axis_count = axes.len() as u32;
            f.header.origin = self.origin[k];
            f.header.timestamp_ns = now + 20_000;
            f.answers_sequence = self.seq[k];
            for (j, &i) in axes.iter().enumerate() {
                let a = &self.m.axes[i];
                let c =
                    motion_frames::axis_to_command(&self.cmd[k].axes[j], a.engine.counts_per_unit);
                let fb = self.plants[i].step(&c, dt);
                f.axes[j] = feedback_to_axis(&fb, a.engine.counts_per_unit);
            }
        }
        self.k += 1;
    }

    pub fn run(&mut self, cycles: u64) {
        for _ in 0..cycles {
            self.cycle();
        }
    }

    pub fn snap(&self) -> Snapshot {
        let mut s = Snapshot::default();
        self.core.snapshot(self.k * MS, &mut s);
        s
    }

    /// A setpoint frame of `token` for the next cycle: `seq`, program time
    /// `t_ns`, one entry (`axis`, `position`).
    pub fn setpoint(&mut self, token: u64, seq: u64, t_ns: u64, axis: u32, position: f64) {
        let mut f = motion_frames::SetpointFrame {
            layout_version: motion_frames::SETPOINT_LAYOUT,
            key: KEY,
            token,
            seq,
            t_ns,
            count: 1,
            ..motion_frames::SetpointFrame::ZERO
        };
        f.axes[0] = motion_frames::SetpointAxis {
            axis,
            position,
            ..motion_frames::SetpointAxis::ZERO
        };
        self.setpoints.push(f);
    }

    /// An operation for the axes of `mask` (`token`: a jog's), applied in
    /// the next cycle; its answer comes after that cycle's step.
    pub fn op(&mut self, mask: u64, op: motion_homing::Operation, token: u64) {
        self.ask(9, Ask::Op { mask, op, token });
    }

    pub fn home(&mut self, mask: u64, parallel: bool) -> Ack {
        self.ask(
            7,
            Ask::Home {
                mask,
                parallel,
                timeout_ns: 0,
            },
        );
        self.acks.pop().unwrap()
    }
}
