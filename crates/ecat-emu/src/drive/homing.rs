//! Homing mode (CiA 402 mode 6) of an emulated drive, for the methods of
//! [`SUPPORTED_METHODS`](super::config::SUPPORTED_METHODS) that its 0x60E3
//! lists:
//!
//! | method | the drive |
//! |---|---|
//! | 19 | positive home switch: forward at 0x6099:01 until active (skipped when active), back at 0x6099:02 until it clears; home = that edge |
//! | 21 | negative home switch: mirrored |
//! | 3 / 5 | as 19 / 21, then on in the same direction to the first index pulse beyond the edge; home = the index |
//! | 34 / 33 | forward / reverse at 0x6099:02 to the first index pulse |
//! | 37 | home = where it stands |
//! | -1 / -2 | forward / reverse at 0x6099:01 into the hard stop: torque at 90 % of the limit for 20 cycles; home = there |
//!
//! Edges and index pulses are the plant's latched positions (exact). At
//! the home event the drive redefines its position (it reads 0x607C there,
//! the backend writes 0), decelerates on 0x609A and reports homing
//! attained (statusword bit 12) and target reached (bit 10) at rest. The
//! homing starts on the rising edge of controlword bit 4 in Operation
//! enabled; its falling edge or halt (bit 8) decelerate it to rest (target
//! reached, not attained). Written independently of the backend's side, like
//! the rest of the drive.

use motion_homing::{Command, Edge, LatchArm};

use super::Drive;

/// What the current segment looks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Goal {
    /// The switch becomes active.
    SwitchOn,
    /// The switch clears (its edge is latched).
    SwitchOff,
    /// The first index pulse beyond `after` in the direction of travel
    /// (`None`: any).
    Index,
    /// Blocked at a hard stop.
    HardStop,
    /// Decelerating to rest (after the event, a halt or an interruption).
    Stop,
}

/// A homing run in progress.
#[derive(Clone, Copy, Debug)]
pub(super) struct HomingRun {
    method: i8,
    goal: Goal,
    dir: f64,
    speed: f64,
    /// Commanded position and velocity, plant units.
    pos: f64,
    vel: f64,
    /// The switch edge found (methods 3 / 5), plant units.
    edge: Option<f64>,
    blocked: u32,
    next_id: u8,
    marker_id: u8,
    switch_id: u8,
    pub attained: bool,
    pub error: bool,
    /// At rest after its last segment.
    pub done: bool,
}

impl Drive {
    /// Speeds and acceleration in plant units: (switch search, zero search,
    /// acceleration).
    fn homing_params(&self) -> (f64, f64, f64) {
        let cpu = self.cfg.counts_per_unit;
        (
            self.od.get(0x6099, 1) as f64 / cpu,
            self.od.get(0x6099, 2) as f64 / cpu,
            (self.od.get(0x609A, 0) as f64 / cpu).max(1e-6),
        )
    }

    /// Controlword bit 4 rose in homing mode: a new run of 0x6098's method.
    pub(super) fn start_homing(&mut self) {
        let method = self.od.get(0x6098, 0) as u8 as i8;
        let fb = self.plant.feedback();
        let (s1, s2, _) = self.homing_params();
        let active = fb.home_switch != self.cfg.plant.switch_normally_closed;
        let supported = self.cfg.homing_methods.contains(&method);
        let (goal, dir, speed) = match method {
            19 | 3 if active => (Goal::SwitchOff, -1.0, s2),
            19 | 3 => (Goal::SwitchOn, 1.0, s1),
            21 | 5 if active => (Goal::SwitchOff, 1.0, s2),
            21 | 5 => (Goal::SwitchOn, -1.0, s1),
            34 => (Goal::Index, 1.0, s2),
            33 => (Goal::Index, -1.0, s2),
            -1 => (Goal::HardStop, 1.0, s1),
            -2 => (Goal::HardStop, -1.0, s1),
            _ => (Goal::Stop, 1.0, 0.0),
        };
        let mut run = HomingRun {
            method,
            goal,
            dir,
            speed,
            pos: fb.position,
            vel: 0.0,
            edge: None,
            blocked: 0,
            next_id: 0,
            marker_id: 0,
            switch_id: 0,
            attained: false,
            error: !supported,
            done: false,
        };
        if supported && method == 37 {
            self.home_here(&mut run, fb.position);
        } else if goal == Goal::SwitchOff {
            run.arm_switch();
        } else if goal == Goal::Index {
            run.arm_marker();
        }
        self.homing = Some(run);
    }

