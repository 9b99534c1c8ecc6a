//! The control thread: a normal-priority thread of the daemon that serves
//! the control service, publishes the status service at 100 Hz and collects
//! what the real-time thread hands over (snapshots, histograms, trace
//! records, acknowledgements).
//!
//! Requests reach the cycle only through the lock-free control queue, and
//! their answers come back through the acknowledgement queue: the cycle never
//! waits for this thread, and this thread never holds anything the cycle
//! needs. `motion-supervisor home` uses this same path (as a client of the
//! control service), so commissioning and the deployed daemon cannot drift
//! apart.

use crate::hlog::HlogFile;
use crate::hub::{SharedHub, TRACE_MAX};
use crate::keeper::Keeper;
use crate::shared::{Ack, Control, Phase, Shared};
use crate::{status_fill, trace_csv};
use motion_config::MachineConfig;
use motion_control::*;
use motion_ipc::Domain;
use motion_report::{Allocations, IoReport, StatsReport};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Status frames per second.
pub const STATUS_HZ: u64 = 100;
/// How long a request waits for the cycle's answer.
const ACK_TIMEOUT: Duration = Duration::from_secs(1);

pub struct ControlSettings {
    pub machine: MachineConfig,
    pub domain: Domain,
    /// `run --hlog FILE`.
    pub hlog_file: Option<PathBuf>,
    /// Serve the control and status services (false only for the
    /// benchmark that measures what they cost: then the thread just collects
    /// what the cycle hands over).
    pub serve: bool,
}

/// Readiness of the control thread, for start-up.
#[derive(Default)]
pub struct Ready {
    pub ready: AtomicBool,
    pub failed: AtomicBool,
}

pub fn spawn(
    s: ControlSettings,
    shared: Arc<Shared>,
    hub: SharedHub,
    stop: Arc<AtomicBool>,
    ready: Arc<Ready>,
) -> std::io::Result<JoinHandle<()>> {
    std::thread::Builder::new()
        .name("motion-control".into())
        .spawn(move || {
            let serve = s.serve;
            let mut t = ControlThread::new(s, shared, hub);
            if !serve {
                ready.ready.store(true, Ordering::Release);
                while !stop.load(Ordering::Acquire) {
                    t.pump();
                    std::thread::sleep(Duration::from_millis(2));
                }
                t.pump();
                return;
            }
            match Server::create(&t.s.domain) {
                Ok(server) => {
                    ready.ready.store(true, Ordering::Release);
                    t.run(server, &stop);
                }
                Err(e) => {
                    t.hub.lock().control_error = Some(format!("control plane: {e}"));
                    ready.failed.store(true, Ordering::Release);
                    // Keep collecting: the final report still needs the data.
                    while !stop.load(Ordering::Acquire) {
                        t.pump();
                        std::thread::sleep(Duration::from_millis(10));
                    }
                    t.pump();
                }
            }
        })
}

struct ControlThread {
    s: ControlSettings,
    shared: Arc<Shared>,
    hub: SharedHub,
    acks: Vec<Ack>,
    next_id: u32,
    /// The last paged answer: `(kind, flags, axis, text)`.
    cache: Option<(u32, u32, String, Vec<u8>)>,
    hlog: Option<HlogFile>,
    attached: Vec<bool>,
    attachments: Vec<u64>,
    all_mask: u64,
    keeper: Keeper,
}

impl ControlThread {
    fn new(s: ControlSettings, shared: Arc<Shared>, hub: SharedHub) -> Self {
        let start = hub.lock().start_time;
        let hlog = s
            .hlog_file
            .as_ref()
            .and_then(|p| match HlogFile::create(p, start) {
                Ok(f) => Some(f),
                Err(e) => {
                    log::error!("{e}");
                    None
                }
            });
        let orders: Vec<Option<u32>> = s.machine.axes.iter().map(|a| a.home_order).collect();
        let all_mask = crate::core::sequence::Sequencer::new(&orders).all_mask();
        let keeper = Keeper::open(&s.machine);
        Self {
            keeper,
            attached: vec![false; s.machine.ios.len()],
            attachments: vec![0; s.machine.ios.len()],
            s,
            shared,
            hub,
            acks: Vec::new(),
            next_id: 1,
            cache: None,
            hlog,
            all_mask,
        }
    }

