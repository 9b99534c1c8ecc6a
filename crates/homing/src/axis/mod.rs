//! The per-axis homing state machine, stepped once per cycle.
//!
//! `step(now, feedback, request) -> Command`: the feedback is the drive's
//! answer to an earlier command, `now` is the cycle's monotonic time. No
//! clock, thread, allocation or I/O in here: the same inputs give the same
//! commands, so a test can drive it cycle by cycle against a plant model.
//!
//! The machine runs the legs of its sequence's [plan](crate::plan) in order;
//! its state (`state.rs`) carries only what the current phase needs.
//! Where the rest lives:
//!
//! * `intake`: which feedback may be used at all, with `loss` (the
//!   feedback-loss rule, a leaky bucket in time) and `plausible` (forged or
//!   corrupt frames never become an event);
//! * `detect`: finding a search leg's goal (events and their precision);
//! * `legs`: starting each leg (or holding at a coordinator's barrier),
//!   what its find means, what follows it;
//! * `at_limit`: the limit switches while homing (abort, carry on on the
//!   limit a leg means to be on, or reverse the search);
//! * `reference`: the stored reference of an absolute axis;
//! * this file: requests (start, stop, shutdown), aborts, completion, the
//!   status and the command written each cycle.
//!
//! Design notes a reviewer will look for:
//!
//! * **Commands never come from unchecked feedback.** The command is sampled
//!   from a profile planned from the previous command state; the actual
//!   position only enters as a hold / release target after validation.
//! * **Coordination.** Each axis is its own engine; a coordinator (gantry
//!   sides, home order) synchronises them only through `Request::hold` (a
//!   barrier at rest before each leg that moves), `move_duration_ns` (a
//!   final move of a given length) and `stop_code`, and reads `Status::leg`,
//!   `waiting`, `min_move_ns`. Nothing here knows about other axes.
//! * **Aborts** (stop, timeout, search limit, lost, invalid or implausible
//!   feedback, an ambiguous marker when refused) stop
//!   the axis at Home Deceleration with the overrides still in force, release
//!   if needed, then restore. A drive fault, a dropped power stage, a lost
//!   drive, a restarted I/O process or shutdown cannot be stopped by us: the
//!   drive is disabled and the overrides restored at once — also during an
//!   abort's stop, which is then abandoned (`ops::power`).

mod at_limit;
mod detect;
pub mod drive_homing;
mod followed;
mod intake;
mod latches;
mod legs;
pub mod loss;
mod ops;
mod plausible;
mod reference;
mod registration;
mod state;
mod tripped;

use crate::codes::*;
use crate::config::*;
use crate::io::*;
use crate::op_limits::OpLimits;
use crate::operation::StopCause;
use crate::plan::Leg;
use crate::position::wrap;
use crate::profile::Profile;
use crate::status::Status;
use crate::time::secs_to_ns;
use crate::validate::{effective_search_limit, validate, ConfigError};
use at_limit::AtLimit;
use followed::Followed;
use intake::{Sample, Seen};
use latches::Latches;
use loss::FeedbackLoss;
use ops::Ops;
use plausible::Plausibility;
pub use reference::RestoreRefusal;
use registration::Registration;
use state::{Run, State};

/// How an abort treats the axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Abort {
    /// We still control the drive: decelerate, release, restore.
    Controlled,
    /// The drive is faulted or shut down: disable, restore at once.
    Disable,
}

