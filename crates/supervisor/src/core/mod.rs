//! The cycle's work without its I/O: control requests in, the newest
//! feedback frame of every I/O process in, every axis stepped, one command
//! frame per I/O process out. Kept apart from the thread, timer and ports so
//! it can be tested (and benchmarked) on its own.
//!
//! Allocation happens only in [`Core::new`]; everything per cycle works on
//! preallocated vectors and bit masks.
//!
//! One step, in stages ([`Core::step`]): the links take the frames
//! (`Core::intake`), the home sequences start and stop axes
//! (`Core::sequences`), the gantries coordinate their sides
//! (`Core::gantries`), every engine steps (`Core::engines`); then the
//! thread publishes ([`Core::fill`]). Requests come in between steps
//! ([`Core::control`], in `control.rs`).
//!
//! * [`slot`] — one axis: its engine, rung, feedback, command, status.
//! * [`link`] — per I/O process: accepted frames, attached, gaps, round trip.
//! * [`sequence`] — home order and the failure of a home sequence.
//! * [`gantry`] — the sides of a gantry homed in lockstep.
//! * [`trace`] — recording one homing cycle by cycle.
//! * `ops` — the operations around homing (enable … move, the stream's
//!   acquire and release): delivery, the engines' answers, gantries whole.
//! * [`stream`] — the setpoint stream's owners and intake.
//! * `gear` — gearing across axes: slaves stepped after their masters with
//!   their news, the rules only the cycle sees, a faulted slave's master
//!   stopped.

mod control;
pub mod gantry;
mod gear;
pub mod link;
mod ops;
pub mod sequence;
pub mod slot;
pub mod stream;
pub mod trace;

use crate::shared::{Snapshot, StreamCounts, TraceRecord};
use gantry::GantryCoord;
use link::IoLink;
use motion_config::MachineConfig;
use motion_frames::SetpointFrame;
use motion_frames::{CommandFrame, FeedbackFrame};
use motion_homing::codes::{ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST, EX_TERMINATED_ON_REQUEST};
use ops::{Pending, MAX_PENDING};
use sequence::{Action, AxisView, Sequencer};
pub use slot::AxisSlot;
pub use stream::StreamIntake;
use trace::Tracer;

/// The axes of `mask` among the first `n`, in index order.
pub(super) fn named(mask: u64, n: usize) -> impl Iterator<Item = usize> {
    (0..n.min(64)).filter(move |&i| mask & (1 << i) != 0)
}

/// What one cycle measured, for the statistics.
#[derive(Clone, Copy, Debug, Default)]
pub struct CycleInfo {
    /// I/O processes that did not answer the previous command in time.
    pub late_replies: u32,
    /// Largest round trip of this cycle's answers, ns.
    pub roundtrip_ns: Option<u64>,
}

#[derive(Clone)]
pub struct Core {
    /// Per axis, in config order.
    slots: Vec<AxisSlot>,
    links: Vec<IoLink>,
    seq: Sequencer,
    gantries: Vec<GantryCoord>,
    tracer: Tracer,
    trace_out: Option<TraceRecord>,
    exiting: bool,
    cycle: u64,
    all_mask: u64,
    /// Per gantry, its sides.
    gantry_mask: Vec<u64>,
    /// Operations delivered this cycle, answered after the step.
    pending: [Option<Pending>; MAX_PENDING],
    stream: StreamIntake,
    /// Per gantry, the cycle monitor's check that its sides stay together.
    together: Vec<motion_monitor::Together>,
}

