//! The cycle's work without its I/O: control requests in, the newest
//! feedback frame of every I/O process in, every axis stepped, one command
//! frame per I/O process out. Kept apart from the thread, timer and ports so
//! it can be tested (and benchmarked) on its own.
//!
//! Allocation happens only in [`Core::new`]; everything per cycle works on
//! preallocated vectors and bit masks.
//!
//! * [`link`] — per I/O process: accepted frames, attached, gaps, round trip.
//! * [`sequence`] — home order and the failure of a home sequence.
//! * [`trace`] — recording one homing cycle by cycle.

pub mod gantry;
pub mod link;
pub mod sequence;
pub mod trace;

use crate::shared::{Ack, AxisAck, AxisSnap, Control, Snapshot, TraceRecord};
use gantry::GantryCoord;
use link::IoLink;
use motion_config::MachineConfig;
use motion_control::{
    REASON_ALREADY_HOMING, REASON_BUSY, REASON_EXITING, REASON_INSTRUCTION, REASON_IO_NOT_ATTACHED,
};
use motion_frames::{axis_to_feedback, command_to_axis, CommandFrame, FeedbackFrame, SW_NO_DATA};
use motion_homing::codes::{
    ERR_ILLEGAL_HOMING_CONFIG, ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST, EX_TERMINATED_ON_REQUEST,
};
use motion_homing::{Axis, Command, Feedback, Phase, Request};
use sequence::{Action, AxisView, Sequencer};
use trace::Tracer;

/// The Home instruction's rung for one axis.
#[derive(Clone, Copy, Debug, Default)]
struct Rung {
    request: Request,
    /// Cycles until the rung goes high: 2 = drop it first (it is still
    /// high from an earlier homing), 1 = raise it now. A request is always
    /// a rising edge.
    pending: u8,
    homes_started: u32,
    /// HomedStatus after the last completed homing, and when and why it was
    /// lost.
    was_homed: bool,
    lost_homed_ns: Option<u64>,
    lost_cause: u8,
    /// HomedStatus comes from a stored reference.
    restored: bool,
    /// This cycle's link events for the axis.
    reconnected: bool,
    fresh_missing: bool,
}

/// What one cycle measured, for the statistics.
#[derive(Clone, Copy, Debug, Default)]
pub struct CycleInfo {
    /// I/O processes that did not answer the previous command in time.
    pub late_replies: u32,
    /// Largest round trip of this cycle's answers, ns.
    pub roundtrip_ns: Option<u64>,
}

pub struct Core {
    axes: Vec<Axis>,
    counts_per_unit: Vec<f64>,
    /// Per axis: its I/O process.
    axis_io: Vec<usize>,
    rungs: Vec<Rung>,
    commands: Vec<Command>,
    feedback: Vec<Option<Feedback>>,
    /// The newest valid feedback per axis (for status: switch, torque, ...).
    last_fb: Vec<Option<Feedback>>,
    drive_error: Vec<u16>,
    links: Vec<IoLink>,
    seq: Sequencer,
    gantries: Vec<GantryCoord>,
    /// Per axis: its gantry (index), if a side of one.
    gantry_of: Vec<Option<usize>>,
    /// Per axis: the gantry side whose failure stopped it.
    gantry_aborted_by: Vec<Option<u8>>,
    tracer: Tracer,
    trace_out: Option<TraceRecord>,
    exiting: bool,
    cycle: u64,
    all_mask: u64,
}