/// One axis's homing engine.
#[derive(Clone, Debug)]
pub struct Axis {
    cfg: AxisConfig,
    /// EXERR of the first configuration problem, reported at start.
    config_error: Option<u16>,
    search_limit: f64,
    /// Home Direction as ±1.
    dir: f64,
    /// Times of the configuration in ns, worked out once: `home_timeout`
    /// (`None` when not positive), `enable_timeout`, `home_torque_time`.
    home_timeout_ns: Option<u64>,
    enable_timeout_ns: u64,
    torque_time_ns: u64,
    /// What [`Axis::output`] writes besides the motion, worked out once.
    out: OutputLimits,
    /// The bounds of the operations around homing, worked out once.
    limits: OpLimits,
    /// What the operations keep besides the state (power stage, reset,
    /// the previous step's time).
    ops: Ops,
    status: Status,
    /// What the engine keeps of the latest request.
    request: Kept,
    state: State,
    profile: Followed,
    /// The power stage is requested on.
    enable: bool,
    /// Torque limits and error tolerances overridden (torque sequences).
    overrides: bool,
    latches: Latches,
    /// The armed registration (MAR), if any.
    reg: Registration,
    /// The newest valid sample, and what the detection needs of the one
    /// before it.
    prev: Option<Seen>,
    last: Option<Sample>,
    /// Time of the last usable sample, ns.
    last_sample_ns: Option<u64>,
    loss: FeedbackLoss,
    plausible: Plausibility,
    /// axis position = raw + offset (wrapped on a cyclic axis).
    offset: f64,
    /// The part of `offset` redefine position added since the reference
    /// was established: the soft limits are `travel_limits` + `shift` in
    /// axis coordinates, so on the machine they do not move.
    shift: f64,
    /// The last redefine applied (its operation id and shift), so a
    /// gantry's redefine can be taken back when another side refused it.
    last_redefine: Option<(u32, f64)>,
    last_command: Command,
}

impl Axis {
    /// Builds the engine. An invalid configuration is accepted here and
    /// reported by the instruction (ER, ERR 41) at start, as a controller
    /// does; [`Axis::config_errors`] lists every problem up front.
    pub fn new(cfg: AxisConfig) -> Self {
        let errors = validate(&cfg);
        let cmd = Command {
            torque_limit_positive: finite_or(cfg.torque_limit, 0.0),
            torque_limit_negative: finite_or(cfg.torque_limit, 0.0),
            position_error_tolerance: finite_or(cfg.position_error_tolerance, 0.0),
            velocity_error_tolerance: finite_or(cfg.velocity_error_tolerance, 0.0),
            ..Command::default()
        };
        Self {
            config_error: errors.first().map(|e| e.exerr),
            search_limit: effective_search_limit(&cfg),
            dir: cfg.home_direction.sign(),
            home_timeout_ns: (cfg.home_timeout > 0.0).then(|| secs_to_ns(cfg.home_timeout)),
            enable_timeout_ns: secs_to_ns(cfg.enable_timeout),
            torque_time_ns: secs_to_ns(cfg.home_torque_time),
            out: OutputLimits::new(&cfg),
            limits: OpLimits::new(&cfg),
            ops: Ops::default(),
            cfg,
            status: Status::default(),
            request: Kept::default(),
            state: State::Idle,
            profile: Followed::new(Profile::hold(0, 0.0)),
            enable: false,
            overrides: false,
            latches: Latches::default(),
            reg: Registration::default(),
            prev: None,
            last: None,
            last_sample_ns: None,
            loss: FeedbackLoss::default(),
            plausible: Plausibility::new(&cfg),
            offset: 0.0,
            shift: 0.0,
            last_redefine: None,
            last_command: cmd,
        }
    }

    pub fn config(&self) -> &AxisConfig {
        &self.cfg
    }

    /// Every configuration problem (empty when valid).
    pub fn config_errors(&self) -> Vec<ConfigError> {
        validate(&self.cfg)
    }

    pub fn status(&self) -> &Status {
        &self.status
    }

    /// Axis position of a raw position under the current reference.
    pub fn to_axis(&self, raw: f64) -> f64 {
        let x = raw + self.offset;
        match self.cfg.travel {
            TravelMode::Cyclic if self.cfg.unwind > 0.0 => wrap(x, self.cfg.unwind),
            _ => x,
        }
    }

    /// Raw actual position from the newest valid feedback.
    pub fn raw_position(&self) -> Option<f64> {
        self.last.map(|s| s.fb.position)
    }

    /// When the newest valid feedback was taken: the `now_ns` of its step.
    /// A step whose feedback was refused (not finite, out of range,
    /// implausible) leaves it as it was.
    pub fn sampled_ns(&self) -> Option<u64> {
        self.last_sample_ns
    }

    /// Axis actual position from the newest valid feedback.
    pub fn axis_position(&self) -> Option<f64> {
        self.raw_position().map(|r| self.to_axis(r))
    }

    /// The last command produced.
    pub fn last_command(&self) -> &Command {
        &self.last_command
    }

    /// One cycle. `feedback` is `None` when no fresh frame arrived for this
    /// axis this cycle; `now_ns` is monotonic.
    /// EXERR of the first configuration problem (ERR 41), if any: what a
    /// Home request would be refused with. No allocation.
    pub fn config_error(&self) -> Option<u16> {
        self.config_error
    }

