//! Feedback intake: what of a cycle's feedback the engine may use.
//!
//! Feedback is validated before anything looks at it (finite, within
//! `max_position`); corrupt feedback clears HomedStatus and aborts homing
//! with ERR 12 / EXERR 41, naming the attribute. A cycle without a usable
//! sample counts towards feedback loss; too many in a row clear HomedStatus
//! and abort homing with ERR 12 / EXERR 40.

use super::{Abort, Axis};
use crate::codes::*;
use crate::config::AxisConfiguration;
use crate::io::{DriveState, Feedback};

/// A validated feedback sample.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sample {
    pub fb: Feedback,
    /// Logical switch state: actuated, whatever the wiring.
    pub switch_active: bool,
}

impl Axis {
    /// This cycle's usable sample, if any.
    pub(super) fn intake(&mut self, now: u64, feedback: Option<&Feedback>) -> Option<Sample> {
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
