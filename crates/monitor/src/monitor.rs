//! The monitor of one axis: every cycle, the command that left the engine
//! is judged against the invariants and passed on, or the axis is stopped
//! by the monitor itself.
//!
//! Positions are judged as the drive receives them (raw), on the
//! differences of consecutive commands over the times between their
//! cycles (divided differences: a late cycle is judged over the time it
//! really spanned). A sampled profile whose continuous speed and
//! acceleration stay within their bounds has first differences within the
//! speed bound, and average velocities of consecutive intervals that differ
//! by at most the acceleration bound × their mean length (≤ the longer
//! one), so the checks hold for every correct plan at any cycle timing.

use crate::bounds::{Bounds, Kind};
use crate::envelope::Envelope;
use crate::events::{Cycle, Events, Seen};
use crate::mode::{Allowed, Mode};
use crate::power::Power;
use crate::ramp::Ramp;
use crate::trip::{within, Broken, Category, Invariant, Trip};
use motion_homing::time::ns_to_s;
use motion_homing::{AxisConfig, Command, Operation, Phase};

/// Relative tolerance of every bound: a command exactly at a bound passes
/// whatever its rounding.
pub const TOLERANCE: f64 = 1e-6;
/// Rounding of a position, relative to its magnitude (64 ulp): what two
/// samples of one exact trajectory may differ by beyond the trajectory.
pub const POSITION_ROUNDING: f64 = 64.0 * f64::EPSILON;

/// The last command passed, and the interval that ended with it.
#[derive(Clone, Copy, Debug, Default)]
struct History {
    /// Time and raw position of the last command.
    last: Option<(u64, f64)>,
    /// The interval that ended there, when it was judged (the drive
    /// followed): its average velocity, units/s, and length, s.
    interval: Option<(f64, f64)>,
    /// The drive followed the last command. A command it did not follow
    /// (its power stage off, or the drive homing itself while the command
    /// follows its readings) says nothing about where the drive is: the
    /// first command it follows again is a step from the drive's newest
    /// reading, not from that command. (A drive homing itself redefines
    /// its position; which frame shows the redefined one — the last of
    /// its homing or the first after — is the frames' timing, and the
    /// command held at the reading before is in the old frame.)
    followed: bool,
}

/// The monitor's own stop in progress.
#[derive(Clone, Copy, Debug)]
struct Tripped {
    trip: Trip,
    ramp: Ramp,
    /// The power stage is still asked on (category 1, not at rest yet).
    power: bool,
}

/// The cycle monitor of one axis. `Copy`-sized, no heap, no panics.
#[derive(Clone, Debug)]
pub struct Monitor {
    b: Bounds,
    seen: Seen,
    mode: Mode,
    /// The bounds of the two cycles before: a second difference spans the
    /// two intervals their plans were followed in, and is judged against
    /// the largest of their bounds and this cycle's.
    before: Allowed,
    before2: Allowed,
    env: Envelope,
    power: Power,
    hist: History,
    /// `hist` before this cycle's command was passed (a gantry's verdict,
    /// which comes after every side's, stops from there).
    undo: History,
    /// This cycle's command drives the axis (its drive follows it).
    following: bool,
    /// The raw → axis offset while homed, as of this cycle.
    reference: Option<f64>,
    /// The drive's position in its newest valid feedback (raw).
    reading: Option<f64>,
    tripped: Option<Tripped>,
    trips: u32,
    /// The axis's configuration: an accepted operation's left-out
    /// parameters are resolved from it as the engine resolves them
    /// (`Operation::resolve`, the one place defaults are decided).
    cfg: AxisConfig,
}

impl Monitor {
    pub fn new(cfg: &AxisConfig) -> Self {
        let b = Bounds::new(cfg);
        let rest = Mode::default().allowed(&b, false, 0);
        Self {
            before: rest,
            before2: rest,
            b,
            seen: Seen::default(),
            mode: Mode::default(),
            env: Envelope::default(),
            power: Power::default(),
            hist: History::default(),
            undo: History::default(),
            following: false,
            reference: None,
            reading: None,
            tripped: None,
            trips: 0,
            cfg: *cfg,
        }
    }

