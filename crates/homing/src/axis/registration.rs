//! Registration (MAR / MDR, PLCopen MC_TouchProbe / MC_AbortTrigger): the
//! axis's position at the next edge of an input, whatever moves the axis.
//!
//! * **Where the drive latches the input** — the home switch with
//!   `registration` (its probe input wired to the home switch: not on a
//!   limit-switch sequence, whose probe watches the limit), the marker with
//!   `marker_latch` — the drive's latch is armed (the same handshake and
//!   plausibility check homing uses, `latches`) and its position taken:
//!   exact to the count. An edge the input bits show before the drive has
//!   confirmed the arming is taken sampled (below), so none is missed.
//! * **Elsewhere the edge is sampled**: the input's level (the home switch
//!   bit, the marker's "pulse passed" bit) in each fresh sample, the edge
//!   placed midway between the positions of the two samples around it —
//!   an error of at most half the travel between them: speed × cycle / 2
//!   (speed × (gap + cycle) / 2 across a tolerated feedback gap). Never
//!   refused for lack of a latch.
//! * Only samples taken after the arming count (the sample of the step
//!   that armed was taken before it), and an edge outside the window is
//!   passed over (a drive latch is re-armed for the next one).
//! * Homing and registration use the same latches and exclude each other
//!   (the Logix error table: Home and Registration are mutually
//!   exclusive): `arm` is refused while homing is in process (ERR 16), and
//!   a homing that starts disarms the registration.
//! * Registration only watches: it never touches the command, so it
//!   changes nothing of a jog, move, stream or stop under way, and it is
//!   answered in place (`OpKind::in_place`).

use super::intake::Sample;
use super::ops::Code;
use super::Axis;
use crate::codes::*;
use crate::config::AxisConfiguration;
use crate::operation::{ArmSpec, LatchEdge, LatchInput};

/// An armed registration.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Registration {
    pub armed: bool,
    input: LatchInput,
    edge: LatchEdge,
    window: Option<(f64, f64)>,
    /// The drive latches the input: the id of its arming (0: sampled).
    latch_id: u8,
    /// Time of the step that armed: only later samples count.
    armed_ns: u64,
    /// The input and position of the previous sample since arming.
    prev: Option<(bool, f64)>,
}

impl Axis {
    /// A redefine position moved every axis position by `d`: an armed
    /// window and a latched position follow, so both stay at their place
    /// on the machine (the edge a window was armed around is still caught).
    pub(super) fn registration_follows(&mut self, d: f64) {
        if let Some((lo, hi)) = &mut self.reg.window {
            *lo += d;
            *hi += d;
        }
        if let Some(p) = &mut self.status.registration_position {
            *p += d;
        }
    }
}

impl Axis {
    /// MAR: refused on a virtual axis, for a marker the axis lacks, on a
    /// bad window, without feedback and while homing; a new arming
    /// replaces the one before.
    pub(super) fn arm_op(&mut self, now: u64, spec: &ArmSpec) -> Result<(), Code> {
        self.arm_refusal(spec)?;
        let mut reg = Registration {
            armed: true,
            input: spec.input,
            edge: spec.edge,
            window: spec.window,
            armed_ns: now,
            ..Registration::default()
        };
        let at = self.last.map(|s| s.fb.position);
        let cfg = &self.cfg;
        match spec.input {
            LatchInput::Switch if cfg.registration && !cfg.home_sequence.uses_limit_switch() => {
                let actuated = spec.edge == LatchEdge::Rising;
                self.latches
                    .arm_switch(actuated != cfg.home_switch_normally_closed, at);
                reg.latch_id = self.latches.switch_id;
            }
            LatchInput::Marker if cfg.marker_latch => {
                self.latches.arm_marker(at);
                reg.latch_id = self.latches.marker_id;
            }
            _ => {}
        }
        self.reg = reg;
        self.status.registration_armed = true;
        self.status.registration_position = None;
        Ok(())
    }

    fn arm_refusal(&self, spec: &ArmSpec) -> Result<(), Code> {
        if self.status.ip {
            return Err((ERR_HOME_IN_PROCESS, 0));
        }
        if self.cfg.configuration == AxisConfiguration::Virtual {
            return Err((ERR_REGISTRATION_REFUSED, EX_REGISTRATION_NO_FEEDBACK_DEVICE));
        }
        if spec.input == LatchInput::Marker && !self.cfg.marker {
            return Err((ERR_REGISTRATION_REFUSED, EX_REGISTRATION_NO_MARKER));
        }
        if let Some((lo, hi)) = spec.window {
            if !(lo.is_finite() && hi.is_finite()) {
                return Err((ERR_REGISTRATION_REFUSED, EX_REGISTRATION_WINDOW_NOT_FINITE));
            }
            if lo > hi {
                return Err((ERR_REGISTRATION_REFUSED, EX_REGISTRATION_WINDOW_EMPTY));
            }
        }
        if self.last.is_none() {
            return Err((ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST));
        }
        Ok(())
    }

