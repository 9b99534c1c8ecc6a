//! Home, stop, unhome and trace: the rules the control thread applies to a
//! typed request before the cycle sees it (which axes the names mean,
//! unknown names, a gantry homed only whole, one axis to trace), then the
//! cycle's answer per axis, the keeper's part and the log line — one
//! concern per function.

use super::answer::{outcome, reason};
use super::ControlThread;
use super::Unanswered;
use crate::hub::TraceBuf;
use crate::shared::{Ack, Ask, AxisAck};
use motion_control::{Axes, AxisOutcome, ControlResponse, Reason, MAX_AXES, RESULT_ACCEPTED};

impl ControlThread {
    /// Home the named axes (none: the axes "home all" homes) as one sequence.
    pub(super) fn home(
        &mut self,
        axes: &Axes,
        parallel: bool,
        timeout_s: Option<f64>,
        r: &mut ControlResponse,
    ) {
        let Some(mask) = self.axes_of(axes, self.all_mask, r) else {
            return;
        };
        if !self.whole_gantries(mask, r) {
            return;
        }
        let timeout_ns = timeout_s.map_or(0, |t| (t * 1e9) as u64);
        let ack = self.ask(Ask::Home {
            mask,
            parallel,
            timeout_ns,
        });
        let ack = match ack {
            Ok(a) => a,
            Err(u) => return no_answer(r, u),
        };
        let (all, why) = self.answers(mask, &ack, r);
        self.verdict("home", mask, all, why, r);
    }

    /// Stop the named axes (none: every axis).
    pub(super) fn stop(&mut self, axes: &Axes, r: &mut ControlResponse) {
        let Some(mask) = self.axes_of(axes, self.every_axis(), r) else {
            return;
        };
        let ack = match self.ask(Ask::Stop { mask }) {
            Ok(a) => a,
            Err(u) => return no_answer(r, u),
        };
        let (all, why) = self.answers(mask, &ack, r);
        self.verdict("stop", mask, all, why, r);
    }

    /// Clear HomedStatus of the named axes (none: every axis); the stored
    /// reference of each one cleared is no longer the operator's either.
    pub(super) fn unhome(&mut self, axes: &Axes, r: &mut ControlResponse) {
        let Some(mask) = self.axes_of(axes, self.every_axis(), r) else {
            return;
        };
        let ack = match self.ask(Ask::Unhome { mask }) {
            Ok(a) => a,
            Err(u) => return no_answer(r, u),
        };
        let (all, why) = self.answers(mask, &ack, r);
        for i in 0..self.s.machine.axes.len() {
            if mask & (1 << i) != 0 && ack.axes[i].accepted() {
                self.keeper
                    .unhomed(&self.s.machine, i, "operator unhome (motionctl unhome)");
            }
        }
        self.verdict("unhome", mask, all, why, r);
    }

    /// Record the next homing of exactly one axis (not a gantry, not none).
    pub(super) fn trace(&mut self, axes: &Axes, r: &mut ControlResponse) {
        let Some(mask) = self.axes_of(axes, 0, r) else {
            return;
        };
        if mask.count_ones() != 1 {
            return r.bad_request("trace needs exactly one axis");
        }
        let axis = mask.trailing_zeros() as usize;
        let ack = match self.ask(Ask::Trace { axis }) {
            Ok(a) => a,
            Err(u) => return no_answer(r, u),
        };
        self.hub.lock().trace = TraceBuf {
            axis: Some(axis),
            ..Default::default()
        };
        let (all, why) = self.answers(mask, &ack, r);
        self.verdict("trace", mask, all, why, r);
    }

    /// Every axis of the machine.
    pub(super) fn every_axis(&self) -> u64 {
        (0..self.s.machine.axes.len()).fold(0, |m, i| m | 1u64 << i)
    }

    /// The axes a request names, as a mask: a gantry's name stands for its
    /// sides, no name for `default`. An unknown name refuses the request
    /// (`None`).
    pub(super) fn axes_of(
        &self,
        axes: &Axes,
        default: u64,
        r: &mut ControlResponse,
    ) -> Option<u64> {
        let names = axes.names();
        match self.resolve(names) {
            Ok(0) => Some(default),
            Ok(mask) => Some(mask),
            Err(unknown) => {
                self.refuse_unknown(names, &unknown, r);
                None
            }
        }
    }

    /// Names → a mask (a gantry's name stands for its sides);
    /// `Err(unknown names)`.
    fn resolve(&self, names: &[String]) -> Result<u64, Vec<String>> {
        let m = &self.s.machine;
        let mut mask = 0u64;
        let mut unknown = Vec::new();
        for n in names {
            if let Some(g) = m.gantries.iter().find(|g| &g.name == n) {
                mask = g.axes.iter().fold(mask, |mask, &i| mask | 1 << i);
                continue;
            }
            match m.axis_index(n) {
                Some(i) => mask |= 1 << i,
                None => unknown.push(n.clone()),
            }
        }
        if unknown.is_empty() {
            Ok(mask)
        } else {
            Err(unknown)
        }
    }

