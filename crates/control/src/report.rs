//! Status frames and answers in the reports' words: `status --json` and the
//! rows of `home --json` are made from the status frame, and a refused
//! request's errors from its answer, by both the daemon and its clients,
//! with one function each.

use crate::message::*;
use motion_report::{AxisResult, AxisStatus, ErrorEntry, StatusReport};

impl AxisAnswer {
    /// A refused axis as an error entry: its name, the Home instruction's
    /// codes where it has them, the reason in words.
    pub fn error_entry(&self) -> ErrorEntry {
        ErrorEntry {
            axis: Some(get_str(&self.name)),
            key: None,
            err: (self.err != 0).then_some(self.err),
            exerr: (self.err != 0).then_some(self.exerr),
            message: if matches!(self.reason, REASON_OPERATION | REASON_OWNED) && self.err != 0 {
                format!(
                    "{}: {}",
                    reason_text(self.reason),
                    motion_report::codes::explain(self.err, self.exerr)
                )
            } else {
                reason_text(self.reason).into()
            },
        }
    }
}

impl ControlResponse {
    /// A refused request as errors: `"{what} refused: {message}"`, then the
    /// error entry of every axis answer `which` selects.
    pub fn refusal(&self, what: &str, which: impl Fn(&AxisAnswer) -> bool) -> Vec<ErrorEntry> {
        let mut errors = vec![ErrorEntry::message(format!(
            "{what} refused: {}",
            self.message_text()
        ))];
        errors.extend(
            self.answers()
                .iter()
                .filter(|x| which(x))
                .map(AxisAnswer::error_entry),
        );
        errors
    }
}

fn r6(x: Option<f64>) -> Option<f64> {
    x.map(|v| motion_report::round(v, 6))
}

fn number(x: Option<f64>) -> String {
    x.map_or("?".to_string(), |d| motion_report::round(d, 6).to_string())
}

/// An axis's status entry in the reports' words: what went wrong, the
/// warnings, the row of `home --json`, and how an operation ended (the
/// entry is `motion-status`'s type; these read it through the status
/// table's accessors).
pub trait AxisReport {
    /// What went wrong, in words, if anything (`names`: every axis's name,
    /// to name the axis that aborted this one's sequence).
    fn error_text(&self, names: &[String]) -> Option<String>;
    /// The warnings of the last homing, in words.
    fn warning_texts(&self) -> Vec<String>;
    /// A row of `home --json` (`ios`: every I/O process's name).
    fn to_result(&self, names: &[String], ios: &[String]) -> AxisResult;
    /// A row of `status --json`.
    fn to_status(&self, names: &[String], ios: &[String]) -> AxisStatus;
}

impl AxisReport for AxisStatusEntry {
    fn error_text(&self, names: &[String]) -> Option<String> {
        if self.timed_out() {
            return Some("not homed: the home request's --timeout ran out; stopped".into());
        }
        if self.aborted_by() != NO_AXIS {
            let who = names
                .get(self.aborted_by() as usize)
                .map_or("another axis", String::as_str);
            return Some(if self.er() {
                format!("home sequence aborted because axis {who} failed: stopped")
            } else {
                format!("not homed: the home sequence was aborted because axis {who} failed")
            });
        }
        if self.er() {
            return Some(motion_report::codes::describe(
                self.err(),
                self.exerr(),
                Some(self.feedback_gap_s()),
            ));
        }
        if self.lost_homed() && !self.homed() {
            let gap = self.feedback_gap_s();
            let lost = if gap > 0.0 {
                format!("feedback lost (no valid feedback for {:.1} ms)", gap * 1e3)
            } else {
                "feedback lost".to_string()
            };
            let why = if self.lost_feedback() {
                lost.as_str()
            } else if self.lost_reconnect() {
                "its I/O process reconnected"
            } else {
                "HomedStatus cleared"
            };
            return Some(format!(
                "homed, then lost: {why} at t = {:.3} s after homing ended",
                self.lost_after_s()
            ));
        }
        None
    }

    fn warning_texts(&self) -> Vec<String> {
        let mut w = Vec::new();
        if self.warn_ambiguous_marker() {
            w.push(format!(
                "ambiguous marker: the marker lay {} from the switch edge, closer than \
                 marker_min_distance: another homing may take the marker one revolution away",
                number(self.switch_to_marker())
            ));
        }
        let drift = self.drift().map_or("?".to_string(), |d| format!("{d:+}"));
        if self.warn_drift() {
            w.push(format!(
                "drift: the home event lay {drift} from the median of the recent homings, \
                 beyond drift_limit (switch wear, coupling slip?): see the homing record"
            ));
        }
        if self.warn_switch_drift() {
            w.push(format!(
                "drift: the switch-to-marker distance ({}) differs by more than drift_limit \
                 from the recent homings: the home switch has moved or wears",
                number(self.switch_to_marker())
            ));
        }
        if self.warn_reference_invalidated() {
            w.push(
                "stored reference invalidated: the reason is in the log and the homing record"
                    .into(),
            );
        }
        w
    }

    fn to_result(&self, names: &[String], ios: &[String]) -> AxisResult {
        let done = !self.ip() && (self.dn() || self.er());
        AxisResult {
            name: self.name_text(),
            mode: self.home_mode().into(),
            sequence: self.home_sequence().into(),
            direction: self.home_direction().into(),
            io: ios.get(self.io as usize).cloned().unwrap_or_default(),
            pc: self.pc(),
            er: self.er(),
            err: self.err(),
            exerr: self.exerr(),
            homed: self.homed(),
            event_raw: r6(self.event_raw()),
            final_position: r6(self.position()),
            final_raw: r6(self.raw()),
            duration_s: done.then(|| motion_report::round(self.elapsed_s(), 3)),
            error: self.error_text(names),
            skew: r6(self.skew()),
            warnings: self.warning_texts(),
        }
    }

    fn to_status(&self, names: &[String], ios: &[String]) -> AxisStatus {
        AxisStatus {
            name: self.name_text(),
            io: ios.get(self.io as usize).cloned().unwrap_or_default(),
            phase: self.phase_text(),
            owner: self.owner_text(),
            error: self.error_text(names),
            warnings: self.warning_texts(),
            ..AxisStatus::from_entry(self)
        }
    }
}

impl StatusFrame {
    pub fn axis_names(&self) -> Vec<String> {
        self.axes().iter().map(AxisStatusEntry::name_text).collect()
    }

    pub fn io_names(&self) -> Vec<String> {
        self.ios().iter().map(|i| get_str(&i.name)).collect()
    }

    /// `status --json`.
    pub fn to_report(&self) -> StatusReport {
        let (names, ios) = (self.axis_names(), self.io_names());
        StatusReport {
            cycle: self.cycle,
            cycle_us: self.cycle_us,
            uptime_ms: self.uptime_ns / 1_000_000,
            axes: self
                .axes()
                .iter()
                .map(|a| a.to_status(&names, &ios))
                .collect(),
            io: self.ios().iter().map(IoStatusEntry::to_status).collect(),
            stream: self.stream,
        }
    }
}
