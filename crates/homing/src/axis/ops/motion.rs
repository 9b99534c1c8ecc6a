//! What an operation's motion carries from one step to the next, kept in
//! `State::Motion`: only data, so the state file can name it without the
//! behaviour (which lives in the files beside this one). Why a stop
//! began is in `Status::last_stop`, set when it began.

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
}

/// A jog: the request, and how its profile was planned.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Jog {
    /// As asked: the sign is the direction.
    pub speed: f64,
    pub accel: f64,
    pub decel: f64,
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
    /// The speed planned (the asked one, or less under the unhomed cap).
    pub planned_speed: f64,
}

/// The supervised stream: the last setpoint taken, and the segment the
/// command follows towards it.
#[derive(Clone, Copy, Debug)]
pub(in crate::axis) struct Stream {
    /// The last setpoint accepted: program time, raw position (unwrapped
    /// on a cyclic axis) and its segment velocity on the program's
    /// timeline (for the acceleration check). `None` before the first.
    pub prev: Option<Taken>,
    /// When the command reaches the last setpoint (ns, engine time);
    /// silence is counted from here.
    pub seg_end_ns: u64,
    /// Velocity of the segment the command follows, units/s.
    pub seg_velocity: f64,
    /// The setpoint's velocity feed-forward, if it had one.
    pub feed_forward: Option<f64>,
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
}
