//! One axis as the cycle keeps it, in one place: its engine, the rung of
//! its Home instruction, this cycle's feedback and command, and what the
//! status reports about it. The cycle's stages walk the slots in order; an
//! axis's data sits together in memory.
//!
//! The operations around homing (enable, reset, jog, move, the supervised
//! setpoint stream) travel in the same `Request` as the rung (`op`,
//! `setpoint`, `jog_renew`, one step each); what the cycle keeps of them
//! per axis — the jog's token, the operation id before a request — is
//! here too, and their rules are in `ops.rs`.
//!
//! The engine's command goes through the axis's cycle monitor
//! (`motion-monitor`) before it reaches the frame: the monitor passes it or
//! stops the axis itself, and the engine is told in the same step
//! (`Axis::monitor_tripped`).

use motion_frames::{axis_to_feedback, AxisFeedback, SW_DRIVE_LOST, SW_NO_DATA};
use motion_homing::{Axis, Command, Feedback, Operation, Phase, Request, Status};
use motion_monitor::{Cycle, Invariant, Monitor, Side, Trip};

use super::link::LinkCycle;
use crate::shared::{AxisSnap, LostCause};

/// The Home instruction's rung for one axis.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Rung {
    /// What the engine is given each cycle (home, stop, the coordination,
    /// and whether the cycle woke late).
    pub request: Request,
    /// Cycles until the rung goes high: 2 = drop it first (it is still
    /// high from an earlier homing), 1 = raise it now. A request is always
    /// a rising edge.
    pub pending: u8,
    /// Home requests the engine has been given (rising edges applied).
    pub homes_started: u32,
}

impl Rung {
    /// Raise the rung: in the next cycle, or in the one after when it must
    /// drop first.
    pub fn arm(&mut self) {
        self.pending = if self.request.home { 2 } else { 1 };
    }

    /// A stop (one-cycle pulse; the engine takes its rising edge) with the
    /// code it reports, if not the default 12 / 1.
    pub fn stop(&mut self, code: Option<(u16, u16)>) {
        self.request.stop = true;
        self.request.stop_code = code;
    }

    /// Moves the rung on by one cycle before the engine steps; true when it
    /// rises in this cycle (homing starts).
    fn edge(&mut self, status: &Status) -> bool {
        match self.pending {
            2 => {
                self.request.home = false;
                self.pending = 1;
                false
            }
            1 => {
                self.request.home = true;
                self.pending = 0;
                self.homes_started += 1;
                true
            }
            _ => {
                // Keep the rung true while the instruction runs; drop it after.
                if self.request.home && !status.ip && (status.dn || status.er) {
                    self.request.home = false;
                }
                false
            }
        }
    }
}

/// HomedStatus over time: set by a homing or by a stored reference, and
/// when and why it was lost after that.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Homed {
    /// HomedStatus after the last completed homing (or restore).
    pub was_homed: bool,
    pub lost_ns: Option<u64>,
    pub cause: LostCause,
    /// HomedStatus comes from a stored reference.
    pub restored: bool,
}

impl Homed {
    /// A homing started: nothing to lose yet.
    fn started(&mut self) {
        self.was_homed = false;
        self.lost_ns = None;
        self.restored = false;
    }

    /// The operator cleared HomedStatus: not lost, just gone.
    pub fn cleared(&mut self) {
        self.was_homed = false;
        self.restored = false;
    }

    /// A stored reference was applied.
    pub fn restored(&mut self) {
        self.was_homed = true;
        self.lost_ns = None;
        self.restored = true;
    }

    /// After a step: a homing that completed sets it, and its loss is noted
    /// once with its cause (the link's events of this cycle, the engine's
    /// feedback state).
    fn observe(&mut self, now_ns: u64, s: &Status, link: LinkEvents) {
        if !s.ip && s.dn && s.homed && !self.was_homed {
            self.was_homed = true;
        } else if self.was_homed && !s.homed && self.lost_ns.is_none() {
            self.lost_ns = Some(now_ns);
            self.restored = false;
            self.cause = if link.reconnected {
                LostCause::Reconnect
            } else if link.detached || !s.feedback_ok {
                LostCause::Feedback
            } else {
                LostCause::Other
            };
        }
    }
}

/// What the axis's I/O link did this cycle.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct LinkEvents {
    /// The I/O process (re)attached or restarted.
    pub reconnected: bool,
    /// The I/O process is detached.
    pub detached: bool,
    /// A new I/O process took over (its drives were off in between).
    pub restarted: bool,
}