impl Core {
    pub fn new(m: &MachineConfig) -> Self {
        let n = m.axes.len();
        let sup = &m.supervisor;
        let links: Vec<IoLink> = (0..m.ios.len())
            .map(|k| {
                IoLink::new(
                    m.axes_of(k),
                    sup.feedback_timeout_ns(),
                    sup.feedback_loss_drain,
                    sup.cycle_ns(),
                )
            })
            .collect();
        let orders: Vec<Option<u32>> = m.axes.iter().map(|a| a.home_order).collect();
        let together: Vec<Vec<usize>> = m.gantries.iter().map(|g| g.axes.clone()).collect();
        let seq = Sequencer::with_groups(&orders, &together);
        let cfgs: Vec<motion_homing::AxisConfig> = m.axes.iter().map(|a| a.engine).collect();
        let gantries: Vec<GantryCoord> = m
            .gantries
            .iter()
            .map(|g| GantryCoord::new(g, &cfgs, sup.cycle_ns()))
            .collect();
        Self {
            axes: m.axes.iter().map(|a| Axis::new(a.engine)).collect(),
            counts_per_unit: m.axes.iter().map(|a| a.engine.counts_per_unit).collect(),
            axis_io: m.axes.iter().map(|a| a.io).collect(),
            rungs: vec![Rung::default(); n],
            commands: vec![Command::default(); n],
            feedback: vec![None; n],
            last_fb: vec![None; n],
            drive_error: vec![0; n],
            links,
            all_mask: seq.all_mask(),
            seq,
            gantries,
            gantry_of: (0..n).map(|i| m.gantry_of(i)).collect(),
            gantry_aborted_by: vec![None; n],
            tracer: Tracer::default(),
            trace_out: None,
            exiting: false,
            cycle: 0,
        }
    }

    pub fn axis_count(&self) -> usize {
        self.axes.len()
    }

    pub fn io_count(&self) -> usize {
        self.links.len()
    }

    pub fn axes(&self) -> &[Axis] {
        &self.axes
    }

    /// The axes "home all" homes.
    pub fn all_mask(&self) -> u64 {
        self.all_mask
    }

    fn arm_rung(&mut self, i: usize) {
        let r = &mut self.rungs[i];
        r.pending = if r.request.home { 2 } else { 1 };
    }

    /// Why axis `i` cannot start homing now, if it cannot.
    fn refusal(&self, i: usize) -> Option<AxisAck> {
        let refuse = |reason, err, exerr| {
            Some(AxisAck {
                accepted: false,
                reason,
                err,
                exerr,
                restore: None,
            })
        };
        if self.exiting {
            return refuse(REASON_EXITING, 0, 0);
        }
        if self.axes[i].status().ip || self.rungs[i].pending > 0 {
            return refuse(REASON_ALREADY_HOMING, 0, 0);
        }
        if self.seq.busy() & (1 << i) != 0 {
            return refuse(REASON_BUSY, 0, 0);
        }
        if let Some(exerr) = self.axes[i].config_error() {
            return refuse(REASON_INSTRUCTION, ERR_ILLEGAL_HOMING_CONFIG, exerr);
        }
        if !self.links[self.axis_io[i]].attached() {
            return refuse(REASON_IO_NOT_ATTACHED, 0, 0);
        }
        None
    }

    /// Applies one control request; requests with an id are answered.
    pub fn control(&mut self, c: Control, now_ns: u64) -> Option<Ack> {
        let mut ack = self.apply(c, now_ns);
        if let Some(a) = ack.as_mut() {
            // Takes effect in the next step.
            a.cycle = self.cycle + 1;
        }
        ack
    }

