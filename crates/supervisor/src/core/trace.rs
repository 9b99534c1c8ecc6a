//! Recording every cycle of one homing (`motionctl trace`): armed for an
//! axis, it starts with the next homing of that axis and ends when the axis
//! has settled. The cycle hands the records over a lock-free queue; nothing
//! is formatted or stored here.

use motion_homing::{Axis, Command, Feedback};

use crate::shared::TraceRecord;

#[derive(Clone, Copy, Debug, Default)]
pub struct Tracer {
    armed: Option<usize>,
    recording: bool,
    start_ns: u64,
    had_event: bool,
}

impl Tracer {
    /// Record the next homing of `axis` (replaces an earlier arming).
    pub fn arm(&mut self, axis: usize) {
        self.armed = Some(axis);
        self.recording = false;
        self.had_event = false;
    }

    pub fn armed(&self) -> Option<usize> {
        self.armed
    }

    /// One cycle of axis `i` (after its engine step). `started` = its Home
    /// instruction got its rising edge this cycle.
    pub fn record(
        &mut self,
        now_ns: u64,
        i: usize,
        axis: &Axis,
        cmd: &Command,
        fb: Option<&Feedback>,
        started: bool,
    ) -> Option<TraceRecord> {
        if self.armed != Some(i) {
            return None;
        }
        let s = axis.status();
        if !self.recording {
            if !started {
                return None;
            }
            self.recording = true;
            self.start_ns = now_ns;
            self.had_event = false;
        }
        let event = s.event_raw.is_some() && !self.had_event;
        self.had_event |= event;
        let end = !s.ip && !s.stopping && cmd.velocity == 0.0 && !started;
        let (position, velocity, torque, switch, marker) = match fb {
            Some(f) => (
                f.position,
                f.velocity,
                f.torque,
                axis.reference_switch_active(f),
                f.marker_pulse || f.marker_latch.latched,
            ),
            None => (f64::NAN, f64::NAN, f64::NAN, false, false),
        };
        let rec = TraceRecord {
            axis: i as u8,
            phase: s.phase as u8,
            switch,
            marker,
            fresh: fb.is_some(),
            event,
            end,
            t_ns: now_ns.saturating_sub(self.start_ns),
            cmd_position: cmd.position,
            cmd_velocity: cmd.velocity,
            position,
            velocity,
            torque,
            event_raw: s.event_raw.unwrap_or(f64::NAN),
            err: s.err,
            exerr: s.exerr,
        };
        if end {
            self.armed = None;
            self.recording = false;
        }
        Some(rec)
    }
}