    /// Operator's "unhome": clears HomedStatus. Refused (`false`) while
    /// homing is in process — stop first.
    pub fn clear_homed(&mut self) -> bool {
        if self.status.ip {
            return false;
        }
        self.status.homed = false;
        true
    }

    /// The drive connection was re-established (its I/O process restarted
    /// or re-attached): HomedStatus is cleared (CIP: reconnection clears it),
    /// samples and the plausibility anchor from before are forgotten, the
    /// enable request is withdrawn (the new process's drives are off and
    /// stay off until someone enables them), and homing in process is
    /// aborted with ERR 12 / EXERR 40 — the feedback it relied on was
    /// interrupted.
    pub fn reconnected(&mut self, now_ns: u64) {
        self.prev = None;
        self.last = None;
        self.last_sample_ns = None;
        self.plausible = Plausibility::new(&self.cfg);
        self.status.homed = false;
        // The drives of a new I/O process are off: a motion ends with them,
        // and nothing asks for them on again by itself.
        self.drive_gone_away(now_ns, EX_FEEDBACK_LOST);
        if self.status.ip {
            // Homing that only watched the axis: the feedback it relied on
            // was interrupted.
            self.fail(
                now_ns,
                ERR_SERVO_MESSAGE,
                EX_FEEDBACK_LOST,
                Abort::Controlled,
            );
        }
    }

    pub fn step(&mut self, now_ns: u64, feedback: Option<&Feedback>, request: &Request) -> Command {
        self.drive_presence(request.drive_lost);
        let fresh = self.intake(now_ns, feedback, request.stalled);
        self.requests(now_ns, request);
        // A fresh sample is the newest one (requests never drop it).
        match self.last.filter(|_| fresh) {
            Some(s) => self.advance(now_ns, &s),
            None => self.advance_blind(now_ns),
        }
        self.settle();
        self.report(now_ns);
        let cmd = self.output(now_ns);
        self.ops.prev_step_ns = Some(now_ns);
        self.ops.limits_before = self.soft_limits_raw();
        cmd
    }

    /// The status fields that describe the state after this step.
    fn report(&mut self, now: u64) {
        self.status.phase = self.state.phase();
        self.status.stopping = matches!(self.state, State::Stopping { .. });
        self.status.waiting = false;
        self.status.min_move_ns = 0;
        self.report_ops();
        self.status.shift = self.shift;
        self.status.soft_limits = self.soft_limits_axis();
        let State::Homing(h) = &self.state else {
            return;
        };
        self.status.leg = u8::try_from(h.leg).unwrap_or(u8::MAX);
        match (&h.run, h.current()) {
            (Run::Waiting { min_move_ns }, _) => {
                self.status.waiting = true;
                self.status.min_move_ns = *min_move_ns;
            }
            (Run::Search(search), Some(Leg::Watch(_))) => {
                let actual = self.last.map_or(search.start, |s| s.fb.position);
                self.status.search_travel = (actual - search.start).abs();
            }
            (Run::Search(search), _) => {
                self.status.search_travel = (self.profile.at(now).0 - search.start).abs();
            }
            (Run::Profile { .. } | Run::Drive(_), _) => {}
        }
    }

    // ------------------------------------------------------------------
    // Requests and start
    // ------------------------------------------------------------------

    fn requests(&mut self, now: u64, req: &Request) {
        let prev = self.request;
        self.ops.master = req.master;
        self.request = Kept {
            home: req.home,
            stop: req.stop,
            shutdown: req.shutdown,
            hold: req.hold,
            move_duration_ns: req.move_duration_ns,
        };
        if req.shutdown {
            if self.status.ip {
                self.fail(now, ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN, Abort::Disable);
            }
            self.shutdown_ops(now);
            self.status.homed = false;
        }
        if req.stop && !prev.stop {
            if self.status.ip {
                let (err, exerr) = req
                    .stop_code
                    .unwrap_or((ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST));
                self.fail(now, err, exerr, Abort::Controlled);
            }
            self.stop_motion(now, None, StopCause::Operator);
        }
        if req.home && !prev.home {
            self.start(now, req.shutdown);
        }
        if let Some(op) = req.op {
            self.operation(now, op);
        }
        self.operation_inputs(now, req.jog_renew, req.setpoint);
        if !req.home && (self.status.dn || self.status.er) {
            self.status.en = false;
        }
    }

