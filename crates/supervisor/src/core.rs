//! The cycle's work without its I/O: control requests in, feedback frame in,
//! every axis stepped, command frame out. Kept apart from the thread, timer
//! and ports so it can be tested (and benchmarked) on its own.
//!
//! Allocation happens only in [`Core::new`]; everything per cycle works on
//! preallocated vectors.

use crate::shared::{AxisSnap, Control, Snapshot};
use motion_config::MachineConfig;
use motion_frames::{axis_to_feedback, command_to_axis, CommandFrame, FeedbackFrame, SW_NO_DATA};
use motion_homing::{Axis, Command, Feedback, Phase, Request};

/// The Home instruction's rung for one axis, driven by control requests.
#[derive(Clone, Copy, Debug, Default)]
struct Rung {
    request: Request,
    /// A Home request waits one cycle with the rung low, so it is always a
    /// rising edge, even right after an earlier Home.
    pending_home: bool,
    homes_started: u32,
}

pub struct Core {
    axes: Vec<Axis>,
    counts_per_unit: Vec<f64>,
    rungs: Vec<Rung>,
    commands: Vec<Command>,
    feedback: Vec<Option<Feedback>>,
    exiting: bool,
    frames_received: u64,
    frames_missing: u64,
    frames_rejected: u64,
    /// Answers older than this many commands count as missing.
    stale_cycles: u64,
    /// Sequence of the last command frame published (0: none yet).
    last_sent: u64,
    /// Frames that arrived but answered a command too old to trust.
    frames_late: u64,
    io_fresh: bool,
    cycle: u64,
}

impl Core {
    pub fn new(m: &MachineConfig) -> Self {
        let n = m.axes.len();
        Self {
            axes: m.axes.iter().map(|a| Axis::new(a.engine)).collect(),
            counts_per_unit: m.axes.iter().map(|a| a.engine.counts_per_unit).collect(),
            rungs: vec![Rung::default(); n],
            commands: vec![Command::default(); n],
            feedback: vec![None; n],
            exiting: false,
            frames_received: 0,
            frames_missing: 0,
            frames_rejected: 0,
            stale_cycles: u64::from(m.supervisor.stale_cycles),
            last_sent: 0,
            frames_late: 0,
            io_fresh: false,
            cycle: 0,
        }
    }

    pub fn axis_count(&self) -> usize {
        self.axes.len()
    }

    pub fn axes(&self) -> &[Axis] {
        &self.axes
    }

    /// Applies one control request.
    pub fn control(&mut self, c: Control) {
        match c {
            Control::Home(i) => {
                if let Some(r) = self.rungs.get_mut(i) {
                    r.request.home = false;
                    r.pending_home = !self.exiting;
                }
            }
            Control::Stop(i) => {
                if let Some(r) = self.rungs.get_mut(i) {
                    r.request.stop = true;
                }
            }
            Control::Exit => {
                self.exiting = true;
                for r in &mut self.rungs {
                    r.pending_home = false;
                    r.request.home = false;
                    r.request.stop = true;
                }
            }
        }
    }

    /// One cycle: `frame` is the fresh feedback frame, if one arrived.
    ///
    /// A frame is used only if it has this machine's axis count and answers
    /// one of the last `stale_cycles` commands: a new frame that answers an
    /// old command (a lagging I/O process, or `motion-io`'s watchdog frames,
    /// which answer none) carries old positions and counts as missing.
    pub fn step(&mut self, now_ns: u64, frame: Option<&FeedbackFrame>) {
        self.cycle += 1;
        let right_shape = frame.filter(|f| f.header.axis_count as usize == self.axes.len());
        if frame.is_some() && right_shape.is_none() {
            self.frames_rejected += 1;
        }
        let usable = right_shape
            .filter(|f| self.last_sent.saturating_sub(f.answers_sequence) <= self.stale_cycles);
        if right_shape.is_some() && usable.is_none() {
            self.frames_late += 1;
        }
        self.io_fresh = usable.is_some();
        if usable.is_some() {
            self.frames_received += 1;
        } else {
            self.frames_missing += 1;
        }
        let at_rest = self.exiting && self.all_at_rest();
        for i in 0..self.axes.len() {
            // An entry the I/O process marks as not fresh (bus frame lost,
            // SubDevice out of OP) is missing feedback for that axis alone.
            self.feedback[i] = usable
                .map(|f| &f.axes[i])
                .filter(|a| a.status_word & SW_NO_DATA == 0)
                .map(|a| axis_to_feedback(a, self.counts_per_unit[i]));
            let rung = &mut self.rungs[i];
            if rung.pending_home {
                rung.pending_home = false;
                rung.request.home = true;
                rung.homes_started += 1;
            } else if rung.request.home {
                // Keep the rung true while the instruction runs; drop it after.
                let s = self.axes[i].status();
                if !s.ip && (s.dn || s.er) {
                    rung.request.home = false;
                }
            }
            // Leaving: once everything is at rest, disable the drives.
            rung.request.shutdown = at_rest;
            let req = rung.request;
            self.commands[i] = self.axes[i].step(now_ns, self.feedback[i].as_ref(), &req);
            // Stop is a one-cycle pulse (the engine takes its rising edge).
            self.rungs[i].request.stop = false;
        }
    }

