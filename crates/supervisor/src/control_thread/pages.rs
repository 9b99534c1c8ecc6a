//! The answers that are text: the status report, and the statistics, the
//! trace and the histogram log, served a page at a time. The text of a
//! paged answer is made once, at its first page, and kept for the pages
//! after it.

use super::ControlThread;
use crate::{status_fill, trace_csv};
use motion_config::MachineConfig;
use motion_control::{ControlResponse, Since, StatusFrame};
use motion_report::{Allocations, IoReport, StatsReport};
use std::sync::atomic::Ordering;

/// What a paged text answers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum PageKey {
    Stats(Since),
    Hlog(Since),
    /// The recorded trace (of the named axis, if one is named).
    Trace(Option<String>),
}

impl ControlThread {
    /// The status report (JSON), one page.
    pub(super) fn status(&self, r: &mut ControlResponse) {
        let mut frame = StatusFrame::zeroed();
        {
            let hub = self.hub.lock();
            if let Some(s) = hub.snapshot.as_deref() {
                let uptime = hub.started.elapsed().as_nanos() as u64;
                let notes = self.keeper.notes();
                status_fill::fill(&self.s.machine, s, notes, uptime, &mut frame);
                status_fill::owners(s, |t| self.owners.name_of(t), &mut frame);
                crate::io_child::note_spawns(&hub.spawns, &mut frame);
            }
        }
        let json = serde_json::to_vec(&frame.to_report()).unwrap_or_default();
        r.page(&json, 0);
    }

    /// The page of `key`'s text from `offset`; the text is made anew at
    /// offset 0 (and for another key). `reset`: the "since reset"
    /// statistics start anew after the statistics were taken.
    pub(super) fn paged(
        &mut self,
        key: PageKey,
        reset: bool,
        offset: u64,
        r: &mut ControlResponse,
    ) {
        let cached = matches!(&self.cache, Some((k, _)) if *k == key);
        if offset == 0 || !cached {
            let Some(text) = self.text(&key, r) else {
                return;
            };
            if reset && matches!(key, PageKey::Stats(_)) {
                self.hub.lock().reset();
            }
            self.cache = Some((key, text));
        }
        if let Some((_, text)) = &self.cache {
            if offset > text.len() as u64 {
                return r.bad_request("offset beyond the end");
            }
            r.page(text, offset as usize);
        }
    }

    /// The whole text of `key`; `None` (and the response says why) when
    /// there is none yet.
    fn text(&self, key: &PageKey, r: &mut ControlResponse) -> Option<Vec<u8>> {
        match key {
            PageKey::Stats(since) => {
                Some(serde_json::to_vec(&self.stats(*since == Since::Reset)).unwrap_or_default())
            }
            PageKey::Hlog(since) => {
                let hub = self.hub.lock();
                let from = match since {
                    Since::Reset => hub.reset_interval,
                    Since::Start => 0,
                };
                Some(hub.lines.log(hub.start_time, from))
            }
            PageKey::Trace(axis) => {
                let hub = self.hub.lock();
                let t = &hub.trace;
                let named_ok =
                    (axis.as_deref()).is_none_or(|a| self.s.machine.axis_index(a) == t.axis);
                if t.axis.is_none() || !named_ok {
                    r.not_ready("no trace armed for this axis");
                    return None;
                }
                if !t.complete {
                    r.not_ready(&if t.records.is_empty() {
                        "armed: waiting for the axis to start homing".to_string()
                    } else {
                        format!("recording: {} cycles so far", t.records.len())
                    });
                    return None;
                }
                Some(trace_csv::csv(&t.records).into_bytes())
            }
        }
    }

    fn stats(&self, since_reset: bool) -> StatsReport {
        let hub = self.hub.lock();
        let (h, since, t) = if since_reset {
            (&hub.since_reset, "reset", hub.reset_at)
        } else {
            (&hub.since_start, "start", hub.started)
        };
        let io = hub
            .snapshot
            .as_deref()
            .map(|s| io_reports(&self.s.machine, s))
            .unwrap_or_default();
        StatsReport {
            since: since.into(),
            seconds: t.elapsed().as_secs_f64(),
            latency: h.summary(),
            io,
            allocations: Allocations {
                system_calls_in_cycle: self.shared.system_calls_in_cycle.load(Ordering::Acquire),
                pool_allocs_in_cycle: self.shared.pool_allocs_in_cycle.load(Ordering::Acquire),
            },
            requests_refused: hub.requests_refused,
        }
    }
}

/// Per I/O process, for the reports.
pub fn io_reports(m: &MachineConfig, s: &crate::shared::Snapshot) -> Vec<IoReport> {
    let named = m.ios.iter().zip(&s.ios);
    named
        .map(|(io, x)| IoReport::new(&io.name, x, m.supervisor.cycle_us))
        .collect()
}