/// Everything the cycle keeps for one axis.
#[derive(Clone, Debug)]
pub struct AxisSlot {
    pub(super) engine: Axis,
    /// Its drive's counts per unit (frame conversion).
    counts_per_unit: f64,
    /// Its I/O process.
    pub(super) io: usize,
    /// Its gantry (index), if a side of one.
    pub(super) gantry: Option<usize>,
    pub(super) rung: Rung,
    pub(super) homed: Homed,
    pub(super) link: LinkEvents,
    /// This cycle's fresh feedback (None: no fresh frame, or the drive
    /// marked the axis as without data).
    feedback: Option<Feedback>,
    /// The newest feedback the engine took (for status: switch, torque, ...).
    last_feedback: Option<Feedback>,
    /// The drive's error code from the newest frame with data.
    drive_error: u16,
    /// This cycle's command, as the monitor passed it (or its stop).
    pub(super) command: Command,
    /// The cycle monitor of the axis, and the engine's own command of this
    /// cycle (what a gantry's verdict, after every side's, stops from).
    pub(super) monitor: Monitor,
    engine_command: Command,
    /// The gantry side whose failure stopped it.
    pub(super) gantry_aborted_by: Option<u8>,
    /// The hold-to-run jog running on the axis: its token (0: none) and
    /// the engine's operation id.
    pub(super) jog_token: u64,
    pub(super) jog_op: u32,
    /// The engine's operation id before this cycle's operation was given
    /// (a new id after the step: accepted).
    pub(super) op_before: u32,
    /// `Status::faulted` after the previous step (its rising edge stops a
    /// gantry's other sides).
    pub(super) was_faulted: bool,
    /// An operator's stop (`stop`, leaving) reaches the engine in this
    /// step: for gearing, a stop of this axis as a master.
    pub(super) operator_stop: bool,
    /// In this step the axis was stopped by an operator, disabled, or began
    /// homing: a slave geared to it stops (`MasterFeed::stopped`).
    pub(super) halted: bool,
    /// It faulted in this step while geared: its master (index) stops.
    pub(super) stop_master: Option<usize>,
}

impl AxisSlot {
    pub(super) fn new(a: &motion_config::AxisEntry, gantry: Option<usize>) -> Self {
        Self {
            engine: Axis::new(a.engine),
            counts_per_unit: a.engine.counts_per_unit,
            io: a.io,
            gantry,
            rung: Rung::default(),
            homed: Homed::default(),
            link: LinkEvents::default(),
            feedback: None,
            last_feedback: None,
            drive_error: 0,
            command: Command::default(),
            monitor: Monitor::new(&a.engine),
            engine_command: Command::default(),
            gantry_aborted_by: None,
            jog_token: 0,
            jog_op: 0,
            op_before: 0,
            was_faulted: false,
            operator_stop: false,
            halted: false,
            stop_master: None,
        }
    }

    pub fn engine(&self) -> &Axis {
        &self.engine
    }

    pub fn status(&self) -> &Status {
        self.engine.status()
    }

    pub fn command(&self) -> &Command {
        &self.command
    }

    /// This cycle's frame entry of the axis (if its link took a fresh
    /// frame) and the link's events.
    pub(super) fn take_feedback(
        &mut self,
        now_ns: u64,
        c: &LinkCycle,
        detached: bool,
        entry: Option<&AxisFeedback>,
    ) {
        self.link = LinkEvents {
            reconnected: c.reconnected,
            detached,
            restarted: c.restarted,
        };
        if c.reconnected {
            self.engine.reconnected(now_ns);
        }
        // the I/O process says the axis's drive is gone (it is alive)
        if c.fresh {
            self.rung.request.drive_lost =
                entry.is_some_and(|a| a.status_word & SW_DRIVE_LOST != 0);
        }
        self.feedback = match entry {
            Some(a) if c.fresh && a.status_word & SW_NO_DATA == 0 => {
                self.drive_error = a.error_code;
                Some(axis_to_feedback(a, self.counts_per_unit))
            }
            _ => None,
        };
    }