    /// MDR (and a homing's start): nothing armed any more; the last
    /// latched position stays.
    pub(super) fn disarm_registration(&mut self) {
        if self.reg.latch_id != 0 && !self.status.ip {
            self.latches.disarm();
        }
        self.reg = Registration::default();
        self.status.registration_armed = false;
    }

    /// One fresh sample for an armed registration.
    pub(super) fn registration_step(&mut self, now: u64, s: &Sample) {
        if !self.reg.armed || now <= self.reg.armed_ns {
            return;
        }
        let level = match self.reg.input {
            LatchInput::Switch => s.fb.home_switch != self.cfg.home_switch_normally_closed,
            LatchInput::Marker => s.fb.marker_pulse,
        };
        let prev = self.reg.prev.filter(|_| self.prev.is_some());
        self.reg.prev = Some((level, s.fb.position));
        if let Some(raw) = self.drive_latched(s) {
            return self.registered(raw);
        }
        let Some((was, at)) = prev else {
            // The first sample since arming (or since the feedback was
            // lost): no edge to see yet.
            return;
        };
        let edge = match self.reg.input {
            LatchInput::Marker => level,
            LatchInput::Switch => match self.reg.edge {
                LatchEdge::Rising => !was && level,
                LatchEdge::Falling => was && !level,
            },
        };
        if edge && !self.latch_confirmed(s) {
            self.registered(0.5 * (at + s.fb.position));
        }
    }

    /// The drive confirmed this registration's arming of its latch.
    fn latch_confirmed(&self, s: &Sample) -> bool {
        let id = self.reg.latch_id;
        let l = match self.reg.input {
            LatchInput::Switch => s.fb.switch_latch,
            LatchInput::Marker => s.fb.marker_latch,
        };
        id != 0 && l.id == id
    }

    /// The drive's latched position for this registration, if it latched
    /// one on the travel since arming; one off the travel is counted and
    /// re-armed, as homing does.
    fn drive_latched(&mut self, s: &Sample) -> Option<f64> {
        let id = self.reg.latch_id;
        let (l, travel) = match self.reg.input {
            LatchInput::Switch => (s.fb.switch_latch, self.latches.switch_travel),
            LatchInput::Marker => (s.fb.marker_latch, self.latches.marker_travel),
        };
        if id == 0 || l.id != id || !l.latched {
            self.keep_latch_armed();
            return None;
        }
        if !self.latch_plausible(travel, l.position, s) {
            let n = match self.reg.input {
                LatchInput::Switch => &mut self.status.implausible.switch_latches,
                LatchInput::Marker => &mut self.status.implausible.marker_latches,
            };
            *n = n.saturating_add(1);
            self.rearm_latch();
            return None;
        }
        Some(l.position)
    }

    /// A refused home request disarms the latches (`fail`): the
    /// registration's is armed again.
    fn keep_latch_armed(&mut self) {
        let id = self.reg.latch_id;
        let current = match self.reg.input {
            LatchInput::Switch => self.latches.switch_id,
            LatchInput::Marker => self.latches.marker_id,
        };
        if id != 0 && current != id {
            self.rearm_latch();
        }
    }

    fn rearm_latch(&mut self) {
        let at = self.last.map(|s| s.fb.position);
        match self.reg.input {
            LatchInput::Switch => {
                let edge = self.latches.switch_edge == crate::io::Edge::Rising;
                self.latches.arm_switch(edge, at);
                self.reg.latch_id = self.latches.switch_id;
            }
            LatchInput::Marker => {
                self.latches.arm_marker(at);
                self.reg.latch_id = self.latches.marker_id;
            }
        }
    }

    /// An edge at raw position `raw`: latched if inside the window (else
    /// passed over, a drive latch re-armed).
    fn registered(&mut self, raw: f64) {
        let p = self.to_axis(raw);
        let inside = self.reg.window.is_none_or(|(lo, hi)| lo <= p && p <= hi);
        if !inside {
            if self.reg.latch_id != 0 {
                self.rearm_latch();
            }
            return;
        }
        if self.reg.latch_id != 0 {
            self.latches.disarm();
        }
        self.reg = Registration::default();
        self.status.registration_armed = false;
        self.status.registration_position = Some(p);
    }
}