    /// Refuses a request with unknown names: each named axis answered, the
    /// unknown ones with their reason, and the machine's axes listed.
    fn refuse_unknown(&self, names: &[String], unknown: &[String], r: &mut ControlResponse) {
        let known: Vec<&str> = (self.s.machine.axes.iter())
            .map(|a| a.name.as_str())
            .collect();
        let shown: Vec<String> = (unknown.iter())
            .map(|u| motion_config::names::shown(u))
            .collect();
        r.refuse(&format!(
            "unknown axis {} (axes: {})",
            shown.join(", "),
            known.join(", ")
        ));
        for n in names {
            let o = if unknown.contains(n) {
                AxisOutcome::Refused(Reason::UnknownAxis)
            } else {
                AxisOutcome::NotStarted
            };
            r.push_answer(n, o);
        }
    }

    /// A gantry is homed (and jogged, moved, streamed, enabled, …) as one
    /// machine axis: all its sides or none. False (and the request refused,
    /// naming the sides) when a gantry is named in part.
    pub(super) fn whole_gantries(&self, mask: u64, r: &mut ControlResponse) -> bool {
        let m = &self.s.machine;
        let named = |i: &usize| mask & (1 << i) != 0;
        let partial: Vec<_> = (m.gantries.iter())
            .filter(|g| {
                let n = g.axes.iter().filter(|i| named(i)).count();
                n > 0 && n < g.axes.len()
            })
            .collect();
        if partial.is_empty() {
            return true;
        }
        let mut why = Vec::new();
        for g in partial {
            for &i in g.axes.iter().filter(|i| named(i)) {
                r.push_answer(&m.axes[i].name, AxisOutcome::Refused(Reason::Gantry));
            }
            let sides: Vec<&str> = g.axes.iter().map(|&i| m.axes[i].name.as_str()).collect();
            let side = (m.axes.iter().enumerate())
                .find(|(i, _)| named(i) && g.axes.contains(i))
                .map_or("an axis", |(_, a)| a.name.as_str());
            why.push(format!(
                "{side} is a side of gantry {} (sides {}): name {} or all its sides (a gantry \
                 is homed, jogged, moved and streamed as one axis)",
                g.name,
                sides.join(", "),
                g.name
            ));
        }
        r.refuse(&why.join("; "));
        false
    }

    /// The cycle's answer for every axis of `mask` into the response, in
    /// config order: whether all were accepted, and why not, in words.
    pub(super) fn answers(
        &self,
        mask: u64,
        ack: &Ack,
        r: &mut ControlResponse,
    ) -> (bool, Vec<String>) {
        let m = &self.s.machine;
        let mut all = true;
        let mut why = Vec::new();
        for (i, a) in m.axes.iter().enumerate() {
            if mask & (1 << i) == 0 || r.axis_count as usize >= MAX_AXES {
                continue;
            }
            let x = ack.axes[i];
            r.push_axis(&a.name, i, outcome(x), ack.op_ids[i]);
            if x.accepted() {
                continue;
            }
            all = false;
            let AxisAck::Refused(refusal) = x else {
                continue;
            };
            let Some(reason) = reason(refusal) else {
                continue;
            };
            let mut w = match reason {
                Reason::Owned => format!(
                    "{}: {} ({})",
                    a.name,
                    reason.text(),
                    self.owners
                        .name_of(self.owner_token(i))
                        .unwrap_or("a program")
                ),
                Reason::IoNotAttached => format!(
                    "{}: its I/O process {} is not attached",
                    a.name, m.ios[a.io].name
                ),
                _ => format!("{}: {}", a.name, reason.text()),
            };
            if let Some((err, exerr)) = reason.codes().filter(|&(err, _)| err != 0) {
                w += &format!(
                    " (ERR {err} EXERR {exerr}: {})",
                    motion_report::codes::explain(err, exerr)
                );
            }
            why.push(w);
        }
        r.cycle = ack.cycle;
        (all, why)
    }

    /// The request's result and message, and its log line.
    pub(super) fn verdict(
        &self,
        what: &str,
        mask: u64,
        all: bool,
        mut why: Vec<String>,
        r: &mut ControlResponse,
    ) {
        if all {
            r.result = RESULT_ACCEPTED;
        } else {
            if why.is_empty() {
                why.push("nothing was started: another named axis was refused".into());
            }
            r.refuse(&why.join("; "));
        }
        let names: Vec<&str> = (self.s.machine.axes.iter().enumerate())
            .filter(|(i, _)| mask & (1 << i) != 0)
            .map(|(_, a)| a.name.as_str())
            .collect();
        if all {
            log::info!("{what} {}: accepted", names.join(" "));
        } else {
            log::warn!("{what} {}: refused: {}", names.join(" "), why.join("; "));
        }
    }
}

/// The cycle did not answer in time.
pub(super) fn no_answer(r: &mut ControlResponse, why: Unanswered) {
    r.refuse(why.text());
}

impl ControlThread {
    /// The owner token of axis `i` in the newest snapshot (0: none).
    fn owner_token(&self, i: usize) -> u64 {
        let hub = self.hub.lock();
        hub.snapshot
            .as_deref()
            .and_then(|s| s.axes.get(i))
            .map_or(0, |a| a.owner)
    }
}
