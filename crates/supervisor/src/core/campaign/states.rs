//! The states of the campaign and how a run gets there: from machines
//! prepared once (at rest homed, homing just asked for) and cloned per run,
//! then a random time into the state.
//!
//! The machine: one servo axis on one I/O process; switch homing at 20
//! (return 2) from −10 onto the switch [0, 5], accelerations 500, so the
//! reference makes raw = axis; soft limits ±50, `max_speed` 40,
//! `unhomed_speed` 10, `max_deceleration` 1000, `stream_acceleration`
//! 2000, `stream_timeout_ms` 50; a drive that takes 30 cycles to enable.

use super::super::testbench::{Bench, MS};
use super::rig::{Client, Program, Rig, KEY};
use super::Rng;
use crate::shared::{Ask, Control};
use motion_homing::{JogSpec, MoveSpec, Operation, Phase};

pub const MACHINE: &str = r#"
[supervisor]
cycle_us = 1000
cpu = 0

[[axis]]
name = "A"
counts_per_unit = 1000000.0
home_sequence = "switch"
home_speed = 20.0
home_return_speed = 2.0
home_acceleration = 500.0
home_deceleration = 500.0
travel_limits = [-50.0, 50.0]
max_speed = 40.0
unhomed_speed = 10.0
max_deceleration = 1000.0
stream_acceleration = 2000.0
stream_timeout_ms = 50
[axis.sim]
start = -10.0
switch = [0.0, 5.0]
enable_delay_cycles = 30
"#;

/// Soft limits (axis = raw on this machine once homed, to within
/// [`REFERENCE`]).
pub const LIMITS: (f64, f64) = (-50.0, 50.0);
/// How far the reference homing establishes can lie from raw = axis: the
/// switch edge is sampled, known to one cycle of travel at Home Return
/// Speed (2 units/s × 1 ms).
pub const REFERENCE: f64 = 0.002;
pub const MAX_SPEED: f64 = 40.0;
pub const MAX_DECEL: f64 = 1000.0;
pub const HOME_DECEL: f64 = 500.0;
pub const STREAM_ACCEL: f64 = 2000.0;
pub const STREAM_TIMEOUT_CYCLES: u64 = 50;
/// The largest acceleration anything on this machine may command.
pub const MAX_ACCEL: f64 = 2000.0;

/// Where an axis can be when something happens.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    HomingEnabling,
    HomingSeek,
    HomingSeekStop,
    HomingReturn,
    HomingReturnStop,
    HomingMoveHome,
    /// A homing's abort coming to rest.
    HomingStopping,
    /// An enable waiting for the drive.
    Enabling,
    Jogging,
    Moving,
    Streaming,
    /// An operation's stop coming to rest.
    Stopping,
    /// An axis fault at rest (the drive faulted, not reset).
    Faulted,
    /// At rest, the power stage off.
    Disabled,
}

impl State {
    pub const ALL: &'static [State] = &[
        State::HomingEnabling,
        State::HomingSeek,
        State::HomingSeekStop,
        State::HomingReturn,
        State::HomingReturnStop,
        State::HomingMoveHome,
        State::HomingStopping,
        State::Enabling,
        State::Jogging,
        State::Moving,
        State::Streaming,
        State::Stopping,
        State::Faulted,
        State::Disabled,
    ];

    pub fn name(self) -> &'static str {
        match self {
            State::HomingEnabling => "homing_enabling",
            State::HomingSeek => "homing_seek",
            State::HomingSeekStop => "homing_seek_stop",
            State::HomingReturn => "homing_return",
            State::HomingReturnStop => "homing_return_stop",
            State::HomingMoveHome => "homing_move_home",
            State::HomingStopping => "homing_stopping",
            State::Enabling => "enabling",
            State::Jogging => "jogging",
            State::Moving => "moving",
            State::Streaming => "streaming",
            State::Stopping => "stopping",
            State::Faulted => "faulted",
            State::Disabled => "disabled",
        }
    }

    /// The homing phase of a homing state.
    fn phase(self) -> Option<Phase> {
        Some(match self {
            State::HomingEnabling => Phase::Enabling,
            State::HomingSeek => Phase::Seek,
            State::HomingSeekStop => Phase::SeekStop,
            State::HomingReturn => Phase::Return,
            State::HomingReturnStop => Phase::ReturnStop,
            State::HomingMoveHome => Phase::MoveHome,
            _ => return None,
        })
    }
}

/// The machines every run starts from.
pub struct Bases {
    /// Homed, enabled, at rest at 0.
    homed: Rig,
    /// Disabled, at rest at −10, homing just asked for.
    homing: Rig,
}

