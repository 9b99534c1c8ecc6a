//! What an operation's motion carries from one step to the next, kept in
//! `State::Motion`: only data, so the state file can name it without the
//! behaviour (which lives in the files beside this one). Why a stop
//! began is in `Status::last_stop`, set when it began.

use crate::profile::Profile;

/// An operation's motion in progress: which operation it answers for, and
/// what it is doing.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Motion {
    /// `Status::op.id` of the operation that started it (a stop that
    /// replaced it carries the stop's id).
    pub op: u32,
    pub run: Run,
}

#[derive(Clone, Copy, Debug)]
pub(in crate::axis) enum Run {
    Jog(Jog),
    Move(MoveRun),
    Stream(Stream),
    /// Coming to rest (a stop, a lease, a release, a disable, a fault).
    Halt(Halt),
    /// Following a master (MAG).
    Gear(Gear),
}

/// Gearing: what the slave follows and how far it got. The geared
/// position is `slave_from + ratio × (master − master_from)` once locked.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Gear {
    /// The master's axis index (the cycle feeds its position).
    pub master: u16,
    pub ratio: f64,
    /// Follows the master's actual position (else its command).
    pub actual: bool,
    /// The clutch's acceleration (0: none).
    pub clutch: f64,
    /// Locked on: following the geared position (else the clutch is
    /// still ramping the velocity in).
    pub locked: bool,
    /// Master and slave (raw) positions the geared position counts from.
    pub master_from: f64,
    pub slave_from: f64,
    /// The master's position at the previous step (raw).
    pub master_prev: f64,
    /// The command's velocity over the last step, units/s.
    pub velocity: f64,
    /// The step the gear was accepted in: the master's velocity is known
    /// from the next one on.
    pub since_ns: u64,
}

/// A jog: the request, and how its profile was planned.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Jog {
    /// As asked: the sign is the direction.
    pub speed: f64,
    pub accel: f64,
    pub decel: f64,
    /// units/s³; 0: a trapezoid.
    pub jerk: f64,
    pub lease_ns: u64,
    /// The jog stops (normally) once `now` passes this, unless renewed.
    pub lease_until: u64,
    /// Planned as a move to the travel limit in its direction (homed,
    /// linear, limits set): it comes to rest on the limit and ends there.
    pub limited: bool,
    /// The speed planned (the asked one, or less under the unhomed cap).
    pub planned_speed: f64,
}

/// A move: its target (raw) and dynamics.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct MoveRun {
    pub target: f64,
    pub speed: f64,
    pub accel: f64,
    pub decel: f64,
    /// units/s³; 0: a trapezoid.
    pub jerk: f64,
    /// The speed planned (the asked one, or less under the unhomed cap).
    pub planned_speed: f64,
}

/// The supervised stream: the last setpoint taken, the reference path the
/// setpoints make (linear from one to the next, on the cycle's timeline),
/// and the command following it (`follower`).
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Stream {
    /// The last setpoint accepted: program time, raw position (unwrapped
    /// on a cyclic axis) and its segment velocity on the program's
    /// timeline (for the acceleration check). `None` before the first.
    pub prev: Option<Taken>,
    /// The reference's segment: from `seg_from` at `seg_start_ns` to the
    /// last setpoint (`seg_to`, raw) at `seg_end_ns`, then resting on it
    /// (engine time).
    pub seg_start_ns: u64,
    pub seg_from: f64,
    pub seg_to: f64,
    pub seg_end_ns: u64,
    /// Velocity of the reference's segment, units/s.
    pub seg_velocity: f64,
    /// The command's velocity over the last step, units/s.
    pub velocity: f64,
    /// The last step's command landed exactly on the reference.
    pub on_reference: bool,
    /// The setpoint's velocity feed-forward, if it had one.
    pub feed_forward: Option<f64>,
    /// When the last setpoint arrived (the stream's start before the
    /// first), ns, engine time: silence counts from here.
    pub arrived_ns: u64,
}

impl Stream {
    /// The reference at `t`: position and velocity (linear along the
    /// segment, exactly `seg_to` at its end and after).
    pub fn reference(&self, t: u64) -> (f64, f64) {
        let length = self.seg_end_ns.saturating_sub(self.seg_start_ns);
        Profile::segment(self.seg_start_ns, self.seg_from, self.seg_to, length).sample(t)
    }
}

/// A setpoint as the stream took it.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Taken {
    pub t_ns: u64,
    pub raw: f64,
    pub velocity: f64,
}

/// A stop in progress.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Halt {
    /// A normal end (stop, lease, release, disable, soft limit): PC when at
    /// rest. A fault's stop is not normal.
    pub normal: bool,
    /// Its deceleration: a fault during the stop brakes at least as hard.
    pub decel: f64,
    /// Its jerk: the motion's for a normal stop, 0 for a fault's (and a
    /// stream's). A fault during a jerk-limited stop plans a new one at 0.
    pub jerk: f64,
    /// The travel limits (raw) it stays inside: those that applied when it
    /// began, whatever happens to the reference while it runs.
    pub limits: Option<(f64, f64)>,
}
