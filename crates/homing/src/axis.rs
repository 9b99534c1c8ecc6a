//! The per-axis homing state machine, stepped once per cycle.
//!
//! `step(now, feedback, request) -> Command`: the feedback is the drive's
//! answer to an earlier command, `now` is the cycle's monotonic time. No
//! clock, thread, allocation or I/O in here: the same inputs give the same
//! commands, so a test can drive it cycle by cycle against a plant model.
//!
//! Design notes a reviewer will look for:
//!
//! * **Commands never come from unchecked feedback.** Feedback is validated
//!   first (finite, within `max_position`); the command is sampled from a
//!   profile planned from the previous command state, and the actual position
//!   only enters as a hold / release target after validation.
//! * **Events.** A marker (and, with `registration`, the switch) uses the
//!   drive-latched position. A switch only sampled once per cycle is placed at
//!   the midpoint of the last sample before and the first after the edge, so
//!   its error is at most half the distance travelled in one cycle.
//! * **"First marker after the switch"** is decided by position, not by time:
//!   the marker latch is armed at the start of the leg, a marker latched before
//!   the switch edge (or on the wrong side of it) is rejected and the latch
//!   re-armed. This needs marker spacing above ~2 cycles of travel, which any
//!   sane return speed gives.
//! * **Hard stops.** After a torque event the command has run past the wall by
//!   the following error plus the stopping distance. Before anything else the
//!   command is *released*: moved back onto the actual position at Home Return
//!   Speed (a profile, not a jump), so the drive's torque falls to zero before
//!   its limits are restored.
//! * **Aborts** (stop, timeout, search limit, lost or invalid feedback) stop
//!   the axis at Home Deceleration with the overrides still in force, release
//!   if needed, then restore. A drive fault or shutdown cannot be stopped by
//!   us: the drive is disabled and the overrides restored at once.

use crate::codes::*;
use crate::config::*;
use crate::io::*;
use crate::position::{ahead_cyclic, nearest_cyclic, wrap};
use crate::profile::{reaches_without_reversing, stopping_distance, Profile};
use crate::status::{Phase, Status};
use crate::validate::{effective_search_limit, validate, ConfigError};

/// A validated feedback sample.
#[derive(Clone, Copy, Debug)]
struct Sample {
    fb: Feedback,
    /// Logical switch state: actuated, whatever the wiring.
    switch_active: bool,
}

/// What a search leg is looking for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Goal {
    /// Switch goes from released to actuated.
    SwitchDetect,
    /// Switch seen actuated in this leg, then released.
    SwitchClear,
    /// `SwitchClear`, then the first marker beyond the clear point.
    SwitchClearThenMarker,
    /// `SwitchDetect`, then the first marker beyond the detect point.
    SwitchDetectThenMarker,
    /// The first marker.
    Marker,
    /// Torque at or over the threshold for the torque time.
    Torque,
}

#[derive(Clone, Copy, Debug)]
struct Search {
    goal: Goal,
    /// Command position where the leg began: origin of the search limit.
    start: f64,
    seen_active: bool,
    /// Raw position of the switch edge, once passed (`*ThenMarker`).
    edge: Option<f64>,
    /// Time the torque first reached the threshold in the current run.
    over_since: Option<u64>,
}