impl Bases {
    pub fn prepare() -> Self {
        let mut b = Bench::new(MACHINE);
        b.core = b.core.clone().with_session_key(KEY);
        let mut r = Rig::new(b);
        r.run(5);
        let homing = {
            let mut h = r.clone();
            home(&mut h);
            h
        };
        home(&mut r);
        for _ in 0..3000 {
            r.cycle();
            let s = r.b.core.axes()[0].status();
            if !s.ip && s.homed && s.phase == Phase::Idle {
                break;
            }
        }
        r.run(20);
        let s = r.b.core.axes()[0].status();
        assert!(s.homed && s.pc && s.servo_action, "{s:?}");
        assert!(
            r.plant().position().abs() <= REFERENCE,
            "{}",
            r.plant().position()
        );
        r.answers.clear();
        Self { homed: r, homing }
    }
}

fn home(r: &mut Rig) {
    r.control(Control::undated(
        1,
        Ask::Home {
            mask: 1,
            parallel: false,
            timeout_ns: 0,
        },
    ));
}

fn op(r: &mut Rig, op: Operation, token: u64) {
    r.control(Control::undated(2, Ask::Op { mask: 1, op, token }));
}

/// A random point of `state`, from the prepared machines.
pub fn enter(bases: &Bases, state: State, rng: &mut Rng) -> Rig {
    if let Some(phase) = state.phase() {
        let mut r = bases.homing.clone();
        let dwell = rng.below(0, 400);
        until(&mut r, 6000, |r| r.b.core.axes()[0].status().phase == phase);
        let mut n = 0;
        while n < dwell && r.b.core.axes()[0].status().phase == phase {
            r.cycle();
            n += 1;
        }
        return r;
    }
    let mut r = bases.homed.clone();
    match state {
        State::HomingStopping => {
            r = bases.homing.clone();
            until(&mut r, 6000, |r| {
                r.b.core.axes()[0].status().phase == Phase::Seek
            });
            r.run(rng.below(40, 400));
            r.control(Control::undated(3, Ask::Stop { mask: 1 }));
            r.cycle();
            r.run(rng.below(0, 38));
        }
        State::Enabling => {
            disable(&mut r);
            op(&mut r, Operation::Enable, 0);
            r.run(rng.below(1, 29));
        }
        State::Jogging => {
            jog(&mut r, rng);
            r.run(rng.below(1, 600));
        }
        State::Moving => {
            let speed = rng.real(5.0, MAX_SPEED);
            op(&mut r, moving(rng.real(-45.0, 45.0), speed, rng), 0);
            r.run(rng.below(1, 400));
        }
        State::Streaming => {
            stream(&mut r, rng);
            r.run(rng.below(1, 800));
        }
        State::Stopping => {
            jog(&mut r, rng);
            r.run(rng.below(100, 400));
            r.control(Control::undated(3, Ask::Stop { mask: 1 }));
            r.cycle();
            r.run(rng.below(0, 20));
        }
        State::Faulted => {
            r.b.plants[0].inject_fault();
            r.run(rng.below(10, 100));
            assert!(r.b.core.axes()[0].status().faulted);
        }
        State::Disabled => {
            disable(&mut r);
            r.run(rng.below(0, 100));
        }
        _ => unreachable!("homing phases are entered above"),
    }
    r
}

fn until(r: &mut Rig, max: u64, f: impl Fn(&Rig) -> bool) {
    for _ in 0..max {
        if f(r) {
            return;
        }
        r.cycle();
    }
}

fn disable(r: &mut Rig) {
    op(r, Operation::Disable, 0);
    r.run(10);
    assert!(!r.plant().feedback().drive.enabled);
}

/// A jog held by a live HMI (renewed every 100 ms, lease 500 ms).
fn jog(r: &mut Rig, rng: &mut Rng) {
    let speed = rng.real(5.0, MAX_SPEED);
    let token = 0x10 + rng.below(0, 1000);
    op(
        r,
        Operation::Jog(JogSpec {
            speed: if rng.coin() { speed } else { -speed },
            lease: Some((500 * MS) as f64 * 1e-9),
            accel: Some(rng.real(500.0, 2000.0)),
            decel: Some(rng.real(500.0, MAX_DECEL)),
        }),
        token,
    );
    r.client = Client::Jog {
        token,
        every: 100,
        alive: true,
    };
}

fn moving(target: f64, speed: f64, rng: &mut Rng) -> Operation {
    Operation::Move(MoveSpec {
        target,
        relative: false,
        speed: Some(speed),
        accel: Some(rng.real(500.0, 2000.0)),
        decel: Some(rng.real(500.0, MAX_DECEL)),
        supersede: false,
    })
}

/// A program streaming at the cycle rate within the stream's bounds.
fn stream(r: &mut Rig, rng: &mut Rng) {
    let token = 0x1000 + rng.below(0, 1000);
    r.control(Control::undated(4, Ask::StreamAcquire { mask: 1, token }));
    r.cycle();
    let p = r.b.core.axes()[0].command().position;
    r.client = Client::Stream(Program {
        token,
        seq: 0,
        t_ns: 1_000_000_000,
        p,
        v: 0.0,
        accel: 0.8 * STREAM_ACCEL,
        vmax: 0.8 * MAX_SPEED,
        room: 45.0,
        push: 0.0,
        hold: 0,
        alive: true,
        last_k: r.k(),
    });
}
