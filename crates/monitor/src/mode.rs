//! What the axis was asked to do, as the monitor keeps it: from the
//! requests the engine accepted (an operation with the speed and
//! accelerations its request carried, a homing started, the setpoints
//! that arrived) and their ends, never from the engine's plan. The bounds
//! each one allows are here.

use crate::bounds::Bounds;
use crate::events::{Cycle, Events};
use motion_homing::{JogSpec, MoveSpec, Operation, Phase};

/// The motion asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Asked {
    /// Nothing: the axis holds.
    Rest,
    /// A homing sequence (its legs, its abort's stop and release).
    Homing,
    /// A jog or a move as its request carried it (`jerk` 0: a
    /// trapezoid; above 0 an S-curve, whose stops and slow-downs build up
    /// their deceleration at that jerk).
    Op {
        speed: f64,
        accel: f64,
        decel: f64,
        jerk: f64,
    },
    /// The supervised setpoint stream: when its last setpoint arrived
    /// (the stream start counts as one), and whether it was released (it
    /// then lands on that setpoint).
    Stream { arrived_ns: u64, released: bool },
    /// Gearing (MAG): the slave follows its master step by step, within
    /// the bounds of the axis's step-by-step motions (its speed cap,
    /// `stream_acceleration`), as long as the engine shows GearingStatus.
    Gear,
}

/// What is allowed now: the motion asked for, and whether it is coming to
/// rest (a stop, a fault, its end): then the speed cap is 0 and the bound
/// decays at the motion's deceleration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Mode {
    pub asked: Asked,
    pub stopping: bool,
}

impl Default for Mode {
    fn default() -> Self {
        Self {
            asked: Asked::Rest,
            stopping: true,
        }
    }
}

/// The bounds a mode allows, units/s and units/s².
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Allowed {
    /// The speed cap.
    pub cap: f64,
    /// Acceleration while the speed grows.
    pub accel: f64,
    /// Deceleration while it shrinks, at most (also the monitor's own
    /// stop: at least `max_deceleration`).
    pub decel: f64,
    /// Deceleration its stops reach at least: the rate the speed bound
    /// decays at after the cap dropped.
    pub brake: f64,
    /// How long after the cap dropped the bound may hold before it decays
    /// at `brake`, ns: 0 for a trapezoid; for an S-curve the time its
    /// stop needs to turn its acceleration into `brake` at the jerk
    /// ((accel + brake / 2) / jerk — from +accel, through 0, to −brake:
    /// the speed such a stop keeps above a linear decay from the cap).
    pub hold_ns: u64,
}

impl Mode {
    /// The mode after this cycle's events, with the engine's status after
    /// the step (which says when a motion has ended; it can end the motion
    /// asked for, never allow more).
    pub fn next(self, ev: &Events, c: &Cycle) -> Mode {
        let st = c.status;
        let run = |asked| Mode {
            asked,
            stopping: false,
        };
        if ev.home_started || st.ip {
            return run(Asked::Homing);
        }
        if self.asked == Asked::Homing && !self.stopping && st.phase != Phase::Idle {
            // A homing's abort: its stop and the release after a hard stop.
            return self;
        }
        let mut m = self;
        if m.asked == Asked::Homing || ev.stop || ev.faulted {
            m.stopping = true;
        }
        match ev.accepted {
            // Resolved (the monitor resolves what the engine accepted the
            // same way): a parameter still left out has no bound to give.
            Some(Operation::Jog(JogSpec {
                speed,
                accel: Some(accel),
                decel: Some(decel),
                jerk,
                ..
            }))
            | Some(Operation::Move(MoveSpec {
                speed: Some(speed),
                accel: Some(accel),
                decel: Some(decel),
                jerk,
                ..
            })) => {
                m = run(Asked::Op {
                    speed: speed.abs(),
                    accel,
                    decel,
                    jerk: jerk.unwrap_or(0.0),
                })
            }
            Some(Operation::StreamStart) => {
                m = run(Asked::Stream {
                    arrived_ns: c.now_ns,
                    released: false,
                })
            }
            Some(Operation::Gear(_)) => m = run(Asked::Gear),
            // MCD: the running jog's or move's new dynamics (left out: as
            // they were). A lower speed is reached at the deceleration, as
            // after any drop of the cap (the envelope).
            Some(Operation::Change(c)) => {
                if let Asked::Op {
                    speed,
                    accel,
                    decel,
                    jerk,
                } = &mut m.asked
                {
                    *speed = c.speed.unwrap_or(*speed).abs();
                    *accel = c.accel.unwrap_or(*accel);
                    *decel = c.decel.unwrap_or(*decel);
                    *jerk = c.jerk.unwrap_or(*jerk);
                }
            }
            Some(Operation::StreamEnd) => {
                if let Asked::Stream { released, .. } = &mut m.asked {
                    *released = true;
                }
            }
            Some(Operation::Stop | Operation::Disable) => m.stopping = true,
            _ => {}
        }
        let running = match &mut m.asked {
            Asked::Op { .. } => st.jogging || st.moving,
            Asked::Stream {
                arrived_ns,
                released,
            } => {
                if c.request.setpoint.is_some() && st.streaming {
                    *arrived_ns = c.now_ns;
                }
                st.streaming || *released
            }
            Asked::Gear => st.gearing,
            Asked::Rest | Asked::Homing => false,
        };
        if !running {
            m.stopping = true;
        }
        m
    }

    /// What this mode allows at `now_ns` on an axis homed or not.
    pub fn allowed(&self, b: &Bounds, homed: bool, now_ns: u64) -> Allowed {
        let mut hold_ns = 0;
        let (cap, accel, decel, brake) = match self.asked {
            Asked::Rest => (0.0, 0.0, b.max_deceleration, b.max_deceleration),
            Asked::Homing => (
                b.home_speed,
                b.home_acceleration,
                b.home_deceleration.max(b.max_deceleration),
                b.home_deceleration,
            ),
            Asked::Op {
                speed,
                accel,
                decel,
                jerk,
            } => {
                if jerk > 0.0 && jerk.is_finite() {
                    let s = (accel + decel / 2.0) / jerk;
                    hold_ns = if s.is_finite() { (s * 1e9) as u64 } else { 0 };
                }
                (
                    speed.min(b.speed_cap(homed)),
                    accel,
                    decel.max(b.max_deceleration),
                    decel,
                )
            }
            // The follower slows a geared slave (its master stopping, its
            // cap dropping) at no more than `stream_acceleration`: its
            // bound decays no faster.
            Asked::Gear => (
                b.speed_cap(homed),
                b.stream_acceleration,
                b.stream_acceleration.max(b.max_deceleration),
                b.stream_acceleration.min(b.max_deceleration),
            ),
            Asked::Stream { arrived_ns, .. } => {
                // A program that stops sending is stopped within the
                // stream's timeout of its last setpoint's arrival, plus
                // the stopping distance.
                let fresh = now_ns.saturating_sub(arrived_ns) <= b.stream_timeout_ns;
                (
                    if fresh { b.speed_cap(homed) } else { 0.0 },
                    b.stream_acceleration,
                    b.stream_acceleration.max(b.max_deceleration),
                    b.max_deceleration,
                )
            }
        };
        let num = |x: f64| if x.is_nan() { 0.0 } else { x };
        Allowed {
            cap: if self.stopping { 0.0 } else { num(cap) },
            accel: num(accel),
            decel: num(decel),
            brake: num(brake),
            hold_ns,
        }
    }
}
