//! What one cycle brought, as the monitor reads it from what crossed the
//! engine's boundary: the request it was given, the answer in its status,
//! the drive's state bits in the feedback. Edges are taken against what
//! the monitor remembers of the cycles before ([`Seen`]), never against
//! the engine's memory.

use motion_homing::{Command, DriveState, Feedback, Operation, Request, Status};

/// One cycle's inputs and the command that left the engine.
#[derive(Clone, Copy, Debug)]
pub struct Cycle<'a> {
    /// The cycle's time, ns (monotonic).
    pub now_ns: u64,
    /// This cycle's fresh feedback (`None`: none arrived).
    pub feedback: Option<&'a Feedback>,
    /// The request the engine was given in this step.
    pub request: &'a Request,
    /// The engine's status after the step (its answer to the request).
    pub status: &'a Status,
    /// The raw → axis offset the soft limits are in while the axis is
    /// homed (`Axis::limits_offset`: a redefine position does not move
    /// them on the machine).
    pub reference: Option<f64>,
    /// The command the engine produced.
    pub command: &'a Command,
    /// A new drive-I/O process took over in this cycle (another process
    /// than before): its drives were off or stopped in between.
    pub io_restarted: bool,
}

/// What the monitor remembers from the cycles before.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Seen {
    /// `Status::op.id` after the previous step.
    op_id: u32,
    /// The rung and the stop as the previous request had them.
    home: bool,
    stop: bool,
    /// `Status::faulted` after the previous step.
    faulted: bool,
    /// The drive's state bits of the newest valid feedback.
    drive: Option<DriveState>,
    /// The power stage was asked on by the previous command.
    enable: bool,
}

/// What happened in this cycle.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Events {
    /// The operation this step's request carried, accepted by the engine
    /// (its `Status::op.id` moved on and names that kind).
    pub accepted: Option<Operation>,
    /// A Home rung's rising edge started homing.
    pub home_started: bool,
    /// A stop's rising edge (`Request::stop`).
    pub stop: bool,
    /// The engine reports a new axis fault.
    pub faulted: bool,
    /// The drive reports a fault it did not report before.
    pub drive_fault: bool,
    /// The drive switched its power stage off by itself (no fault) while
    /// it was asked on.
    pub dropped: bool,
    /// This cycle's feedback is valid: its drive state bits are news.
    pub fresh: bool,
    /// A new I/O process took over.
    pub io_restarted: bool,
    /// The drive state as known now (the newest valid feedback's).
    pub drive: Option<DriveState>,
}

/// A sample whose positions are numbers: its state bits are taken.
fn valid(fb: &Feedback) -> bool {
    fb.position.is_finite() && fb.velocity.is_finite()
}

impl Seen {
    /// The events of cycle `c`; remembers what the next cycle compares with.
    pub fn events(&mut self, c: &Cycle) -> Events {
        let (req, st) = (c.request, c.status);
        let accepted = match req.op {
            Some(op) if st.op.id != self.op_id && st.op.kind == op.kind() => Some(op),
            // answered in place (a change of dynamics, a registration):
            // the running operation keeps its id; accepted when the engine
            // left no refusal
            Some(op) if op.kind().in_place() && st.op.refused.is_none() => Some(op),
            _ => None,
        };
        let fresh = c.feedback.filter(|f| valid(f)).map(|f| f.drive);
        let before = self.drive;
        let (drive_fault, dropped) = match (fresh, before) {
            (Some(now), Some(was)) => (
                now.fault && !was.fault,
                self.enable && was.enabled && !now.enabled && !now.fault,
            ),
            (Some(now), None) => (now.fault, false),
            _ => (false, false),
        };
        let ev = Events {
            accepted,
            home_started: req.home && !self.home && st.ip,
            stop: req.stop && !self.stop,
            faulted: st.faulted && !self.faulted,
            drive_fault,
            dropped,
            fresh: fresh.is_some(),
            io_restarted: c.io_restarted,
            drive: fresh.or(before),
        };
        *self = Seen {
            op_id: st.op.id,
            home: req.home,
            stop: req.stop,
            faulted: st.faulted,
            drive: ev.drive,
            enable: c.command.enable,
        };
        ev
    }

    /// The command that left this cycle asked the power stage `on`
    /// (after the monitor's own verdict: a tripped axis is off).
    pub fn sent(&mut self, on: bool) {
        self.enable = on;
    }
}