impl Core {
    /// The cycle's work for machine `m`; setpoint frames are refused until
    /// [`Core::with_session_key`] names the key they must carry.
    pub fn new(m: &MachineConfig) -> Self {
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
        // Per axis, the axis whose setpoints move it: itself, or its
        // gantry's first side.
        let lead: Vec<usize> = (0..m.axes.len())
            .map(|i| {
                m.gantry_of(i)
                    .and_then(|g| m.gantries[g].axes.iter().copied().min())
                    .unwrap_or(i)
            })
            .collect();
        let gantry_mask = (m.gantries.iter())
            .map(|g| g.axes.iter().fold(0u64, |k, &i| k | 1 << i))
            .collect();
        Self {
            together: (m.gantries.iter())
                .map(|g| motion_monitor::Together::new(g.max_skew))
                .collect(),
            stream: StreamIntake::new(None, &lead),
            gantry_mask,
            pending: [None; MAX_PENDING],
            slots: (m.axes.iter().enumerate())
                .map(|(i, a)| AxisSlot::new(a, m.gantry_of(i)))
                .collect(),
            links,
            all_mask: seq.all_mask(),
            seq,
            gantries,
            tracer: Tracer::default(),
            trace_out: None,
            exiting: false,
            cycle: 0,
        }
    }

    pub fn axis_count(&self) -> usize {
        self.slots.len()
    }

    /// The axes, in config order.
    pub fn axes(&self) -> &[AxisSlot] {
        &self.slots
    }

    /// The axes "home all" homes.
    pub fn all_mask(&self) -> u64 {
        self.all_mask
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
        let info = self.intake(now_ns, stalled, frames);
        self.sequences(now_ns);
        self.gantries();
        self.hand_setpoints();
        self.engines(now_ns, stalled);
        self.op_upkeep();
        self.gear_upkeep();
        info
    }

    /// Setpoint frames must carry `key` (this session's).
    pub fn with_session_key(mut self, key: [u64; 2]) -> Self {
        self.stream.set_key(key);
        self
    }

    /// Before the frames of a cycle: last cycle's setpoints are forgotten.
    pub fn setpoints_begin(&mut self) {
        self.stream.begin_cycle();
    }

    /// One received setpoint frame (the intake judges it).
    pub fn setpoints_take(&mut self, f: &SetpointFrame) {
        self.stream.take(f);
    }

    /// After a step: the answers of the operations delivered in it.
    pub fn answers(&mut self, each: impl FnMut(crate::shared::Ack)) {
        self.op_answers(each);
    }