    /// The trip in force (until a `Reset` the engine accepts).
    pub fn tripped(&self) -> Option<&Trip> {
        self.tripped.as_ref().map(|t| &t.trip)
    }

    /// Trips since start.
    pub fn trips(&self) -> u32 {
        self.trips
    }

    /// This cycle's command drives the axis and was passed.
    pub fn following(&self) -> bool {
        self.following && self.tripped.is_none()
    }

    /// One cycle: the command to send in place of `c.command` — the same,
    /// or the monitor's stop.
    pub fn check(&mut self, c: &Cycle) -> Command {
        let mut ev = self.seen.events(c);
        if let Some(op) = &mut ev.accepted {
            op.resolve(&self.cfg);
        }
        self.reference = c.reference.filter(|_| c.status.homed);
        if let Some(f) = c.feedback {
            if f.position.is_finite() && f.velocity.is_finite() {
                self.reading = Some(f.position);
            }
        }
        if self.tripped.is_some() {
            if ev.accepted == Some(Operation::Reset) {
                self.untrip();
            } else {
                return self.stopping(c.now_ns, c.command, off_now(c, &ev));
            }
        }
        self.power.observe(&ev, c.request);
        self.mode = self.mode.next(&ev, c);
        let now = self.mode.allowed(&self.b, c.status.homed, c.now_ns);
        self.undo = self.hist;
        let verdict = self.judge(c, &ev, now);
        let before = self.before;
        self.before2 = before;
        self.before = now;
        match verdict {
            Ok(()) => {
                self.seen.sent(c.command.enable);
                *c.command
            }
            Err(broken) => {
                let decel = before.decel.max(now.decel);
                let on = c.command.enable && follows_drive(&ev) && !off_now(c, &ev);
                self.trip(c.now_ns, c.command, on, broken, decel)
            }
        }
    }

    /// The command of this cycle broke an invariant judged across axes (a
    /// gantry's sides): the axis is stopped from the command before it.
    /// Call after [`Monitor::check`] in the same cycle, with the engine's
    /// command of that cycle.
    pub fn force(
        &mut self,
        now_ns: u64,
        command: &Command,
        invariant: Invariant,
        value: f64,
        bound: f64,
    ) -> Command {
        if self.tripped.is_some() {
            return self.stopping(now_ns, command, false);
        }
        self.hist = self.undo;
        let broken = Broken {
            invariant,
            value,
            bound,
            withdrawn: None,
        };
        let decel = self.before.decel;
        self.trip(now_ns, command, self.following, broken, decel)
    }

    /// This cycle's command moved the axis (it differs from the one before).
    pub fn moved(&self) -> bool {
        match (self.undo.last, self.hist.last) {
            (Some((_, a)), Some((_, b))) => a != b,
            _ => false,
        }
    }

    /// Every invariant, on this cycle's command; the history moves on.
    fn judge(&mut self, c: &Cycle, ev: &Events, a: Allowed) -> Result<(), Broken> {
        let cmd = c.command;
        if !(cmd.position.is_finite() && cmd.velocity.is_finite()) {
            let bad = if cmd.position.is_finite() {
                cmd.velocity
            } else {
                cmd.position
            };
            return Err(Broken {
                invariant: Invariant::NotFinite,
                value: bad,
                bound: f64::MAX,
                withdrawn: None,
            });
        }
        let dt = self
            .hist
            .last
            .map_or(0, |(t, _)| c.now_ns.saturating_sub(t));
        let interval_bound = self.env.interval(a.cap);
        self.env.advance(
            a.cap,
            self.before.brake.min(a.brake),
            dt,
            self.before.hold_ns.max(a.hold_ns),
        );
        self.power
            .judge(cmd.enable, self.env.at_rest(), ev, c.request)?;
        self.following = self.follows(c, ev);
        let judged = if self.following {
            self.motion(c, a, interval_bound)?
        } else {
            None
        };
        self.hist = History {
            last: Some((c.now_ns, cmd.position)),
            interval: judged,
            followed: self.following,
        };
        Ok(())
    }