    fn start(&mut self, now: u64, shutdown: bool) {
        if self.status.ip {
            // Re-triggering a running instruction changes nothing.
            return;
        }
        self.status = Status {
            en: true,
            homed: self.status.homed,
            prior_offset: self.status.homed.then_some(self.offset - self.shift),
            feedback_ok: self.status.feedback_ok,
            feedback_gap_ns: self.status.feedback_gap_ns,
            feedback_loss_ns: self.status.feedback_loss_ns,
            implausible: self.status.implausible,
            started_ns: now,
            faulted: self.status.faulted,
            last_stop: self.status.last_stop,
            op: self.status.op,
            redefines: self.status.redefines,
            registration_armed: self.status.registration_armed,
            registration_position: self.status.registration_position,
            ..Status::default()
        };
        // Logix: MAH on a faulted axis errors (20); a jog, move or stream
        // must be stopped first (3); a stop in progress is taken over.
        if self.status.faulted {
            return self.fail(now, ERR_AXIS_FAULTED, 0, Abort::Controlled);
        }
        if self.op_in_motion() {
            return self.fail(now, ERR_EXECUTION_COLLISION, 0, Abort::Controlled);
        }
        if let Some(exerr) = self.config_error {
            return self.fail(now, ERR_ILLEGAL_HOMING_CONFIG, exerr, Abort::Controlled);
        }
        if shutdown {
            return self.fail(now, ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN, Abort::Controlled);
        }
        let Some(s) = self.last else {
            return self.fail(now, ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST, Abort::Controlled);
        };
        self.homing_takes_over();
        // Home and registration exclude each other: the homing needs the
        // latches, and its new reference would move the window.
        self.disarm_registration();
        self.status.ip = true;
        self.status.homing = true;
        self.status.homed = false;

        if self.cfg.home_sequence == HomeSequence::Immediate
            || self.cfg.home_mode == HomeMode::Absolute
        {
            // Actual and command position become Home Position: nothing moves,
            // the reference is redefined from the raw (encoder) position —
            // never from the axis position, so homing again never adds an
            // offset twice. Home Offset does not apply.
            self.offset = self.cfg.home_position - s.fb.position;
            self.shift = 0.0;
            return self.complete(now, true);
        }
        match self.cfg.home_mode {
            HomeMode::Passive | HomeMode::Absolute => self.begin(now, &s),
            HomeMode::Active => {
                self.enable = true;
                if s.fb.drive.enabled && !s.fb.drive.fault {
                    self.begin(now, &s);
                } else {
                    self.state = State::Enabling { since: now };
                }
            }
        }
    }

    // ------------------------------------------------------------------
    // Per-cycle progress
    // ------------------------------------------------------------------