    fn apply(&mut self, c: Control, now_ns: u64) -> Option<Ack> {
        let n = self.axes.len();
        match c {
            Control::Home {
                id,
                mask,
                parallel,
                timeout_ns,
            } => {
                let mut ack = Ack::new(id);
                let mut accepted = 0u64;
                for i in 0..n {
                    if mask & (1 << i) == 0 {
                        continue;
                    }
                    match self.refusal(i) {
                        Some(r) => ack.axes[i] = r,
                        None => {
                            ack.axes[i].accepted = true;
                            accepted |= 1 << i;
                        }
                    }
                }
                // Nothing starts unless every named axis can: a sequence
                // with holes would home the machine in the wrong order.
                let all_ok = (0..n).all(|i| mask & (1 << i) == 0 || ack.axes[i].accepted);
                if all_ok && accepted != 0 {
                    let deadline = if timeout_ns > 0 {
                        now_ns.saturating_add(timeout_ns)
                    } else {
                        0
                    };
                    if !self.seq.begin(accepted, parallel, deadline) {
                        for i in 0..n {
                            if accepted & (1 << i) != 0 {
                                ack.axes[i] = AxisAck {
                                    reason: REASON_BUSY,
                                    ..AxisAck::default()
                                };
                            }
                        }
                    }
                } else {
                    for a in ack.axes.iter_mut() {
                        a.accepted = false;
                    }
                }
                Some(ack)
            }
            Control::Stop { id, mask } => {
                let mut ack = Ack::new(id);
                for i in 0..n {
                    if mask & (1 << i) != 0 {
                        self.rungs[i].request.stop = true;
                        self.rungs[i].pending = 0;
                        ack.axes[i].accepted = true;
                    }
                }
                Some(ack)
            }
            Control::Unhome { id, mask } => {
                let mut ack = Ack::new(id);
                for i in 0..n {
                    if mask & (1 << i) != 0 {
                        ack.axes[i] = if self.rungs[i].pending == 0 && self.axes[i].clear_homed() {
                            self.rungs[i].was_homed = false;
                            self.rungs[i].restored = false;
                            AxisAck {
                                accepted: true,
                                ..AxisAck::default()
                            }
                        } else {
                            AxisAck {
                                accepted: false,
                                reason: REASON_ALREADY_HOMING,
                                ..AxisAck::default()
                            }
                        };
                    }
                }
                Some(ack)
            }
            Control::Trace { id, axis } => {
                let mut ack = Ack::new(id);
                if axis < n {
                    self.tracer.arm(axis);
                    ack.axes[axis].accepted = true;
                }
                Some(ack)
            }
            Control::Restore { id, axis, offset } => {
                let mut ack = Ack::new(id);
                if axis < n {
                    let r = if self.exiting {
                        Err(REASON_EXITING)
                    } else if self.rungs[axis].pending > 0 || self.seq.busy() & (1 << axis) != 0 {
                        Err(REASON_BUSY)
                    } else {
                        Ok(())
                    };
                    ack.axes[axis] =
                        match r.map(|()| self.axes[axis].restore_reference(now_ns, offset)) {
                            Ok(Ok(())) => {
                                let rung = &mut self.rungs[axis];
                                rung.was_homed = true;
                                rung.lost_homed_ns = None;
                                rung.restored = true;
                                AxisAck {
                                    accepted: true,
                                    ..AxisAck::default()
                                }
                            }
                            Ok(Err(why)) => AxisAck {
                                restore: Some(why),
                                ..AxisAck::default()
                            },
                            Err(reason) => AxisAck {
                                reason,
                                ..AxisAck::default()
                            },
                        };
                }
                Some(ack)
            }
            Control::Exit => {
                self.exiting = true;
                for r in &mut self.rungs {
                    r.pending = 0;
                    r.request.home = false;
                    r.request.stop = true;
                }
                None
            }
        }
    }

    /// The link of I/O process `k` refused a frame (layout, key).
    pub fn note_refused(&mut self, k: usize) {
        if let Some(l) = self.links.get_mut(k) {
            l.refused();
        }
    }