    /// Steps the engine for this cycle: the rung moves on, `shutdown`
    /// (leaving, everything at rest) disables the drive. True when homing
    /// started in this cycle.
    pub(super) fn step(&mut self, now_ns: u64, stalled: bool, shutdown: bool) -> bool {
        let started = self.rung.edge(self.engine.status());
        self.rung.request.shutdown = shutdown;
        self.rung.request.stalled = stalled;
        let stopped = self.operator_stop
            || matches!(
                self.rung.request.op,
                Some(Operation::Stop | Operation::Disable)
            );
        let (geared, faulted) = (self.engine.gear_master(), self.status().faulted);
        let request = &self.rung.request;
        self.engine_command = (self.engine).step(now_ns, self.feedback.as_ref(), request);
        let trips = self.monitor.trips();
        self.command = self.monitor.check(&Cycle {
            now_ns,
            feedback: self.feedback.as_ref(),
            request,
            status: self.engine.status(),
            reference: self.engine.limits_offset(),
            command: &self.engine_command,
            io_restarted: self.link.restarted,
        });
        if self.monitor.trips() != trips {
            self.tell_engine(now_ns);
        }
        self.halted = stopped || started;
        self.operator_stop = false;
        self.stop_master = geared
            .filter(|_| !faulted && self.status().faulted)
            .map(usize::from);
        self.rung.request.master = None;
        // The status shows only what the engine took: a refused sample
        // (not finite, out of range, implausible) is not a reading.
        if self.feedback.is_some() && self.engine.sampled_ns() == Some(now_ns) {
            self.last_feedback = self.feedback;
        }
        // Stop is a one-cycle pulse (the engine takes its rising edge); an
        // operation, a setpoint and a renewal count in their step only.
        self.rung.request.stop = false;
        self.rung.request.stop_code = None;
        self.rung.request.op = None;
        self.rung.request.setpoint = None;
        self.rung.request.jog_renew = false;
        if started {
            self.homed.started();
        } else {
            self.homed.observe(now_ns, self.engine.status(), self.link);
        }
        started
    }

    /// The monitor tripped in this cycle: the engine learns it (ER with
    /// the monitor's ERR / EXERR, its motion ended, the power stage off).
    fn tell_engine(&mut self, now_ns: u64) {
        if let Some(t) = self.monitor.tripped() {
            self.engine.monitor_tripped(now_ns, t.code());
        }
    }

    /// This side of a gantry in this cycle, as its monitor passed it.
    pub(super) fn side(&self) -> Side {
        let s = self.engine.status();
        Side {
            position: self.command.position,
            following: self.monitor.following(),
            homing: s.ip || s.phase != Phase::Idle,
            moved: self.monitor.moved(),
        }
    }

    /// A gantry's sides moved apart: this side's monitor stops it from its
    /// command before this cycle's.
    pub(super) fn gantry_apart(&mut self, now_ns: u64, value: f64, bound: f64) {
        let trips = self.monitor.trips();
        self.command = (self.monitor).force(
            now_ns,
            &self.engine_command,
            Invariant::Gantry,
            value,
            bound,
        );
        if self.monitor.trips() != trips {
            self.tell_engine(now_ns);
        }
    }

    /// The monitor's trip in force, if any.
    pub fn trip(&self) -> Option<&Trip> {
        self.monitor.tripped()
    }

    /// This cycle's fresh feedback, as the engine got it.
    pub(super) fn feedback(&self) -> Option<&Feedback> {
        self.feedback.as_ref()
    }

    /// Writes the command into the frame's entry of the axis.
    pub(super) fn command_entry(&self) -> motion_frames::AxisCommand {
        motion_frames::command_to_axis(&self.command, self.counts_per_unit)
    }

    /// Nothing in process, nothing decelerating, the command at rest.
    pub(super) fn at_rest(&self) -> bool {
        let s = self.engine.status();
        !s.ip && s.phase == Phase::Idle && self.command.velocity == 0.0
    }

    /// The axis for the status snapshot; what the slot does not know (the
    /// sequences', gantries' and tracer's part) comes from the caller.
    pub(super) fn snap(&self) -> AxisSnap {
        let a = &self.engine;
        let c = &self.command;
        let fb = self.last_feedback;
        AxisSnap {
            status: *a.status(),
            raw: a.raw_position(),
            axis: a.axis_position(),
            velocity: fb.map_or(0.0, |f| f.velocity),
            torque: fb.map_or(0.0, |f| f.torque),
            switch: fb.is_some_and(|f| f.home_switch != a.config().home_switch_normally_closed),
            marker: fb.is_some_and(|f| f.marker_pulse || f.marker_latch.latched),
            enabled: fb.is_some_and(|f| f.drive.enabled),
            fault: fb.is_some_and(|f| f.drive.fault),
            drive_error_code: self.drive_error,
            fresh: self.feedback.is_some(),
            cmd_position: c.position,
            cmd_velocity: c.velocity,
            enable: c.enable,
            homes_started: self.rung.homes_started,
            lost_homed_ns: self.homed.lost_ns,
            lost_cause: self.homed.cause,
            offset: a.reference_offset(),
            restored: self.homed.restored && a.status().homed,
            cmd_axis: c.position.is_finite().then(|| a.to_axis(c.position)),
            monitor: self.monitor.tripped().copied(),
            monitor_trips: self.monitor.trips(),
            ..AxisSnap::default()
        }
    }
}