impl Search {
    fn new(goal: Goal, start: f64) -> Self {
        Self {
            goal,
            start,
            seen_active: false,
            edge: None,
            over_since: None,
        }
    }
}

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
    status: Status,
    prev_request: Request,
    phase: Phase,
    profile: Profile,
    enable: bool,
    /// Torque limits and error tolerances overridden (torque sequences).
    overrides: bool,
    marker_id: u8,
    switch_id: u8,
    switch_edge: Edge,
    last_id: u8,
    search: Search,
    /// Last two valid samples (`last` is the newest).
    prev: Option<Sample>,
    last: Option<Sample>,
    stale: u32,
    /// axis position = raw + offset (wrapped on a cyclic axis).
    offset: f64,
    /// Raw position where the hard stop was found (torque sequences).
    torque_point: f64,
    /// PC value for a sequence that ends when the current stop ends.
    pc_on_rest: bool,
    /// Stopping: the release back onto the actual position has been planned.
    released: bool,
    /// A marker was found at speed by a drive without a latch: creep back
    /// over it once the current stop ends. Holds its approximate position.
    creep_to: Option<f64>,
    enabling_since: u64,
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
            cfg,
            status: Status::default(),
            prev_request: Request::default(),
            phase: Phase::Idle,
            profile: Profile::hold(0, 0.0),
            enable: false,
            overrides: false,
            marker_id: 0,
            switch_id: 0,
            switch_edge: Edge::Rising,
            last_id: 0,
            search: Search::new(Goal::Marker, 0.0),
            prev: None,
            last: None,
            stale: 0,
            offset: 0.0,
            torque_point: 0.0,
            pc_on_rest: false,
            released: false,
            creep_to: None,
            enabling_since: 0,
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
    pub fn step(&mut self, now_ns: u64, feedback: Option<&Feedback>, request: &Request) -> Command {
        let fresh = self.intake(now_ns, feedback);
        self.requests(now_ns, request);
        match fresh {
            Some(s) => self.advance(now_ns, &s),
            None => self.advance_blind(now_ns),
        }
        self.status.phase = self.phase;
        self.status.stopping = self.phase == Phase::Stopping;
        self.output(now_ns)
    }

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
    /// samples from before are forgotten, and homing in process is aborted
    /// with ERR 12 / EXERR 40 — the feedback it relied on was interrupted.
    pub fn reconnected(&mut self, now_ns: u64) {
        self.prev = None;
        self.last = None;
        self.status.homed = false;
        if self.status.ip {
            self.fail(
                now_ns,
                ERR_SERVO_MESSAGE,
                EX_FEEDBACK_LOST,
                Abort::Controlled,
            );
        }
    }

    // ------------------------------------------------------------------
    // Inputs
    // ------------------------------------------------------------------

    fn intake(&mut self, now: u64, feedback: Option<&Feedback>) -> Option<Sample> {
        if self.cfg.configuration == AxisConfiguration::Virtual {
            // No hardware: the command is the position.
            let (p, v) = self.profile.sample(now);
            let fb = Feedback {
                position: p,
                velocity: v,
                drive: DriveState {
                    enabled: true,
                    fault: false,
                },
                ..Feedback::default()
            };
            return Some(self.accept(fb));
        }
        match feedback {
            None => {
                self.missing(now);
                None
            }
            Some(fb) => match check_feedback(fb, self.cfg.max_position) {
                Ok(()) => Some(self.accept(*fb)),
                Err(attribute) => {
                    self.status.bad_attribute = Some(attribute);
                    // Corrupt feedback: the reference can no longer be trusted.
                    self.status.homed = false;
                    if self.status.ip {
                        self.fail(
                            now,
                            ERR_SERVO_MESSAGE,
                            EX_FEEDBACK_INVALID,
                            Abort::Controlled,
                        );
                    }
                    self.missing(now);
                    None
                }
            },
        }
    }

    fn accept(&mut self, fb: Feedback) -> Sample {
        let s = Sample {
            fb,
            switch_active: fb.home_switch != self.cfg.home_switch_normally_closed,
        };
        self.stale = 0;
        self.status.feedback_ok = true;
        self.prev = self.last;
        self.last = Some(s);
        s
    }

    fn missing(&mut self, now: u64) {
        self.stale = self.stale.saturating_add(1);
        if self.stale > self.cfg.stale_limit {
            self.status.feedback_ok = false;
            self.status.homed = false;
            // Edges across a gap of unknown length mean nothing.
            self.prev = None;
            self.last = None;
            if self.status.ip {
                self.fail(now, ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST, Abort::Controlled);
            }
        }
    }

    fn requests(&mut self, now: u64, req: &Request) {
        let prev = self.prev_request;
        self.prev_request = *req;
        if req.shutdown {
            if self.status.ip {
                self.fail(now, ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN, Abort::Disable);
            }
            self.enable = false;
            self.status.homed = false;
        }
        if req.stop && !prev.stop && self.status.ip {
            self.fail(
                now,
                ERR_SERVO_MESSAGE,
                EX_TERMINATED_ON_REQUEST,
                Abort::Controlled,
            );
        }
        if req.home && !prev.home {
            self.start(now, req.shutdown);
        }
        if !req.home && (self.status.dn || self.status.er) {
            self.status.en = false;
        }
    }

    // ------------------------------------------------------------------
    // Start
    // ------------------------------------------------------------------

    fn start(&mut self, now: u64, shutdown: bool) {
        if self.status.ip {
            // Re-triggering a running instruction changes nothing.
            return;
        }
        self.status = Status {
            en: true,
            homed: self.status.homed,
            feedback_ok: self.status.feedback_ok,
            started_ns: now,
            ..Status::default()
        };
        if let Some(exerr) = self.config_error {
            return self.fail(now, ERR_ILLEGAL_HOMING_CONFIG, exerr, Abort::Controlled);
        }
        if shutdown {
            return self.fail(now, ERR_SERVO_MESSAGE, EX_AXIS_SHUTDOWN, Abort::Controlled);
        }
        let Some(s) = self.last else {
            return self.fail(now, ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST, Abort::Controlled);
        };
        self.status.ip = true;
        self.status.homing = true;
        self.status.homed = false;
        self.creep_to = None;

        if self.cfg.home_sequence == HomeSequence::Immediate {
            // Actual and command position become Home Position: nothing moves,
            // the reference is redefined. Home Offset does not apply.
            self.offset = self.cfg.home_position - s.fb.position;
            return self.complete(now, true);
        }
        match self.cfg.home_mode {
            HomeMode::Passive => self.begin(now, &s),
            HomeMode::Active => {
                self.enable = true;
                if s.fb.drive.enabled && !s.fb.drive.fault {
                    self.begin(now, &s);
                } else {
                    self.phase = Phase::Enabling;
                    self.enabling_since = now;
                }
            }
        }
    }

    /// First step of the configured sequence, with the drive ready.
    fn begin(&mut self, now: u64, s: &Sample) {
        let seq = self.cfg.home_sequence;
        if self.cfg.home_mode == HomeMode::Passive {
            let goal = match seq {
                HomeSequence::Switch => Goal::SwitchDetect,
                HomeSequence::SwitchThenMarker => Goal::SwitchDetectThenMarker,
                _ => Goal::Marker,
            };
            self.phase = Phase::Passive;
            self.begin_search(goal, s.fb.position);
            return;
        }
        if seq.uses_torque() {
            self.overrides = true;
        }
        let unidirectional = self.cfg.home_direction.is_unidirectional();
        if seq.uses_switch() && s.switch_active {
            if unidirectional {
                // Establish the event where we stand, then go on if the
                // unidirectional constraint allows.
                self.event(s.fb.position);
                self.unidirectional_after_event(now);
            } else {
                // Already on the switch: start with the return leg.
                let goal = if seq == HomeSequence::Switch {
                    Goal::SwitchClear
                } else {
                    Goal::SwitchClearThenMarker
                };
                self.start_return(now, goal, s);
            }
            return;
        }
        let goal = match seq {
            HomeSequence::Switch if unidirectional => Goal::SwitchDetect,
            HomeSequence::SwitchThenMarker if unidirectional => Goal::SwitchDetectThenMarker,
            HomeSequence::Switch | HomeSequence::SwitchThenMarker => Goal::SwitchDetect,
            HomeSequence::Marker => Goal::Marker,
            _ => Goal::Torque,
        };
        let (p, v) = self.profile.sample(now);
        self.begin_search(goal, p);
        self.profile = Profile::jog(
            now,
            p,
            v,
            self.dir * self.cfg.home_speed,
            self.cfg.home_acceleration,
            self.cfg.home_deceleration,
        );
        self.phase = Phase::Seek;
    }

    fn begin_search(&mut self, goal: Goal, start: f64) {
        self.search = Search::new(goal, start);
        if matches!(
            goal,
            Goal::Marker | Goal::SwitchClearThenMarker | Goal::SwitchDetectThenMarker
        ) {
            self.arm_marker();
        }
        if matches!(goal, Goal::SwitchDetect | Goal::SwitchDetectThenMarker) {
            self.arm_switch(true);
        }
    }

    fn start_return(&mut self, now: u64, goal: Goal, s: &Sample) {
        let (p, v) = self.profile.sample(now);
        self.begin_search(goal, p);
        if goal != Goal::Marker && s.switch_active {
            self.search.seen_active = true;
            self.arm_switch(false);
        }
        self.profile = Profile::jog(
            now,
            p,
            v,
            -self.dir * self.cfg.home_return_speed,
            self.cfg.home_acceleration,
            self.cfg.home_deceleration,
        );
        self.phase = Phase::Return;
    }

    // ------------------------------------------------------------------
    // Per-cycle progress
    // ------------------------------------------------------------------

    fn advance(&mut self, now: u64, s: &Sample) {
        let moving_phase = matches!(
            self.phase,
            Phase::Seek
                | Phase::SeekStop
                | Phase::Release
                | Phase::Return
                | Phase::ReturnStop
                | Phase::MoveHome
                | Phase::Creep
        );
        if !moving_phase && self.phase != Phase::Stopping && !s.fb.drive.enabled {
            // Nobody holds the axis: follow it, so enabling never jumps.
            self.profile = Profile::hold(now, s.fb.position);
        }
        if self.phase == Phase::Idle && s.fb.drive.fault {
            self.enable = false;
        }
        if moving_phase {
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
            let v = self.profile.sample(now).1;
            if (v > 0.0 && s.fb.overtravel_positive) || (v < 0.0 && s.fb.overtravel_negative) {
                return self.fail(now, ERR_SERVO_MESSAGE, EX_OVERTRAVEL, Abort::Controlled);
            }
        }
        if self.check_timeout(now) {
            return;
        }
        if matches!(self.phase, Phase::Seek | Phase::Return | Phase::Creep) {
            let p = self.profile.sample(now).0;
            if (p - self.search.start).abs() > self.search_limit {
                let leg = self.phase as u16;
                return self.fail(now, ERR_SEARCH_LIMIT, leg, Abort::Controlled);
            }
        }
        let done = self.profile.is_done(now);
        match self.phase {
            Phase::Idle => {}
            Phase::Enabling => {
                if s.fb.drive.enabled && !s.fb.drive.fault {
                    self.begin(now, s);
                } else if s.fb.drive.fault && self.enable {
                    // Fault reset: enable must go low before it goes high again.
                    self.enable = false;
                } else if now.saturating_sub(self.enabling_since)
                    > secs_to_ns(self.cfg.enable_timeout)
                {
                    self.fail(now, ERR_SERVO_MESSAGE, EX_ENABLE_TIMEOUT, Abort::Controlled);
                } else {
                    self.enable = true;
                }
            }
            Phase::Seek => {
                if let Some(at) = self.detect(now, s) {
                    self.on_seek_event(now, at);
                }
            }
            Phase::SeekStop | Phase::ReturnStop if done && self.creep_to.is_some() => {
                self.start_creep(now)
            }
            Phase::SeekStop if done => self.on_seek_stopped(now, s),
            Phase::Release if done => self.on_released(now, s),
            Phase::Return => {
                if let Some(at) = self.detect(now, s) {
                    if self.search.goal != Goal::SwitchClear && self.creeps() {
                        self.creep_to = Some(at);
                    } else {
                        self.event(at);
                    }
                    self.stop_into(now, Phase::ReturnStop);
                }
            }
            Phase::Creep => {
                if let Some(at) = self.detect(now, s) {
                    self.event(at);
                    self.stop_into(now, Phase::ReturnStop);
                }
            }
            Phase::ReturnStop if done => {
                if self.cfg.home_sequence == HomeSequence::TorqueThenMarker {
                    // Torque then marker restores before the move (seed text).
                    self.overrides = false;
                }
                self.move_home_or_finish(now);
            }
            Phase::MoveHome if done => self.complete(now, true),
            Phase::Passive => {
                if let Some(at) = self.detect(now, s) {
                    self.event(at);
                    self.complete(now, true);
                }
            }
            Phase::Stopping if done => {
                if self.overrides && !self.released {
                    self.released = true;
                    self.profile = self.release_profile(now, s.fb.position);
                } else {
                    self.overrides = false;
                    self.phase = Phase::Idle;
                }
            }
            _ => {}
        }
    }

    /// A cycle without valid feedback: profiles run on, nothing is detected.
    /// An abort's stop still finishes; a release (which needs the actual
    /// position) waits for feedback, keeping the reduced torque limits.
    fn advance_blind(&mut self, now: u64) {
        self.check_timeout(now);
        if self.phase == Phase::Stopping && !self.overrides && self.profile.is_done(now) {
            self.phase = Phase::Idle;
        }
    }

    fn check_timeout(&mut self, now: u64) -> bool {
        let t = self.cfg.home_timeout;
        if self.status.ip && t > 0.0 && now.saturating_sub(self.status.started_ns) > secs_to_ns(t) {
            self.fail(now, ERR_TIMEOUT, 0, Abort::Controlled);
            return true;
        }
        false
    }

    /// Looks for the current search goal in this sample; returns the raw
    /// position of the event when found.
    fn detect(&mut self, now: u64, s: &Sample) -> Option<f64> {
        let (was_active, prev_pos) = match self.prev {
            Some(p) => (p.switch_active, p.fb.position),
            None => (s.switch_active, s.fb.position),
        };
        let detected = !was_active && s.switch_active;
        let cleared = was_active && !s.switch_active;
        match self.search.goal {
            Goal::SwitchDetect => detected.then(|| self.edge_position(prev_pos, s)),
            Goal::SwitchClear | Goal::SwitchClearThenMarker => {
                if !self.search.seen_active {
                    if s.switch_active {
                        self.search.seen_active = true;
                        self.arm_switch(false);
                    }
                } else if cleared && self.search.edge.is_none() {
                    let at = self.edge_position(prev_pos, s);
                    if self.search.goal == Goal::SwitchClear {
                        return Some(at);
                    }
                    self.search.edge = Some(at);
                }
                self.marker_after_edge(prev_pos, s)
            }
            Goal::SwitchDetectThenMarker => {
                if detected && self.search.edge.is_none() {
                    self.search.edge = Some(self.edge_position(prev_pos, s));
                }
                self.marker_after_edge(prev_pos, s)
            }
            Goal::Marker => self.marker_seen(prev_pos, s),
            Goal::Torque => {
                if s.fb.torque * self.dir >= self.cfg.home_torque_threshold {
                    let since = *self.search.over_since.get_or_insert(now);
                    if now - since >= secs_to_ns(self.cfg.home_torque_time) {
                        return Some(s.fb.position);
                    }
                } else {
                    self.search.over_since = None;
                }
                None
            }
        }
    }

    /// The latched marker if it lies beyond the switch edge in the direction
    /// the axis went; an earlier one is rejected and the latch re-armed.
    fn marker_after_edge(&mut self, prev_pos: f64, s: &Sample) -> Option<f64> {
        let m = self.marker_seen(prev_pos, s)?;
        match self.search.edge {
            Some(e) if (m - e) * (s.fb.position - e) >= 0.0 => Some(m),
            _ => {
                self.arm_marker();
                None
            }
        }
    }

    /// The marker, if one was passed: the latched position, or for a drive
    /// without a latch the midpoint of the samples around the index pulse.
    fn marker_seen(&self, prev_pos: f64, s: &Sample) -> Option<f64> {
        if !self.cfg.marker_latch {
            return s
                .fb
                .marker_pulse
                .then_some(0.5 * (prev_pos + s.fb.position));
        }
        let l = s.fb.marker_latch;
        (self.marker_id != 0 && l.id == self.marker_id && l.latched).then_some(l.position)
    }

    /// A marker found at speed is refined by a creep leg (no latch, a creep
    /// speed, a bidirectional active sequence: creeping back reverses).
    fn creeps(&self) -> bool {
        !self.cfg.marker_latch
            && self.cfg.home_creep_speed > 0.0
            && self.cfg.home_mode == HomeMode::Active
            && !self.cfg.home_direction.is_unidirectional()
    }

    /// At rest just past a marker found at speed: creep back over it.
    fn start_creep(&mut self, now: u64) {
        let Some(target) = self.creep_to.take() else {
            return;
        };
        let (p, v) = self.profile.sample(now);
        let dir = if target >= p { 1.0 } else { -1.0 };
        self.begin_search(Goal::Marker, p);
        self.profile = Profile::jog(
            now,
            p,
            v,
            dir * self.cfg.home_creep_speed,
            self.cfg.home_acceleration,
            self.cfg.home_deceleration,
        );
        self.phase = Phase::Creep;
    }

    /// Switch edge position: the registration latch where the drive has one,
    /// else the midpoint of the samples around the edge.
    fn edge_position(&self, prev_pos: f64, s: &Sample) -> f64 {
        let l = s.fb.switch_latch;
        if self.cfg.registration && self.switch_id != 0 && l.id == self.switch_id && l.latched {
            l.position
        } else {
            0.5 * (prev_pos + s.fb.position)
        }
    }

    // ------------------------------------------------------------------
    // Transitions
    // ------------------------------------------------------------------

    /// The home event at raw position `e`: redefine the axis position so the
    /// event point reads Home Position − Home Offset (spec §3).
    fn event(&mut self, e: f64) {
        self.status.event_raw = Some(e);
        self.offset = self.cfg.home_position - self.cfg.home_offset - e;
        self.marker_id = 0;
        self.switch_id = 0;
    }

    fn on_seek_event(&mut self, now: u64, at: f64) {
        let seq = self.cfg.home_sequence;
        if self.cfg.home_direction.is_unidirectional() && !seq.uses_torque() {
            self.event(at);
            return self.unidirectional_after_event(now);
        }
        match seq {
            HomeSequence::Marker if self.creeps() => self.creep_to = Some(at),
            HomeSequence::Marker => self.event(at),
            HomeSequence::Torque => {
                self.torque_point = at;
                self.event(at);
            }
            HomeSequence::TorqueThenMarker => self.torque_point = at,
            _ => {} // switch detected: the event comes on the return leg
        }
        self.stop_into(now, Phase::SeekStop);
    }

    fn on_seek_stopped(&mut self, now: u64, s: &Sample) {
        let seq = self.cfg.home_sequence;
        if self.cfg.home_direction.is_unidirectional() && !seq.uses_torque() {
            let pc = self.pc_on_rest;
            return self.complete(now, pc);
        }
        match seq {
            HomeSequence::Switch => self.start_return(now, Goal::SwitchClear, s),
            HomeSequence::SwitchThenMarker => {
                self.start_return(now, Goal::SwitchClearThenMarker, s)
            }
            HomeSequence::Marker => self.move_home_or_finish(now),
            _ => {
                self.profile = self.release_profile(now, s.fb.position);
                self.phase = Phase::Release;
            }
        }
    }

    fn on_released(&mut self, now: u64, s: &Sample) {
        if self.cfg.home_sequence == HomeSequence::TorqueThenMarker {
            self.start_return(now, Goal::Marker, s);
        } else {
            self.move_home_or_finish(now);
        }
    }

    /// After the event on a unidirectional sequence: keep going to Home
    /// Position at Home Speed if that needs no reversal, else stop there
    /// (linear: PC only with a zero offset). A cyclic axis adds whole
    /// revolutions, so it always gets there.
    fn unidirectional_after_event(&mut self, now: u64) {
        let (p, v) = self.profile.sample(now);
        let base = self.status.event_raw.unwrap_or(p) + self.cfg.home_offset;
        let target = if self.cfg.travel == TravelMode::Cyclic {
            let d = stopping_distance(v, self.cfg.home_deceleration);
            ahead_cyclic(base, p, self.dir, d, self.cfg.unwind)
        } else {
            base
        };
        let forward = (target - p) * self.dir >= 0.0;
        if forward && reaches_without_reversing(p, v, target, self.cfg.home_deceleration) {
            self.profile = Profile::move_to(
                now,
                p,
                v,
                target,
                self.cfg.home_speed,
                self.cfg.home_acceleration,
                self.cfg.home_deceleration,
            );
            self.phase = Phase::MoveHome;
        } else {
            self.pc_on_rest = self.cfg.home_offset == 0.0;
            self.stop_into(now, Phase::SeekStop);
        }
    }

    /// At rest after the event of a bidirectional sequence: move to Home
    /// Position at Home Return Speed (the shortest way on a cyclic axis),
    /// unless that lies beyond the hard stop of a torque sequence.
    fn move_home_or_finish(&mut self, now: u64) {
        let (p, v) = self.profile.sample(now);
        let base = self.status.event_raw.unwrap_or(p) + self.cfg.home_offset;
        let target = if self.cfg.travel == TravelMode::Cyclic {
            nearest_cyclic(base, p, self.cfg.unwind)
        } else {
            base
        };
        if self.cfg.home_sequence.uses_torque() && (target - self.torque_point) * self.dir > 0.0 {
            // Home Position inside the hard stop: stay; homed, not at HP.
            return self.complete(now, false);
        }
        self.profile = Profile::move_to(
            now,
            p,
            v,
            target,
            self.cfg.home_return_speed,
            self.cfg.home_acceleration,
            self.cfg.home_deceleration,
        );
        self.phase = Phase::MoveHome;
    }

    fn stop_into(&mut self, now: u64, phase: Phase) {
        let (p, v) = self.profile.sample(now);
        self.profile = Profile::stop(now, p, v, self.cfg.home_deceleration);
        self.phase = phase;
    }

    /// Command back onto the actual position at return speed.
    fn release_profile(&self, now: u64, actual: f64) -> Profile {
        let (p, v) = self.profile.sample(now);
        let speed = if self.cfg.home_return_speed > 0.0 {
            self.cfg.home_return_speed
        } else {
            self.cfg.home_speed
        };
        if speed > 0.0 && self.cfg.home_acceleration > 0.0 && self.cfg.home_deceleration > 0.0 {
            Profile::move_to(
                now,
                p,
                v,
                actual,
                speed,
                self.cfg.home_acceleration,
                self.cfg.home_deceleration,
            )
        } else {
            Profile::hold(now, actual)
        }
    }

    fn complete(&mut self, now: u64, pc: bool) {
        self.status.ip = false;
        self.status.dn = true;
        self.status.pc = pc;
        self.status.homing = false;
        self.status.homed = true;
        self.status.finished_ns = Some(now);
        self.overrides = false;
        self.marker_id = 0;
        self.switch_id = 0;
        self.phase = Phase::Idle;
    }

    fn fail(&mut self, now: u64, err: u16, exerr: u16, how: Abort) {
        self.status.er = true;
        self.status.pc = false;
        self.status.err = err;
        self.status.exerr = exerr;
        self.marker_id = 0;
        self.switch_id = 0;
        self.creep_to = None;
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
                let (p, v) = self.profile.sample(now);
                self.profile = Profile::stop(now, p, v, self.cfg.home_deceleration);
                self.released = false;
                self.phase = Phase::Stopping;
            }
            Abort::Disable => {
                self.enable = false;
                self.overrides = false;
                let hold = self
                    .last
                    .map_or(self.profile.sample(now).0, |s| s.fb.position);
                self.profile = Profile::hold(now, hold);
                self.phase = Phase::Idle;
            }
        }
    }

    // ------------------------------------------------------------------
    // Output
    // ------------------------------------------------------------------

    fn arm_marker(&mut self) {
        self.marker_id = self.next_id();
    }

    /// Arms the registration latch (if the drive has one) for the electrical
    /// edge of the switch being actuated (`true`) or released (`false`).
    fn arm_switch(&mut self, actuated: bool) {
        if !self.cfg.registration {
            return;
        }
        self.switch_edge = if actuated != self.cfg.home_switch_normally_closed {
            Edge::Rising
        } else {
            Edge::Falling
        };
        self.switch_id = self.next_id();
    }

    fn next_id(&mut self) -> u8 {
        self.last_id = if self.last_id == u8::MAX {
            1
        } else {
            self.last_id + 1
        };
        self.last_id
    }

    fn output(&mut self, now: u64) -> Command {
        let (mut p, mut v) = self.profile.sample(now);
        if !p.is_finite() || !v.is_finite() {
            // Unreachable by construction; never let it out if it happens.
            p = self.last_command.position;
            v = 0.0;
            self.profile = Profile::hold(now, p);
        }
        let servo = self.cfg.configuration == AxisConfiguration::Servo;
        let (torque, ptol, vtol) = if self.overrides {
            (self.cfg.home_torque_level, 0.0, 0.0)
        } else {
            (
                self.cfg.torque_limit,
                self.cfg.position_error_tolerance,
                self.cfg.velocity_error_tolerance,
            )
        };
        let cmd = Command {
            enable: self.enable && servo,
            position: p,
            velocity: v,
            torque_limit_positive: finite_or(torque, 0.0),
            torque_limit_negative: finite_or(torque, 0.0),
            position_error_tolerance: finite_or(ptol, 0.0),
            velocity_error_tolerance: finite_or(vtol, 0.0),
            marker_arm: LatchArm {
                id: self.marker_id,
                edge: Edge::Rising,
            },
            switch_arm: LatchArm {
                id: self.switch_id,
                edge: self.switch_edge,
            },
        };
        self.last_command = cmd;
        cmd
    }
}

fn finite_or(x: f64, fallback: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        fallback
    }
}

fn secs_to_ns(s: f64) -> u64 {
    if s.is_finite() && s > 0.0 {
        (s * 1e9).min(u64::MAX as f64) as u64
    } else {
        0
    }
}

/// Rejects feedback that must not reach the engine; names the attribute.
fn check_feedback(fb: &Feedback, max_position: f64) -> Result<(), &'static str> {
    let bad = |x: f64, limit: f64| !x.is_finite() || x.abs() > limit;
    if bad(fb.position, max_position) {
        return Err("feedback.position");
    }
    // A speed of more than `max_position` units per second is not a reading either.
    if bad(fb.velocity, max_position) {
        return Err("feedback.velocity");
    }
    // More than ten times rated torque is not a reading, it is a broken frame.
    if bad(fb.torque, 1000.0) {
        return Err("feedback.torque");
    }
    if fb.marker_latch.latched && bad(fb.marker_latch.position, max_position) {
        return Err("feedback.marker_latch.position");
    }
    if fb.switch_latch.latched && bad(fb.switch_latch.position, max_position) {
        return Err("feedback.switch_latch.position");
    }
    Ok(())
}