    /// Writes the cycle's commands into an outgoing frame.
    pub fn fill(&self, frame: &mut CommandFrame) {
        frame.header.axis_count = self.axes.len() as u32;
        for (i, cmd) in self.commands.iter().enumerate() {
            frame.axes[i] = command_to_axis(cmd, self.counts_per_unit[i]);
        }
    }

    /// The command frame with this sequence number was published.
    pub fn sent(&mut self, sequence: u64) {
        self.last_sent = sequence;
    }

    /// A frame the ports refused (wrong layout version, bad header).
    pub fn note_rejected(&mut self) {
        self.frames_rejected += 1;
    }

    pub fn exiting(&self) -> bool {
        self.exiting
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
        for (i, a) in self.axes.iter().enumerate() {
            let c = &self.commands[i];
            s.axes[i] = AxisSnap {
                status: *a.status(),
                raw: a.raw_position(),
                axis: a.axis_position(),
                cmd_position: c.position,
                cmd_velocity: c.velocity,
                enable: c.enable,
                homes_started: self.rungs[i].homes_started,
            };
        }
        s.frames_received = self.frames_received;
        s.frames_missing = self.frames_missing;
        s.frames_rejected = self.frames_rejected;
        s.frames_late = self.frames_late;
        s.io_fresh = self.io_fresh;
        s.all_at_rest = self.all_at_rest();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_frames::feedback_to_axis;
    use motion_plant::Plant;

    /// The demo machine through Core + frames + plants, no threads or IPC.
    #[test]
    fn demo_homes_through_frames() {
        let m = motion_config::parse(motion_config::DEMO_TOML).unwrap();
        let mut core = Core::new(&m);
        let mut plants: Vec<Plant> = m.axes.iter().map(|a| Plant::new(a.sim)).collect();
        let mut fb = FeedbackFrame::default();
        let mut cmd = CommandFrame::default();
        let dt = m.supervisor.cycle_us as f64 * 1e-6;
        for k in 0..10_000u64 {
            if k == 10 {
                // As `home` does: only once the I/O answers.
                for i in 0..m.axes.len() {
                    core.control(Control::Home(i));
                }
            }
            core.step(k * m.supervisor.cycle_ns(), (k > 0).then_some(&fb));
            core.fill(&mut cmd);
            fb.header.axis_count = cmd.header.axis_count;
            for (i, a) in m.axes.iter().enumerate() {
                let c = motion_frames::axis_to_command(&cmd.axes[i], a.engine.counts_per_unit);
                let f = plants[i].step(&c, dt);
                fb.axes[i] = feedback_to_axis(&f, a.engine.counts_per_unit);
            }
        }
        let mut snap = Snapshot::default();
        core.snapshot(0, &mut snap);
        for (i, a) in m.axes.iter().enumerate() {
            let s = &snap.axes[i];
            assert!(s.status.pc, "{}: {:?}", a.name, s.status);
            assert_eq!(s.homes_started, 1);
            assert!(s.settled());
        }
        // Exit: stop, then disable every drive.
        core.control(Control::Exit);
        for k in 10_000..10_010u64 {
            core.step(k * 1_000_000, Some(&fb));
        }
        assert!(core.exit_done());
    }

    #[test]
    fn an_answer_to_an_old_command_is_no_feedback() {
        let m = motion_config::parse(motion_config::DEMO_TOML).unwrap();
        let stale = u64::from(m.supervisor.stale_cycles);
        let mut core = Core::new(&m);
        let mut fb = FeedbackFrame::default();
        fb.header.axis_count = m.axes.len() as u32;
        fb.answers_sequence = 100;
        core.sent(100 + stale);
        core.step(0, Some(&fb));
        let mut snap = Snapshot::default();
        core.snapshot(0, &mut snap);
        assert!(snap.io_fresh, "{stale} commands old is still fresh");
        core.sent(101 + stale);
        core.step(1, Some(&fb));
        core.snapshot(1, &mut snap);
        assert!(!snap.io_fresh);
        assert_eq!((snap.frames_late, snap.frames_received), (1, 1));
    }

    #[test]
    fn wrong_axis_count_is_no_feedback() {
        let m = motion_config::parse(motion_config::DEMO_TOML).unwrap();
        let mut core = Core::new(&m);
        let mut fb = FeedbackFrame::default();
        fb.header.axis_count = 2;
        core.step(0, Some(&fb));
        let mut snap = Snapshot::default();
        core.snapshot(0, &mut snap);
        assert_eq!(snap.frames_rejected, 1);
        assert!(!snap.io_fresh);
    }
}
