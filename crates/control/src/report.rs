//! Status frames and answers in the reports' words: `status --json` and the
//! rows of `home --json` are made from the status frame, and a refused
//! request's errors from its answer, by both the daemon and its clients,
//! with one function each.

use crate::message::*;
use motion_homing::{HomeDirection, HomeMode, HomeSequence};
use motion_report::{
    AxisResult, AxisStatus, ErrorEntry, GapCounts, IoStatus, OpReport, StatusReport, StreamIntake,
};

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

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

fn r6(x: Option<f64>) -> Option<f64> {
    x.map(|v| motion_report::round(v, 6))
}

impl AxisStatusEntry {
    pub fn has(&self, bit: u16) -> bool {
        self.bits & bit != 0
    }

    /// What went wrong, in words, if anything (`names`: every axis's name,
    /// to name the axis that aborted this one's sequence).
    pub fn error_text(&self, names: &[String]) -> Option<String> {
        if self.extra & SX_TIMED_OUT != 0 {
            return Some("not homed: the home request's --timeout ran out; stopped".into());
        }
        if self.aborted_by != NO_AXIS {
            let who = names
                .get(self.aborted_by as usize)
                .map_or("another axis", String::as_str);
            return Some(if self.has(ST_ER) {
                format!("home sequence aborted because axis {who} failed: stopped")
            } else {
                format!("not homed: the home sequence was aborted because axis {who} failed")
            });
        }
        if self.has(ST_ER) {
            return Some(motion_report::codes::describe(
                self.err,
                self.exerr,
                Some(self.feedback_gap_s),
            ));
        }
        if self.extra & SX_LOST_HOMED != 0 && !self.has(ST_HOMED) {
            let lost = if self.feedback_gap_s > 0.0 {
                format!(
                    "feedback lost (no valid feedback for {:.1} ms)",
                    self.feedback_gap_s * 1e3
                )
            } else {
                "feedback lost".to_string()
            };
            let why = if self.extra & SX_LOST_FEEDBACK != 0 {
                lost.as_str()
            } else if self.extra & SX_LOST_RECONNECT != 0 {
                "its I/O process reconnected"
            } else {
                "HomedStatus cleared"
            };
            return Some(format!(
                "homed, then lost: {why} at t = {:.3} s after homing ended",
                self.lost_after_s
            ));
        }
        None
    }

    /// The warnings of the last homing, in words.
    pub fn warning_texts(&self) -> Vec<String> {
        let mut w = Vec::new();
        if self.warnings & W_AMBIGUOUS_MARKER != 0 {
            w.push(format!(
                "ambiguous marker: the marker lay {} from the switch edge, closer than \
                 marker_min_distance: another homing may take the marker one revolution away",
                finite(self.switch_to_marker)
                    .map_or("?".to_string(), |d| motion_report::round(d, 6).to_string())
            ));
        }
        let drift = finite(self.drift).map_or("?".to_string(), |d| format!("{d:+}"));
        if self.warnings & W_DRIFT != 0 {
            w.push(format!(
                "drift: the home event lay {drift} from the median of the recent homings, \
                 beyond drift_limit (switch wear, coupling slip?): see the homing record"
            ));
        }
        if self.warnings & W_SWITCH_DRIFT != 0 {
            w.push(format!(
                "drift: the switch-to-marker distance ({}) differs by more than drift_limit \
                 from the recent homings: the home switch has moved or wears",
                finite(self.switch_to_marker)
                    .map_or("?".to_string(), |d| motion_report::round(d, 6).to_string())
            ));
        }
        if self.warnings & W_REFERENCE_INVALIDATED != 0 {
            w.push(
                "stored reference invalidated: the reason is in the log and the homing record"
                    .into(),
            );
        }
        w
    }

    /// A row of `home --json`.
    pub fn to_result(&self, names: &[String], ios: &[String]) -> AxisResult {
        let done = !self.has(ST_IP) && (self.has(ST_DN) || self.has(ST_ER));
        AxisResult {
            name: get_str(&self.name),
            mode: HomeMode::from_number(self.home_mode)
                .map_or("?", HomeMode::name)
                .into(),
            sequence: HomeSequence::from_number(self.home_sequence)
                .map_or("?", HomeSequence::name)
                .into(),
            direction: HomeDirection::from_number(self.home_direction)
                .map_or("?", HomeDirection::name)
                .into(),
            io: ios.get(self.io as usize).cloned().unwrap_or_default(),
            pc: self.has(ST_PC),
            er: self.has(ST_ER),
            err: self.err,
            exerr: self.exerr,
            homed: self.has(ST_HOMED),
            event_raw: r6(self
                .has(ST_EVENT)
                .then_some(self.event_raw)
                .and_then(finite)),
            final_position: r6(self
                .has(ST_FEEDBACK)
                .then_some(self.position)
                .and_then(finite)),
            final_raw: r6(self.has(ST_FEEDBACK).then_some(self.raw).and_then(finite)),
            duration_s: done.then(|| motion_report::round(self.elapsed_s, 3)),
            error: self.error_text(names),
            skew: finite(self.skew).map(|x| motion_report::round(x, 6)),
            warnings: self.warning_texts(),
        }
    }
}

