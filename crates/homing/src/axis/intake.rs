//! Feedback intake: what of a cycle's feedback the engine may use.
//!
//! Feedback is validated before anything looks at it (finite, within
//! `max_position`); corrupt feedback clears HomedStatus and aborts homing
//! with ERR 12 / EXERR 41, naming the attribute. A finite position that
//! jumped further than the axis can move is refused too
//! ([`plausible`](super::plausible), ERR 12 / EXERR 44). A step without a usable
//! sample counts towards feedback loss ([`loss`](super::loss), a leaky
//! bucket in time); when that rule trips, HomedStatus is cleared and homing
//! aborts with ERR 12 / EXERR 40 (`Status::lost_after_ns` says how long the
//! gap was).
//!
//! # During a tolerated gap
//!
//! The engine takes no decision on old data: nothing is detected until a
//! fresh sample arrives (no event from a stale sample), and no profile is
//! changed: the planned profile just runs on, so a leg that ends by time (a
//! stop ramp) reaches its end, and the next leg starts on the next fresh
//! sample. When feedback returns, a sampled switch edge found across the gap
//! is placed at the midpoint of the samples around it, so its precision
//! degrades from speed × cycle / 2 to **speed × (gap + cycle) / 2**. Drive
//! latches (markers, registration) are exact whatever the gap. An index
//! pulse reported without a latch (`marker_latch = false`) falls in the frame
//! that was lost: a marker search across a gap can miss it, which is why
//! such drives should home with a latch or slowly.

use super::{Abort, Axis};
use crate::codes::*;
use crate::config::AxisConfiguration;
use crate::io::{DriveState, Feedback};
use crate::operation::StopCause;

/// What the detection needs of the sample before the newest (an edge is
/// between the two).
#[derive(Clone, Copy, Debug)]
pub(super) struct Seen {
    pub switch_active: bool,
    pub position: f64,
}

/// A validated feedback sample.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sample {
    pub fb: Feedback,
    /// Logical state of the sequence's reference switch (the home switch,
    /// or the limit switch of a limit-switch sequence): actuated, whatever
    /// the wiring.
    pub switch_active: bool,
    /// Time since the previous usable sample, ns (0 for the first).
    pub dt_ns: u64,
}

impl Axis {
    /// Takes this cycle's feedback: true when it gave a usable sample,
    /// which is then the newest one (`self.last`).
    pub(super) fn intake(&mut self, now: u64, feedback: Option<&Feedback>, stalled: bool) -> bool {
        let dt = self.loss.tick(now, self.cfg.cycle_ns);
        let fresh = self.sample(now, feedback);
        if fresh {
            self.loss.fresh(now, dt, self.cfg.feedback_loss_drain);
        } else {
            self.missing(now, dt, stalled);
        }
        self.status.feedback_gap_ns = self.loss.gap(now);
        self.status.feedback_loss_ns = self.loss.bucket();
        fresh
    }

    /// Takes this step's feedback as the newest sample if it is usable.
    fn sample(&mut self, now: u64, feedback: Option<&Feedback>) -> bool {
        if self.cfg.configuration == AxisConfiguration::Virtual {
            // No hardware: the command is the position.
            let (p, v) = self.profile.at(now);
            let fb = Feedback {
                position: p,
                velocity: v,
                drive: DriveState {
                    enabled: true,
                    fault: false,
                },
                ..Feedback::default()
            };
            self.accept(now, &fb);
            return true;
        }
        match feedback {
            None => false,
            Some(fb) => match check_feedback(fb, self.cfg.max_position) {
                Ok(()) if !self.plausible.position(fb.position, now) => {
                    // A forged or corrupt frame: never used, never an event.
                    let n = &mut self.status.implausible.jumps;
                    *n = n.saturating_add(1);
                    self.status.homed = false;
                    self.feedback_trouble(now, EX_FEEDBACK_IMPLAUSIBLE);
                    false
                }
                Ok(()) => {
                    self.accept(now, fb);
                    true
                }
                Err(attribute) => {
                    self.status.bad_attribute = Some(attribute);
                    // Corrupt feedback: the reference can no longer be trusted.
                    self.status.homed = false;
                    self.feedback_trouble(now, EX_FEEDBACK_INVALID);
                    false
                }
            },
        }
    }

    /// `fb` becomes the newest sample (copied once, into `self.last`).
    fn accept(&mut self, now: u64, fb: &Feedback) {
        self.prev = self.last.as_ref().map(|l| Seen {
            switch_active: l.switch_active,
            position: l.fb.position,
        });
        self.last = Some(Sample {
            fb: *fb,
            switch_active: self.reference_switch_active(fb),
            dt_ns: self.last_sample_ns.map_or(0, |t| now.saturating_sub(t)),
        });
        self.last_sample_ns = Some(now);
        self.latches.seen_at(fb.position);
        self.status.feedback_ok = true;
    }

    /// A step without a usable sample, `dt` after the previous step.
    fn missing(&mut self, now: u64, dt: u64, stalled: bool) {
        if self.loss.missing(dt, self.cfg.feedback_timeout_ns, stalled) {
            self.status.feedback_ok = false;
            self.status.homed = false;
            self.status.lost_after_ns = Some(self.loss.gap(now));
            // Edges across a gap of unknown length mean nothing.
            self.prev = None;
            self.last = None;
            // a lost drive is named as such, not as its I/O process; it no
            // longer follows: nothing is asked of it any more (the enable
            // request withdrawn in every state), so it is never switched on
            // by a request left standing when it comes back
            if self.status.drive_lost {
                self.drive_gone_away(now, EX_DRIVE_LOST);
                self.feedback_trouble(now, EX_DRIVE_LOST);
            } else {
                self.feedback_trouble(now, EX_FEEDBACK_LOST);
            }
        }
    }

    /// Feedback that cannot be used (12 / `exerr`): homing in process
    /// aborts, an operation's motion is an axis fault; both stop the axis
    /// (at Home Deceleration, at `max_deceleration`).
    fn feedback_trouble(&mut self, now: u64, exerr: u16) {
        if self.status.ip {
            self.fail(now, ERR_SERVO_MESSAGE, exerr, Abort::Controlled);
        }
        self.op_fault(
            now,
            (ERR_SERVO_MESSAGE, exerr),
            StopCause::FeedbackLost,
            false,
        );
    }
}

/// Rejects feedback that must not reach the engine; names the attribute.
fn check_feedback(fb: &Feedback, max_position: f64) -> Result<(), &'static str> {
    // Finite and within the limit: `|x| <= limit` with the limit cut to the
    // largest finite number (so an infinite or NaN limit still refuses
    // infinities; NaN compares false), one comparison where `is_finite` and
    // the limit take two.
    let ok = |x: f64, limit: f64| x.abs() <= limit.min(f64::MAX);
    let bad = |x: f64, limit: f64| !ok(x, limit);
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