    /// The drive follows this command: a servo axis asked on whose drive
    /// reports its power stage on without a fault, and does not home
    /// itself (the command then follows the drive); a virtual axis always.
    fn follows(&self, c: &Cycle, ev: &Events) -> bool {
        match self.b.kind {
            Kind::FeedbackOnly => false,
            Kind::Virtual => true,
            Kind::Servo => {
                let drive_homes = c.command.drive_home
                    || c.status.phase == Phase::DriveHoming
                    || c.feedback.is_some_and(|f| f.drive_homing.active);
                c.command.enable && follows_drive(ev) && !drive_homes
            }
        }
    }

    /// Speed, step, acceleration and soft limits of a command the drive
    /// follows; the interval it ends (velocity, length), if it has one.
    fn motion(
        &self,
        c: &Cycle,
        a: Allowed,
        interval_bound: f64,
    ) -> Result<Option<(f64, f64)>, Broken> {
        let p = c.command.position;
        let v_bound = self.env.now();
        within(
            Invariant::Velocity,
            c.command.velocity.abs(),
            v_bound,
            v_bound * TOLERANCE + 1e-12,
        )?;
        self.soft_limits(c)?;
        // The step from the command the drive followed last; after commands
        // it did not follow, from where it is (its newest reading) over the
        // interval since the last command.
        let from = match self.hist.last {
            Some((t, _)) if !self.hist.followed => self.reading.map(|r| (t, r)),
            last => last,
        };
        let Some((t0, p0)) = from else {
            return Ok(None);
        };
        let eps = POSITION_ROUNDING * (1.0 + p.abs().max(p0.abs()));
        let dt = c.now_ns.saturating_sub(t0);
        if dt == 0 {
            within(Invariant::Step, (p - p0).abs(), 0.0, eps)?;
            return Ok(None);
        }
        let h = ns_to_s(dt);
        let v = (p - p0) / h;
        within(
            Invariant::Step,
            v.abs(),
            interval_bound,
            interval_bound * TOLERANCE + 2.0 * eps / h,
        )?;
        if let Some((v1, h1)) = self.hist.interval {
            // The change of velocity between the two intervals, over the
            // longer one: a sampled profile whose acceleration stays within
            // the bound changes its average velocity by at most the bound ×
            // the mean of the two intervals (× one cycle when they are
            // equal), and a planner that allows the bound × the interval it
            // plans (a late cycle is longer) passes too.
            let hmax = h.max(h1);
            let acc = (v - v1) / hmax;
            let bound = self.accel_bound(a);
            let slack = bound * TOLERANCE + 4.0 * eps / (h * hmax);
            if acc.abs() > bound + slack && !self.braking_for_a_limit(p0, v1, v, bound) {
                return Err(Broken {
                    invariant: Invariant::Acceleration,
                    value: acc.abs(),
                    bound,
                    withdrawn: None,
                });
            }
        }
        Ok(Some((v, h)))
    }

    /// The acceleration allowed now: the largest acceleration or
    /// deceleration of the plans followed in the window (within two cycles
    /// a stop and a start in the other direction can both fall into one
    /// change of velocity).
    fn accel_bound(&self, a: Allowed) -> f64 {
        let most = |x: Allowed| x.accel.max(x.decel);
        most(a).max(most(self.before)).max(most(self.before2))
    }

    /// A stop from `v1` to `v2` (same direction, slower) that brakes
    /// harder than `bound` to end on the soft limit ahead, which braking at
    /// `bound` would have passed: not bounded here (the soft limit is; the
    /// engine's stops end on the limit, never beyond).
    fn braking_for_a_limit(&self, p0: f64, v1: f64, v2: f64, bound: f64) -> bool {
        let braking = v1 * v2 >= 0.0 && v2.abs() < v1.abs();
        braking
            && self
                .limit_ahead(v1.signum())
                .is_some_and(|l| v1 * v1 > 2.0 * bound * (l - p0) * v1.signum())
    }