impl StatusFrame {
    pub fn axis_names(&self) -> Vec<String> {
        self.axes().iter().map(|a| get_str(&a.name)).collect()
    }

    pub fn io_names(&self) -> Vec<String> {
        self.ios().iter().map(|i| get_str(&i.name)).collect()
    }

    /// `status --json`.
    pub fn to_report(&self) -> StatusReport {
        let names = self.axis_names();
        let ios = self.io_names();
        StatusReport {
            cycle: self.cycle,
            cycle_us: self.cycle_us,
            uptime_ms: self.uptime_ns / 1_000_000,
            axes: self
                .axes()
                .iter()
                .map(|a| {
                    let fb = a.has(ST_FEEDBACK);
                    let val = |x: f64| r6(fb.then_some(x).and_then(finite));
                    AxisStatus {
                        name: get_str(&a.name),
                        io: ios.get(a.io as usize).cloned().unwrap_or_default(),
                        phase: get_str(&a.phase),
                        homing: a.has(ST_HOMING),
                        homed: a.has(ST_HOMED),
                        en: a.has(ST_EN),
                        dn: a.has(ST_DN),
                        er: a.has(ST_ER),
                        ip: a.has(ST_IP),
                        pc: a.has(ST_PC),
                        err: a.err,
                        exerr: a.exerr,
                        position: val(a.position),
                        raw: val(a.raw),
                        velocity: val(a.velocity),
                        torque: val(a.torque),
                        switch: a.has(ST_SWITCH),
                        marker: a.has(ST_MARKER),
                        event_raw: r6(a.has(ST_EVENT).then_some(a.event_raw).and_then(finite)),
                        elapsed_s: motion_report::round(a.elapsed_s, 3),
                        timeout_s: a.timeout_s,
                        search_travel: motion_report::round(a.search_travel, 6),
                        search_limit: (a.search_limit > 0.0)
                            .then(|| motion_report::round(a.search_limit, 6)),
                        enabled: a.has(ST_ENABLED),
                        fault: a.has(ST_FAULT),
                        drive_error_code: a.drive_error_code,
                        skew: finite(a.skew).map(|x| motion_report::round(x, 6)),
                        restored: a.extra & SX_RESTORED != 0,
                        drive_lost: a.extra & SX_DRIVE_LOST != 0,
                        error: a.error_text(&names),
                        warnings: a.warning_texts(),
                        ..a.motion_report()
                    }
                })
                .collect(),
            io: self
                .ios()
                .iter()
                .map(|i| IoStatus {
                    name: get_str(&i.name),
                    attached: i.attached != 0,
                    frames_received: i.frames_received,
                    frames_missing: i.frames_missing,
                    frames_refused: i.frames_refused,
                    attachments: i.attachments,
                    gaps: GapCounts {
                        one: i.gaps[0],
                        two_to_three: i.gaps[1],
                        four_to_ten: i.gaps[2],
                        over_ten: i.gaps[3],
                        longest_cycles: i.longest_gap_cycles,
                    },
                    gap_cycles: i.gap_cycles,
                    restarts: i.spawn_restarts,
                    retry_in_s: (i.spawn_retry_s > 0.0)
                        .then(|| motion_report::round(f64::from(i.spawn_retry_s), 1)),
                    start_error: Some(get_str(&i.start_error)).filter(|e| !e.is_empty()),
                })
                .collect(),
            stream: self.stream.to_report(),
        }
    }
}

impl StreamStatusEntry {
    /// The intake part of `status --json`.
    pub fn to_report(&self) -> StreamIntake {
        StreamIntake {
            frames: self.frames,
            setpoints: self.setpoints,
            refused_layout: self.refused_layout,
            refused_key: self.refused_key,
            refused_count: self.refused_count,
            refused_token: self.refused_token,
            refused_sequence: self.refused_sequence,
            refused_axis: self.refused_axis,
            acquired: self.acquired,
            owners: self.owners,
        }
    }
}

impl AxisStatusEntry {
    pub fn motion_has(&self, bit: u16) -> bool {
        self.motion & bit != 0
    }

    /// The operation fields of `status --json` (the rest default).
    fn motion_report(&self) -> AxisStatus {
        let owner = get_str(&self.owner);
        AxisStatus {
            servo_action: self.motion_has(MS_SERVO_ACTION),
            jogging: self.motion_has(MS_JOGGING),
            moving: self.motion_has(MS_MOVING),
            streaming: self.motion_has(MS_STREAMING),
            stopping: self.has(ST_STOPPING),
            limit_negative: self.motion_has(MS_LIMIT_NEGATIVE),
            limit_positive: self.motion_has(MS_LIMIT_POSITIVE),
            faulted: self.motion_has(MS_FAULTED),
            owner: (!owner.is_empty()).then_some(owner),
            op: OpReport {
                id: self.op_id,
                kind: crate::names::op_kind(self.op_kind).into(),
                ip: self.op_flags & OP_IP != 0,
                pc: self.op_flags & OP_PC != 0,
                err: self.op_err,
                exerr: self.op_exerr,
            },
            last_stop: crate::names::stop_cause(self.last_stop).into(),
            command: r6((self.motion_has(MS_COMMAND))
                .then_some(self.cmd_position)
                .and_then(finite)),
            ..AxisStatus::default()
        }
    }
}