    /// The event at plant position `at`: the drive's position reads 0x607C
    /// there from now on; then to rest.
    fn home_here(&mut self, run: &mut HomingRun, at: f64) {
        let home = self.od.get_signed(0x607C, 0) as f64 / self.cfg.counts_per_unit;
        self.offset = home - at;
        run.attained = true;
        run.goal = Goal::Stop;
    }

    /// One cycle of homing mode in Operation enabled: the command for the
    /// plant. `halt`: controlword bit 8, or bit 4 fell.
    pub(super) fn homing_command(&mut self, dt: f64, halt: bool, cmd: &mut Command) {
        let Some(mut run) = self.homing else {
            return;
        };
        let fb = self.plant.feedback();
        let (_, s2, acc) = self.homing_params();
        if halt && !run.done {
            run.goal = Goal::Stop;
        }
        match run.goal {
            Goal::SwitchOn if fb.home_switch != self.cfg.plant.switch_normally_closed => {
                // on the switch: back off it at the zero search speed
                run.goal = Goal::SwitchOff;
                run.dir = -run.dir;
                run.speed = s2;
                run.arm_switch();
            }
            Goal::SwitchOff if fb.switch_latch.latched && fb.switch_latch.id == run.switch_id => {
                let edge = fb.switch_latch.position;
                if matches!(run.method, 3 | 5) {
                    run.edge = Some(edge);
                    run.goal = Goal::Index;
                    run.arm_marker();
                } else {
                    self.home_here(&mut run, edge);
                }
            }
            Goal::Index if fb.marker_latch.latched && fb.marker_latch.id == run.marker_id => {
                let at = fb.marker_latch.position;
                match run.edge {
                    // an index inside the switch, before its edge: the next
                    Some(e) if (at - e) * run.dir <= 0.0 => run.arm_marker(),
                    _ => self.home_here(&mut run, at),
                }
            }
            Goal::HardStop => {
                let limit = if run.dir > 0.0 {
                    self.limits().0
                } else {
                    self.limits().1
                };
                let pushing = fb.torque * run.dir >= 0.9 * limit && limit > 0.0;
                run.blocked = if pushing { run.blocked + 1 } else { 0 };
                if run.blocked >= 20 {
                    run.vel = 0.0;
                    run.pos = fb.position;
                    self.home_here(&mut run, fb.position);
                }
            }
            _ => {}
        }
        // the profile: towards the segment's speed, or to rest
        let want = if run.goal == Goal::Stop {
            0.0
        } else {
            run.dir * run.speed
        };
        let dv = acc * dt;
        run.vel = if (want - run.vel).abs() <= dv {
            want
        } else {
            run.vel + dv.copysign(want - run.vel)
        };
        run.pos += run.vel * dt;
        run.done = run.goal == Goal::Stop && run.vel == 0.0;
        cmd.enable = true;
        cmd.position = run.pos;
        cmd.velocity = run.vel;
        cmd.marker_arm = LatchArm {
            id: run.marker_id,
            edge: Edge::Rising,
        };
        // the edge as the switch clears: closed → open on a normally open
        // switch
        let clears = if self.cfg.plant.switch_normally_closed {
            Edge::Rising
        } else {
            Edge::Falling
        };
        cmd.switch_arm = LatchArm {
            id: run.switch_id,
            edge: clears,
        };
        self.homing = Some(run);
    }
}

impl HomingRun {
    fn fresh_id(&mut self) -> u8 {
        self.next_id = self.next_id.wrapping_add(1).max(1);
        self.next_id
    }

    fn arm_switch(&mut self) {
        self.switch_id = self.fresh_id();
    }

    fn arm_marker(&mut self) {
        self.marker_id = self.fresh_id();
    }
}