    /// The soft limit in direction `dir` (raw), while homed on a linear
    /// axis with travel limits.
    fn limit_ahead(&self, dir: f64) -> Option<f64> {
        let (lo, hi) = self.b.limits?;
        let off = self.reference?;
        Some(if dir > 0.0 { hi - off } else { lo - off })
    }

    /// Inside the soft limits while homed; once outside, never further out
    /// than the command before.
    fn soft_limits(&self, c: &Cycle) -> Result<(), Broken> {
        let (Some((lo, hi)), Some(off)) = (self.b.limits, self.reference) else {
            return Ok(());
        };
        let x = c.command.position + off;
        let tol = self.b.half_count.max(1e-9 * (1.0 + x.abs()));
        let out = |x: f64| (lo - x).max(x - hi);
        let excess = out(x);
        if excess <= tol {
            return Ok(());
        }
        let before = self.hist.last.map_or(0.0, |(_, p0)| out(p0 + off));
        if excess <= before + tol {
            return Ok(());
        }
        Err(Broken {
            invariant: Invariant::SoftLimit,
            value: x,
            bound: if x > hi { hi } else { lo },
            withdrawn: None,
        })
    }

    /// Trips: the monitor's stop from the last command it passed; `on`:
    /// the power stage is on and the drive follows (category 1 possible).
    fn trip(&mut self, now: u64, cmd: &Command, on: bool, broken: Broken, decel: f64) -> Command {
        let (t0, p0, v0) = match (self.hist.last, self.hist.interval) {
            (Some((t, p)), Some((v, _))) => (t, p, v),
            (Some((t, p)), None) => (t, p, 0.0),
            (None, _) => {
                let p = cmd.position;
                (now, if p.is_finite() { p } else { 0.0 }, 0.0)
            }
        };
        let controlled =
            on && broken.invariant != Invariant::Enable && decel > 0.0 && decel.is_finite();
        let ramp = if controlled {
            Ramp::new(t0, p0, v0, decel, self.limit_ahead(v0.signum()))
        } else {
            Ramp::new(t0, p0, 0.0, f64::INFINITY, None)
        };
        let trip = Trip {
            invariant: broken.invariant,
            value: broken.value,
            bound: broken.bound,
            at_ns: now,
            category: if controlled {
                Category::Stop1
            } else {
                Category::Stop0
            },
            from: p0,
            withdrawn: broken.withdrawn,
        };
        self.trips = self.trips.wrapping_add(1);
        self.tripped = Some(Tripped {
            trip,
            ramp,
            power: controlled,
        });
        self.stopping(now, cmd, false)
    }

    /// The command while tripped: the ramp, the power stage on until it is
    /// at rest — and off at once when it must be (`off`).
    fn stopping(&mut self, now: u64, cmd: &Command, off: bool) -> Command {
        let Some(t) = self.tripped.as_mut() else {
            return *cmd;
        };
        let (p, v, done) = t.ramp.at(now);
        if done || off {
            t.power = false;
        }
        let out = Command {
            enable: t.power,
            position: p,
            velocity: if t.power { v } else { 0.0 },
            drive_home: false,
            ..*cmd
        };
        self.seen.sent(out.enable);
        out
    }

    /// A reset the engine accepted clears the trip: the axis starts from
    /// rest, off until asked on.
    fn untrip(&mut self) {
        self.tripped = None;
        self.power.reset();
        self.env.reset();
        self.mode = Mode::default();
        self.hist = History::default();
    }
}

/// The drive follows whatever it is sent (its newest state: on, no fault).
fn follows_drive(ev: &Events) -> bool {
    ev.drive.is_some_and(|d| d.enabled && !d.fault)
}

/// The power stage must be off now: the drive faulted or dropped it, is
/// lost, or the axis shuts down.
fn off_now(c: &Cycle, ev: &Events) -> bool {
    let dropped = ev
        .drive
        .is_some_and(|d| d.fault || (ev.fresh && !d.enabled));
    dropped || c.request.drive_lost || c.request.shutdown
}