    /// One cycle: `frames[k]` is the newest frame received from I/O process
    /// `k` this cycle, if any. `stalled`: the thread woke late for this
    /// cycle (its CPU was taken away); a missing answer is then the
    /// machine's stall more likely than the peer's silence, and the
    /// feedback-loss rules excuse it within a bound.
    pub fn step(
        &mut self,
        now_ns: u64,
        stalled: bool,
        frames: &[Option<&FeedbackFrame>],
    ) -> CycleInfo {
        self.cycle += 1;
        let mut info = CycleInfo::default();
        let n = self.axes.len();
        for (k, link) in self.links.iter_mut().enumerate() {
            let frame = frames.get(k).copied().flatten();
            let c = link.step(now_ns, frame, stalled);
            if link.attached() && !c.answered_previous {
                info.late_replies += 1;
            }
            if let Some(rt) = c.roundtrip_ns {
                info.roundtrip_ns = Some(info.roundtrip_ns.map_or(rt, |m: u64| m.max(rt)));
            }
            let detached = !link.attached();
            for (j, &i) in link.axes.iter().enumerate() {
                self.rungs[i].reconnected = c.reconnected;
                self.rungs[i].fresh_missing = detached;
                if c.reconnected {
                    self.axes[i].reconnected(now_ns);
                }
                self.feedback[i] = frame
                    .filter(|_| c.fresh)
                    .map(|f| &f.axes[j])
                    .filter(|a| a.status_word & SW_NO_DATA == 0)
                    .map(|a| {
                        self.drive_error[i] = a.error_code;
                        axis_to_feedback(a, self.counts_per_unit[i])
                    });
            }
        }

        // Home sequences: who starts, who is stopped.
        let axes = &self.axes;
        let rungs = &self.rungs;
        let links = &self.links;
        let axis_io = &self.axis_io;
        let mut starts = 0u64;
        let mut stops = 0u64;
        self.seq.step(
            now_ns,
            |i| {
                let s = axes[i].status();
                AxisView {
                    running: rungs[i].pending > 0 || s.ip || s.stopping,
                    failed: s.er,
                    io_lost: s.er
                        && (s.err, s.exerr) == (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST)
                        && !links[axis_io[i]].attached(),
                }
            },
            |a| match a {
                Action::Start(i) => starts |= 1 << i,
                Action::Stop(i) => stops |= 1 << i,
            },
        );
        for i in 0..n {
            if starts & (1 << i) != 0 && !self.exiting {
                self.arm_rung(i);
                self.gantry_aborted_by[i] = None;
            }
            if stops & (1 << i) != 0 {
                self.rungs[i].request.stop = true;
                self.rungs[i].request.stop_code =
                    Some((ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST));
            }
        }
        // Gantries: the barrier per phase, the final moves, skew, one side
        // failing stops all (decided on the previous step's state).
        for g in &mut self.gantries {
            let d = g.step(&self.axes, &self.commands);
            for (j, &i) in g.sides().iter().enumerate() {
                let r = &mut self.rungs[i].request;
                r.hold = d.hold;
                r.move_duration_ns = d.move_duration_ns;
                if let Some(code) = d.stop[j] {
                    r.stop = true;
                    r.stop_code = Some(code);
                    if let Some(f) = d.failed_side {
                        self.gantry_aborted_by[i] = Some(f as u8);
                    }
                }
            }
        }

        let at_rest = self.exiting && self.all_at_rest();
        self.trace_out = None;
        for i in 0..n {
            let rung = &mut self.rungs[i];
            let mut started = false;
            match rung.pending {
                2 => {
                    rung.request.home = false;
                    rung.pending = 1;
                }
                1 => {
                    rung.request.home = true;
                    rung.pending = 0;
                    rung.homes_started += 1;
                    started = true;
                }
                _ => {
                    if rung.request.home {
                        // Keep the rung true while the instruction runs; drop it after.
                        let s = self.axes[i].status();
                        if !s.ip && (s.dn || s.er) {
                            rung.request.home = false;
                        }
                    }
                }
            }
            // Leaving: once everything is at rest, disable the drives.
            rung.request.shutdown = at_rest;
            let req = Request {
                stalled,
                ..rung.request
            };
            let fb = self.feedback[i];
            self.commands[i] = self.axes[i].step(now_ns, fb.as_ref(), &req);
            // The status shows only what the engine took: a refused sample
            // (not finite, out of range, implausible) is not a reading.
            if fb.is_some() && self.axes[i].sampled_ns() == Some(now_ns) {
                self.last_fb[i] = fb;
            }
            // Stop is a one-cycle pulse (the engine takes its rising edge).
            self.rungs[i].request.stop = false;
            self.rungs[i].request.stop_code = None;
            let s = self.axes[i].status();
            let rung = &mut self.rungs[i];
            if started {
                rung.was_homed = false;
                rung.lost_homed_ns = None;
                rung.restored = false;
            } else if !s.ip && s.dn && s.homed && !rung.was_homed {
                rung.was_homed = true;
            } else if rung.was_homed && !s.homed && rung.lost_homed_ns.is_none() {
                rung.lost_homed_ns = Some(now_ns);
                rung.restored = false;
                rung.lost_cause = if rung.reconnected {
                    motion_control::SX_LOST_RECONNECT
                } else if rung.fresh_missing || !s.feedback_ok {
                    motion_control::SX_LOST_FEEDBACK
                } else {
                    0
                };
            }
            if let Some(r) = self.tracer.record(
                now_ns,
                i,
                &self.axes[i],
                &self.commands[i],
                fb.as_ref(),
                started,
            ) {
                self.trace_out = Some(r);
            }
        }
        info
    }