    fn advance(&mut self, now: u64, s: &Sample) {
        self.registration_step(now, s);
        self.power_tick(now);
        self.watch_drive(now, s);
        let moving = self.state.commands_motion();
        let stopping = matches!(self.state, State::Stopping { .. } | State::Motion(_));
        self.follow_the_drive(now, s);
        if !moving && !stopping && !s.fb.drive.enabled {
            // Nobody holds the axis: follow it, so enabling never jumps.
            self.profile.set(Profile::hold(now, s.fb.position));
        }
        if matches!(self.state, State::Idle) && s.fb.drive.fault && !self.in_reset() {
            self.enable = false;
        }
        if moving {
            if s.fb.drive.fault {
                return self.fail(now, ERR_SERVO_MESSAGE, EX_DRIVE_FAULT, Abort::Disable);
            }
            if !s.fb.drive.enabled {
                return self.fail(
                    now,
                    ERR_SERVO_MESSAGE,
                    EX_TERMINATED_ON_REQUEST,
                    Abort::Disable,
                );
            }
            // A limit switch in the direction of travel (`at_limit`).
            match self.at_limit(now, s) {
                AtLimit::Go => {}
                AtLimit::Reverse => return self.reverse_search(now, s),
                AtLimit::Overtravel => {
                    return self.fail(now, ERR_SERVO_MESSAGE, EX_OVERTRAVEL, Abort::Controlled);
                }
            }
        }
        if self.check_timeout(now) {
            return;
        }
        if self.check_search_limit(now) {
            return;
        }
        let done = self.profile.is_done(now);
        // By reference: the state is large, and each arm needs a few words.
        match &self.state {
            State::Idle => {}
            &State::Enabling { since } => {
                if s.fb.drive.enabled && !s.fb.drive.fault {
                    self.begin(now, s);
                } else if s.fb.drive.fault && !self.in_reset() {
                    // The drive faults while we wait for it (it used to be
                    // reset by toggling the enable; now only `Reset` does).
                    self.fail(now, ERR_SERVO_MESSAGE, EX_DRIVE_FAULT, Abort::Disable);
                } else if now.saturating_sub(since) > self.enable_timeout_ns {
                    self.fail(now, ERR_SERVO_MESSAGE, EX_ENABLE_TIMEOUT, Abort::Controlled);
                } else {
                    self.enable = true;
                }
            }
            State::Homing(h) => match h.run {
                Run::Search(mut search) => {
                    let found = self.detect(now, s, &mut search);
                    if let State::Homing(h) = &mut self.state {
                        h.run = Run::Search(search);
                    }
                    if let Some(at) = found {
                        self.found(now, s, at);
                    }
                }
                Run::Profile { to_home } if done => self.profile_done(now, s, to_home),
                Run::Profile { .. } => {}
                Run::Waiting { .. } if !self.request.hold => self.start_leg(now, s),
                Run::Waiting { .. } => {}
                Run::Drive(d) => self.drive_homing_step(now, s, d),
            },
            &State::Stopping { released } if done => {
                if self.overrides && !released {
                    self.state = State::Stopping { released: true };
                    self.profile.set(self.release_profile(now, s.fb.position));
                } else {
                    self.overrides = false;
                    self.state = State::Idle;
                }
            }
            State::Stopping { .. } => {}
            State::Motion(_) => self.advance_motion(now, Some(s)),
        }
    }

    /// A cycle without valid feedback: profiles run on, nothing is detected.
    /// An abort's stop still finishes; a release (which needs the actual
    /// position) waits for feedback, keeping the reduced torque limits.
    /// Once the feedback is lost (the loss rule forgot the samples) and
    /// nothing is left to stop, the enable request is withdrawn: no request
    /// stands for a drive whose state is unknown — a drive that comes back
    /// (a restarted I/O process, a power-cycled drive) is never switched on
    /// by it.
    fn advance_blind(&mut self, now: u64) {
        self.power_tick(now);
        self.advance_motion(now, None);
        self.check_timeout(now);
        if matches!(self.state, State::Stopping { .. })
            && !self.overrides
            && self.profile.is_done(now)
        {
            self.state = State::Idle;
        }
        if self.enable && self.last.is_none() && matches!(self.state, State::Idle) {
            self.power_off();
        }
    }

    fn check_timeout(&mut self, now: u64) -> bool {
        let Some(t) = self.home_timeout_ns else {
            return false;
        };
        if self.status.ip && now.saturating_sub(self.status.started_ns) > t {
            self.fail(now, ERR_TIMEOUT, 0, Abort::Controlled);
            return true;
        }
        false
    }

    /// A commanded search leg that travelled beyond the search limit fails
    /// with ERR 1016 and the leg's EXERR (see `codes`).
    fn check_search_limit(&mut self, now: u64) -> bool {
        let State::Homing(h) = &self.state else {
            return false;
        };
        let (Run::Search(search), Some(leg)) = (&h.run, h.current()) else {
            return false;
        };
        let start = search.start;
        let exerr = match leg {
            Leg::Seek(_) => EX_SEARCH_SEEK,
            Leg::Return(_) => EX_SEARCH_RETURN,
            Leg::Creep => EX_SEARCH_CREEP,
            Leg::Pass(_) => EX_SEARCH_REVERSE,
            _ => return false,
        };
        let p = self.profile.at(now).0;
        if (p - start).abs() > self.search_limit {
            self.fail(now, ERR_SEARCH_LIMIT, exerr, Abort::Controlled);
            return true;
        }
        false
    }

    // ------------------------------------------------------------------
    // Endings
    // ------------------------------------------------------------------