    fn run(&mut self, mut server: Server, stop: &AtomicBool) {
        let period = Duration::from_nanos(1_000_000_000 / STATUS_HZ);
        let mut next_status = Instant::now();
        loop {
            self.pump();
            if let Err(e) = server.serve(|req, resp| self.handle(req, resp)) {
                log::warn!("control service: {e}");
            }
            self.hub.lock().requests_refused = server.refused();
            if Instant::now() >= next_status {
                next_status += period;
                if Instant::now() > next_status {
                    next_status = Instant::now() + period;
                }
                self.publish_status(&mut server);
            }
            if stop.load(Ordering::Acquire) {
                self.pump();
                self.publish_status(&mut server);
                return;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn publish_status(&self, server: &mut Server) {
        let hub = self.hub.lock();
        let Some(snap) = hub.snapshot.as_deref() else {
            return;
        };
        let uptime = hub.started.elapsed().as_nanos() as u64;
        let notes = self.keeper.notes();
        if let Err(e) =
            server.publish_status(|f| status_fill::fill(&self.s.machine, snap, notes, uptime, f))
        {
            log::warn!("status service: {e}");
        }
    }

    /// Takes over what the cycle handed over.
    fn pump(&mut self) {
        while let Some(a) = self.shared.acks.pop() {
            self.acks.push(a);
        }
        // The keeper's restore requests are answered here.
        let (keeper, machine) = (&mut self.keeper, &self.s.machine);
        self.acks.retain(|a| !keeper.ack(machine, a));
        // Acks nobody waits for any more.
        if self.acks.len() > 64 {
            self.acks.drain(..self.acks.len() - 64);
        }
        let mut hub = self.hub.lock();
        let hub = &mut *hub;
        self.shared.latest_snapshot(&mut hub.snapshot);
        self.shared.collect_intervals(|h| {
            hub.since_start.merge(h);
            hub.since_reset.merge(h);
            if let Some(lines) = hub.lines.add(h) {
                if let Some(f) = self.hlog.as_mut() {
                    f.write(lines);
                }
            }
        });
        while let Some(r) = self.shared.trace.pop() {
            if hub.trace.axis == Some(usize::from(r.axis)) && !hub.trace.complete {
                if hub.trace.records.len() < TRACE_MAX {
                    hub.trace.records.push(r);
                }
                hub.trace.complete = r.end;
            }
        }
        if let Some(snap) = hub.snapshot.as_deref() {
            let (shared, next_id) = (&self.shared, &mut self.next_id);
            self.keeper.observe(&self.s.machine, snap, |axis, offset| {
                let id = *next_id;
                *next_id = next_id.wrapping_add(1).max(1);
                shared
                    .send(Control::Restore { id, axis, offset })
                    .then_some(id)
            });
            for (k, io) in self.s.machine.ios.iter().enumerate() {
                let now = snap.ios[k].attached;
                // Attachments counted, not just the state seen: a detach and
                // re-attach between two snapshots is reported too.
                let attachments = snap.ios[k].attachments;
                let bounced = now && self.attached[k] && attachments > self.attachments[k];
                self.attachments[k] = attachments;
                if now != self.attached[k] || bounced {
                    self.attached[k] = now;
                    if now {
                        let axes = self.s.machine.axes_of(k);
                        let names: Vec<&str> = axes
                            .iter()
                            .map(|&i| self.s.machine.axes[i].name.as_str())
                            .collect();
                        if snap.ios[k].attachments > 1 {
                            log::warn!(
                                "I/O process {} attached again (attachment {}, restarts {}): \
                                 HomedStatus of {} cleared",
                                io.name,
                                snap.ios[k].attachments,
                                snap.ios[k].restarts,
                                names.join(", ")
                            );
                        } else {
                            log::info!("I/O process {} attached ({})", io.name, names.join(", "));
                        }
                    } else if snap.exiting {
                        log::info!("I/O process {} stopped answering (shutting down)", io.name);
                    } else {
                        log::warn!(
                            "I/O process {} detached: no fresh feedback for {} cycles; its \
                             axes' homing aborts (ERR 12/40)",
                            io.name,
                            snap.ios[k].gap_cycles
                        );
                    }
                }
            }
        }
    }

    /// Sends `c` to the cycle and waits for its answer.
    fn ask(&mut self, make: impl FnOnce(u32) -> Control) -> Option<Ack> {
        let id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1).max(1);
        let c = make(id);
        let until = Instant::now() + ACK_TIMEOUT;
        while !self.shared.send(c) {
            if Instant::now() > until {
                return None;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        loop {
            while let Some(a) = self.shared.acks.pop() {
                self.acks.push(a);
            }
            if let Some(p) = self.acks.iter().position(|a| a.id == id) {
                return Some(self.acks.swap_remove(p));
            }
            if Instant::now() > until || self.shared.phase() != Phase::Running {
                return None;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Names → a mask (a gantry's name stands for its sides);
    /// `Err(unknown names)`.
    fn resolve(&self, names: &[String]) -> Result<u64, Vec<String>> {
        let mut mask = 0u64;
        let mut unknown = Vec::new();
        for n in names {
            if let Some(g) = self.s.machine.gantries.iter().find(|g| &g.name == n) {
                for &i in &g.axes {
                    mask |= 1 << i;
                }
                continue;
            }
            match self.s.machine.axis_index(n) {
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

    fn handle(&mut self, req: &ControlRequest, r: &mut ControlResponse) {
        match req.kind {
            REQ_HOME | REQ_STOP | REQ_UNHOME | REQ_TRACE => self.axes_request(req, r),
            REQ_STATUS => {
                let mut frame = StatusFrame::zeroed();
                {
                    let hub = self.hub.lock();
                    if let Some(s) = hub.snapshot.as_deref() {
                        let uptime = hub.started.elapsed().as_nanos() as u64;
                        let notes = self.keeper.notes();
                        status_fill::fill(&self.s.machine, s, notes, uptime, &mut frame);
                    }
                }
                let json = serde_json::to_vec(&frame.to_report()).unwrap_or_default();
                page(r, &json, 0);
            }
            REQ_STATS | REQ_HLOG | REQ_TRACE_FETCH => self.paged(req, r),
            k => {
                r.result = RESULT_BAD_REQUEST;
                put_str(&mut r.message, &format!("unknown request kind {k}"));
            }
        }
    }

    fn axes_request(&mut self, req: &ControlRequest, r: &mut ControlResponse) {
        let names = req.axis_names();
        let mask = match self.resolve(&names) {
            Ok(0) if req.kind == REQ_HOME => self.all_mask,
            Ok(0) if req.kind == REQ_TRACE => {
                r.result = RESULT_BAD_REQUEST;
                put_str(&mut r.message, "trace needs exactly one axis");
                return;
            }
            Ok(0) => (0..self.s.machine.axes.len()).fold(0, |m, i| m | 1u64 << i),
            Ok(m) => m,
            Err(unknown) => {
                r.result = RESULT_REFUSED;
                let known: Vec<&str> = self
                    .s
                    .machine
                    .axes
                    .iter()
                    .map(|a| a.name.as_str())
                    .collect();
                put_str(
                    &mut r.message,
                    &format!(
                        "unknown axis {} (axes: {})",
                        unknown
                            .iter()
                            .map(|u| motion_config::names::shown(u))
                            .collect::<Vec<_>>()
                            .join(", "),
                        known.join(", ")
                    ),
                );
                let mut k = 0;
                for n in &names {
                    let a = &mut r.axes[k];
                    put_str(&mut a.name, n);
                    if unknown.contains(n) {
                        a.reason = REASON_UNKNOWN_AXIS;
                    }
                    k += 1;
                }
                r.axis_count = k as u32;
                return;
            }
        };
        if req.kind == REQ_HOME {
            // A gantry is homed as one machine axis: all its sides or none.
            let mut partial = Vec::new();
            for g in &self.s.machine.gantries {
                let named = g.axes.iter().filter(|&&i| mask & (1 << i) != 0).count();
                if named > 0 && named < g.axes.len() {
                    partial.push(g);
                }
            }
            if !partial.is_empty() {
                r.result = RESULT_REFUSED;
                let mut k = 0;
                let mut why = Vec::new();
                for g in partial {
                    for &i in &g.axes {
                        if mask & (1 << i) != 0 && k < MAX_AXES {
                            put_str(&mut r.axes[k].name, &self.s.machine.axes[i].name);
                            r.axes[k].reason = REASON_GANTRY;
                            k += 1;
                        }
                    }
                    let sides: Vec<&str> = g
                        .axes
                        .iter()
                        .map(|&i| self.s.machine.axes[i].name.as_str())
                        .collect();
                    why.push(format!(
                        "{} is a side of gantry {} (sides {}): home {} or all its sides",
                        self.s
                            .machine
                            .axes
                            .iter()
                            .enumerate()
                            .find(|(i, _)| mask & (1 << i) != 0 && g.axes.contains(i))
                            .map_or("an axis", |(_, a)| a.name.as_str()),
                        g.name,
                        sides.join(", "),
                        g.name
                    ));
                }
                r.axis_count = k as u32;
                put_str(&mut r.message, &why.join("; "));
                return;
            }
        }
        if req.kind == REQ_TRACE && mask.count_ones() != 1 {
            r.result = RESULT_BAD_REQUEST;
            put_str(&mut r.message, "trace needs exactly one axis");
            return;
        }
        let parallel = req.flags & FLAG_PARALLEL != 0;
        let timeout_ns = if req.timeout_s.is_finite() && req.timeout_s > 0.0 {
            (req.timeout_s.min(86_400.0) * 1e9) as u64
        } else {
            0
        };
        let ack = match req.kind {
            REQ_HOME => self.ask(|id| Control::Home {
                id,
                mask,
                parallel,
                timeout_ns,
            }),
            REQ_STOP => self.ask(|id| Control::Stop { id, mask }),
            REQ_UNHOME => self.ask(|id| Control::Unhome { id, mask }),
            _ => {
                let axis = mask.trailing_zeros() as usize;
                let ack = self.ask(|id| Control::Trace { id, axis });
                if ack.is_some() {
                    let mut hub = self.hub.lock();
                    hub.trace = crate::hub::TraceBuf {
                        axis: Some(axis),
                        ..Default::default()
                    };
                }
                ack
            }
        };
        let Some(ack) = ack else {
            r.result = RESULT_REFUSED;
            put_str(
                &mut r.message,
                "the real-time cycle did not answer (shutting down or stalled)",
            );
            return;
        };
        let mut k = 0;
        let mut why = Vec::new();
        let mut all = true;
        for (i, a) in self.s.machine.axes.iter().enumerate() {
            if mask & (1 << i) == 0 || k >= MAX_AXES {
                continue;
            }
            let x = ack.axes[i];
            let e = &mut r.axes[k];
            put_str(&mut e.name, &a.name);
            e.accepted = u8::from(x.accepted);
            e.reason = x.reason;
            e.err = x.err;
            e.exerr = x.exerr;
            k += 1;
            if !x.accepted {
                all = false;
                if x.reason != REASON_NONE {
                    let mut w = format!("{}: {}", a.name, reason_text(x.reason));
                    if x.reason == REASON_IO_NOT_ATTACHED {
                        w = format!(
                            "{}: its I/O process {} is not attached",
                            a.name, self.s.machine.ios[a.io].name
                        );
                    }
                    if x.err != 0 {
                        w += &format!(
                            " (ERR {} EXERR {}: {})",
                            x.err,
                            x.exerr,
                            motion_report::codes::explain(x.err, x.exerr)
                        );
                    }
                    why.push(w);
                }
            }
        }
        r.axis_count = k as u32;
        r.cycle = ack.cycle;
        if req.kind == REQ_UNHOME {
            for i in 0..self.s.machine.axes.len() {
                if mask & (1 << i) != 0 && ack.axes[i].accepted {
                    self.keeper
                        .unhomed(&self.s.machine, i, "operator unhome (motionctl unhome)");
                }
            }
        }
        r.result = if all { RESULT_ACCEPTED } else { RESULT_REFUSED };
        if !all {
            if why.is_empty() {
                why.push("nothing was started: another named axis was refused".into());
            }
            put_str(&mut r.message, &why.join("; "));
        }
        let what = match req.kind {
            REQ_HOME => "home",
            REQ_STOP => "stop",
            REQ_UNHOME => "unhome",
            _ => "trace",
        };
        let names: Vec<&str> = self
            .s
            .machine
            .axes
            .iter()
            .enumerate()
            .filter(|(i, _)| mask & (1 << i) != 0)
            .map(|(_, a)| a.name.as_str())
            .collect();
        if all {
            log::info!("{what} {}: accepted", names.join(" "));
        } else {
            log::warn!("{what} {}: refused: {}", names.join(" "), why.join("; "));
        }
    }

    fn paged(&mut self, req: &ControlRequest, r: &mut ControlResponse) {
        let axis = req.axis_names().first().cloned().unwrap_or_default();
        let cached = matches!(&self.cache, Some((k, f, a, _)) if *k == req.kind && *f == req.flags & !FLAG_RESET && *a == axis);
        if req.offset == 0 || !cached {
            let text = match req.kind {
                REQ_STATS => serde_json::to_vec(&self.stats(req.flags & FLAG_SINCE_RESET != 0))
                    .unwrap_or_default(),
                REQ_HLOG => {
                    let hub = self.hub.lock();
                    let from = if req.flags & FLAG_SINCE_RESET != 0 {
                        hub.reset_interval
                    } else {
                        0
                    };
                    hub.lines.log(hub.start_time, from)
                }
                _ => {
                    let hub = self.hub.lock();
                    let t = &hub.trace;
                    let named_ok = axis.is_empty() || self.s.machine.axis_index(&axis) == t.axis;
                    if t.axis.is_none() || !named_ok {
                        r.result = RESULT_NOT_READY;
                        put_str(&mut r.message, "no trace armed for this axis");
                        return;
                    }
                    if !t.complete {
                        r.result = RESULT_NOT_READY;
                        put_str(
                            &mut r.message,
                            &if t.records.is_empty() {
                                "armed: waiting for the axis to start homing".to_string()
                            } else {
                                format!("recording: {} cycles so far", t.records.len())
                            },
                        );
                        return;
                    }
                    trace_csv::csv(&t.records).into_bytes()
                }
            };
            if req.kind == REQ_STATS && req.flags & FLAG_RESET != 0 {
                self.hub.lock().reset();
            }
            self.cache = Some((req.kind, req.flags & !FLAG_RESET, axis, text));
        }
        if let Some((_, _, _, text)) = &self.cache {
            if req.offset > text.len() as u64 {
                r.result = RESULT_BAD_REQUEST;
                put_str(&mut r.message, "offset beyond the end");
                return;
            }
            page(r, text, req.offset as usize);
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

/// One page of `text` from `offset` into the response.
fn page(r: &mut ControlResponse, text: &[u8], offset: usize) {
    let end = (offset + DATA_LEN).min(text.len());
    let chunk = &text[offset.min(end)..end];
    r.data[..chunk.len()].copy_from_slice(chunk);
    r.data_len = chunk.len() as u32;
    r.offset = offset as u64;
    r.total = text.len() as u64;
    r.result = RESULT_ACCEPTED;
}

/// Per I/O process, for the reports.
pub fn io_reports(m: &MachineConfig, s: &crate::shared::Snapshot) -> Vec<IoReport> {
    let cycle_ms = f64::from(m.supervisor.cycle_us) / 1000.0;
    m.ios
        .iter()
        .enumerate()
        .map(|(k, io)| {
            let x = s.ios[k];
            IoReport {
                name: io.name.clone(),
                attached: x.attached,
                frames_received: x.frames_received,
                frames_missing: x.frames_missing,
                frames_refused: x.frames_refused,
                frames_too_old: x.frames_too_old,
                attachments: x.attachments,
                longest_gap_ms: x.gaps.longest_cycles as f64 * cycle_ms,
                gaps: x.gaps,
            }
        })
        .collect()
}