    /// This cycle's trace record, if an armed trace is recording.
    pub fn trace_record(&self) -> Option<TraceRecord> {
        self.trace_out
    }

    /// Writes the cycle's commands of I/O process `k` into its frame.
    pub fn fill(&self, k: usize, frame: &mut CommandFrame) {
        let axes = &self.links[k].axes;
        frame.header.axis_count = axes.len() as u32;
        for (j, &i) in axes.iter().enumerate() {
            frame.axes[j] = command_to_axis(&self.commands[i], self.counts_per_unit[i]);
        }
    }

    /// The command frame of I/O process `k` with this sequence number was
    /// published at `now_ns`.
    pub fn sent(&mut self, k: usize, sequence: u64, now_ns: u64) {
        self.links[k].sent(sequence, now_ns);
    }

    pub fn exiting(&self) -> bool {
        self.exiting
    }

    /// Every I/O process attached.
    pub fn all_attached(&self) -> bool {
        self.links.iter().all(IoLink::attached)
    }

    /// Nothing in process, nothing decelerating, every command at rest.
    pub fn all_at_rest(&self) -> bool {
        self.axes.iter().zip(&self.commands).all(|(a, c)| {
            let s = a.status();
            !s.ip && s.phase == Phase::Idle && c.velocity == 0.0
        })
    }

    /// Leaving is complete: at rest and the drives told to disable.
    pub fn exit_done(&self) -> bool {
        self.exiting && self.all_at_rest() && self.commands.iter().all(|c| !c.enable)
    }

    pub fn snapshot(&self, now_ns: u64, s: &mut Snapshot) {
        s.cycle = self.cycle;
        s.now_ns = now_ns;
        s.axis_count = self.axes.len();
        let busy = self.seq.busy();
        for (i, a) in self.axes.iter().enumerate() {
            let c = &self.commands[i];
            let fb = self.last_fb[i];
            let r = &self.rungs[i];
            s.axes[i] = AxisSnap {
                status: *a.status(),
                raw: a.raw_position(),
                axis: a.axis_position(),
                velocity: fb.map_or(0.0, |f| f.velocity),
                torque: fb.map_or(0.0, |f| f.torque),
                switch: fb.is_some_and(|f| f.home_switch != a.config().home_switch_normally_closed),
                marker: fb.is_some_and(|f| f.marker_pulse || f.marker_latch.latched),
                enabled: fb.is_some_and(|f| f.drive.enabled),
                fault: fb.is_some_and(|f| f.drive.fault),
                drive_error_code: self.drive_error[i],
                fresh: self.feedback[i].is_some(),
                cmd_position: c.position,
                cmd_velocity: c.velocity,
                enable: c.enable,
                homes_started: r.homes_started,
                aborted_by: self.seq.aborted_by(i).or(self.gantry_aborted_by[i]),
                skew: self.gantry_of[i].and_then(|g| self.gantries[g].skew()),
                timed_out: self.seq.timed_out(i),
                in_sequence: busy & (1 << i) != 0 || r.pending > 0,
                traced: self.tracer.armed() == Some(i),
                lost_homed_ns: r.lost_homed_ns,
                lost_cause: r.lost_cause,
                offset: a.reference_offset(),
                restored: r.restored && a.status().homed,
            };
        }
        s.io_count = self.links.len();
        for (k, l) in self.links.iter().enumerate() {
            s.ios[k] = l.snap();
        }
        s.all_at_rest = self.all_at_rest();
        s.exiting = self.exiting;
    }
}

#[cfg(test)]
mod fuzz;
#[cfg(test)]
pub(crate) mod testbench;
#[cfg(test)]
mod tests;