    fn complete(&mut self, now: u64, pc: bool) {
        self.status.ip = false;
        self.status.dn = true;
        self.status.pc = pc;
        self.status.homing = false;
        self.status.homed = true;
        self.status.finished_ns = Some(now);
        self.overrides = false;
        self.latches.disarm();
        self.state = State::Idle;
    }

    fn fail(&mut self, now: u64, err: u16, exerr: u16, how: Abort) {
        if (err, exerr) == (ERR_SERVO_MESSAGE, EX_DRIVE_FAULT) {
            // A drive fault is an axis fault: `Reset` before the next homing.
            self.status.faulted = true;
        }
        self.status.er = true;
        self.status.pc = false;
        self.status.err = err;
        self.status.exerr = exerr;
        self.latches.disarm();
        if !self.status.ip {
            // Refused at start: nothing was started, nothing to stop.
            return;
        }
        self.status.ip = false;
        self.status.dn = true;
        self.status.homing = false;
        self.status.homed = false;
        self.status.finished_ns = Some(now);
        match how {
            Abort::Controlled => {
                let (p, v) = self.profile.at(now);
                self.profile
                    .set(Profile::stop(now, p, v, self.cfg.home_deceleration));
                self.state = State::Stopping { released: false };
            }
            Abort::Disable => {
                self.enable = false;
                self.overrides = false;
                let hold = self
                    .last
                    .map_or(self.profile.sample(now).0, |s| s.fb.position);
                self.profile.set(Profile::hold(now, hold));
                self.state = State::Idle;
            }
        }
    }

    // ------------------------------------------------------------------
    // Output
    // ------------------------------------------------------------------

    fn output(&mut self, now: u64) -> Command {
        let (mut p, mut v) = self.profile.at(now);
        if let Some(vs) = self.stepwise_command_velocity(now) {
            v = vs;
        }
        if !p.is_finite() || !v.is_finite() {
            // Unreachable by construction; never let it out if it happens.
            p = self.last_command.position;
            v = 0.0;
            self.profile.set(Profile::hold(now, p));
        }
        let o = &self.out;
        let (torque, ptol, vtol) = if self.overrides {
            (o.override_torque, 0.0, 0.0)
        } else {
            (o.torque, o.position_tolerance, o.velocity_tolerance)
        };
        let cmd = Command {
            enable: self.enable && o.servo,
            position: p,
            velocity: v,
            torque_limit_positive: torque,
            torque_limit_negative: torque,
            position_error_tolerance: ptol,
            velocity_error_tolerance: vtol,
            marker_arm: LatchArm {
                id: self.latches.marker_id,
                edge: Edge::Rising,
            },
            switch_arm: LatchArm {
                id: self.latches.switch_id,
                edge: self.latches.switch_edge,
            },
            fault_reset: self.fault_reset_out(),
            drive_home: self.drive_home_requested(),
        };
        self.last_command = cmd;
        self.plausible.commanded(cmd.position);
        cmd
    }
}

/// What the engine keeps of the latest request: the rung and stop levels
/// (their rising edges are what counts) and the coordination it follows.
#[derive(Clone, Copy, Debug, Default)]
struct Kept {
    home: bool,
    stop: bool,
    /// `Request::shutdown` (a level).
    shutdown: bool,
    /// `Request::hold`.
    hold: bool,
    /// `Request::move_duration_ns`.
    move_duration_ns: u64,
}

/// The torque limits and error tolerances a command carries, finite (0 where
/// the configuration's is not), from a configuration that never changes.
#[derive(Clone, Copy, Debug)]
struct OutputLimits {
    /// The power stage may be enabled at all (a servo axis).
    servo: bool,
    torque: f64,
    position_tolerance: f64,
    velocity_tolerance: f64,
    /// Home Torque Level, in force while a torque sequence overrides the
    /// limits (the tolerances are then off).
    override_torque: f64,
}

impl OutputLimits {
    fn new(cfg: &AxisConfig) -> Self {
        Self {
            servo: cfg.configuration == AxisConfiguration::Servo,
            torque: finite_or(cfg.torque_limit, 0.0),
            position_tolerance: finite_or(cfg.position_error_tolerance, 0.0),
            velocity_tolerance: finite_or(cfg.velocity_error_tolerance, 0.0),
            override_torque: finite_or(cfg.home_torque_level, 0.0),
        }
    }
}

fn finite_or(x: f64, fallback: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        fallback
    }
}