    /// Stage 1: every link judges its frame (attached, gaps, reconnection)
    /// and hands each of its axes this cycle's feedback.
    fn intake(
        &mut self,
        now_ns: u64,
        stalled: bool,
        frames: &[Option<&FeedbackFrame>],
    ) -> CycleInfo {
        let mut info = CycleInfo::default();
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
                let entry = frame.map(|f| &f.axes[j]);
                self.slots[i].take_feedback(now_ns, &c, detached, entry);
            }
        }
        info
    }

    /// Stage 2: the home sequences decide who starts and who is stopped.
    fn sequences(&mut self, now_ns: u64) {
        let (slots, links) = (&self.slots, &self.links);
        let mut starts = 0u64;
        let mut stops = 0u64;
        self.seq.step(
            now_ns,
            |i| {
                let s = slots[i].status();
                AxisView {
                    running: slots[i].rung.pending > 0 || s.ip || s.stopping,
                    failed: s.er,
                    io_lost: s.er
                        && (s.err, s.exerr) == (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST)
                        && !links[slots[i].io].attached(),
                }
            },
            |a| match a {
                Action::Start(i) => starts |= 1 << i,
                Action::Stop(i) => stops |= 1 << i,
            },
        );
        for (i, slot) in self.slots.iter_mut().enumerate() {
            if starts & (1 << i) != 0 && !self.exiting {
                slot.rung.arm();
                slot.gantry_aborted_by = None;
            }
            if stops & (1 << i) != 0 {
                slot.rung
                    .stop(Some((ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST)));
            }
        }
    }

    /// Stage 3: every gantry holds its sides at the barrier per phase, gives
    /// the final moves one duration, and stops every side when one fails
    /// (decided on the previous step's state).
    fn gantries(&mut self) {
        for g in &mut self.gantries {
            let d = g.step(&self.slots);
            for (j, &i) in g.sides().iter().enumerate() {
                let slot = &mut self.slots[i];
                slot.rung.request.hold = d.hold;
                slot.rung.request.move_duration_ns = d.move_duration_ns;
                if let Some(code) = d.stop[j] {
                    slot.rung.stop(Some(code));
                    if let Some(f) = d.failed_side {
                        slot.gantry_aborted_by = Some(f as u8);
                    }
                }
            }
        }
    }

    /// Stage 4: every engine steps (leaving: once everything is at rest,
    /// the drives are disabled) — geared slaves after every other axis,
    /// with their master's news of this cycle (`gear`); an armed trace
    /// records its axis.
    fn engines(&mut self, now_ns: u64, stalled: bool) {
        let shutdown = self.exiting && self.all_at_rest();
        self.trace_out = None;
        let n = self.slots.len();
        let slaves = self.slaves();
        for i in named(!slaves, n) {
            self.step_axis(i, now_ns, stalled, shutdown);
        }
        for i in named(slaves, n) {
            self.feed_slave(i);
            self.step_axis(i, now_ns, stalled, shutdown);
        }
    }

    /// One engine's step, and the trace's record of it.
    fn step_axis(&mut self, i: usize, now_ns: u64, stalled: bool, shutdown: bool) {
        let slot = &mut self.slots[i];
        let started = slot.step(now_ns, stalled, shutdown);
        if let Some(r) = self.tracer.record(
            now_ns,
            i,
            &slot.engine,
            &slot.command,
            slot.feedback(),
            started,
        ) {
            self.trace_out = Some(r);
        }
        self.gantries_together(now_ns);
    }

    /// After every side's own verdict: a gantry whose sides moved apart is
    /// stopped on every side by their monitors.
    fn gantries_together(&mut self, now_ns: u64) {
        for (g, together) in self.together.iter_mut().enumerate() {
            let sides = self.gantries[g].sides();
            let slots = &self.slots;
            if let Err(apart) = together.judge(sides.iter().map(|&i| slots[i].side())) {
                for &i in sides {
                    self.slots[i].gantry_apart(now_ns, apart.value, apart.bound);
                }
            }
        }
    }

    /// This cycle's trace record, if an armed trace is recording.
    pub fn trace_record(&self) -> Option<TraceRecord> {
        self.trace_out
    }

    /// Writes the cycle's commands of I/O process `k` into its frame.
    pub fn fill(&self, k: usize, frame: &mut CommandFrame) {
        let axes = &self.links[k].axes;
        frame.header.axis_count = axes.len() as u32;
        for (e, &i) in frame.axes.iter_mut().zip(axes) {
            *e = self.slots[i].command_entry();
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
        self.slots.iter().all(AxisSlot::at_rest)
    }

    /// Leaving is complete: at rest and the drives told to disable.
    pub fn exit_done(&self) -> bool {
        self.exiting && self.all_at_rest() && self.slots.iter().all(|s| !s.command.enable)
    }

    pub fn snapshot(&self, now_ns: u64, s: &mut Snapshot) {
        s.cycle = self.cycle;
        s.now_ns = now_ns;
        s.axis_count = self.slots.len();
        let busy = self.seq.busy();
        for (i, slot) in self.slots.iter().enumerate() {
            s.axes[i] = crate::shared::AxisSnap {
                aborted_by: self.seq.aborted_by(i).or(slot.gantry_aborted_by),
                skew: slot.gantry.and_then(|g| self.gantries[g].skew()),
                timed_out: self.seq.timed_out(i),
                in_sequence: busy & (1 << i) != 0 || slot.rung.pending > 0,
                traced: self.tracer.armed() == Some(i),
                owner: self.stream.owner_of(i),
                ..slot.snap()
            };
        }
        s.stream = StreamCounts {
            owners: self.stream.owner_count(),
            ..self.stream.counts
        };
        s.io_count = self.links.len();
        for (k, l) in self.links.iter().enumerate() {
            s.ios[k] = l.snap();
        }
        s.all_at_rest = self.all_at_rest();
        s.exiting = self.exiting;
    }
}

#[cfg(test)]
mod campaign;
#[cfg(test)]
mod fuzz;
#[cfg(test)]
mod gear_tests;
#[cfg(test)]
mod ops_tests;
#[cfg(test)]
mod stream_fuzz;
#[cfg(test)]
pub(crate) mod testbench;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod together_tests;
