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
//!
//! A request is decoded once, at the edge, into a [`Request`]; the rules
//! are applied to that enum, one concern per function:
//!
//! * `axes.rs` — home, stop, unhome, trace: names → axes, the gantry rule,
//!   the cycle's answer per axis, the keeper, the log line;
//! * `ops.rs` — enable, disable, reset, jog (and its renewals), move, the
//!   setpoint stream's acquire and release; `owners.rs` — the programs
//!   that own axes and whether their nodes are alive (every 100 ms);
//! * `pages.rs` — status, statistics, trace and histogram log, paged;
//! * `answer.rs` — the cycle's answers (domain words) as the wire's reasons;
//! * `pump.rs` — what the cycle hands over (snapshots, histograms, trace
//!   records, acknowledgements) and the keeper's and I/O processes' news;
//!   `trips.rs` — the cycle monitor's trips in the log.

pub(crate) mod answer;
mod axes;
mod ops;
mod owners;
mod pages;
mod pump;
mod trips;

pub use pages::io_reports;

use crate::hlog::HlogFile;
use crate::hub::SharedHub;
use crate::keeper::Keeper;
use crate::shared::{Ack, Ask, Control, Phase, Shared};
use crate::status_fill;
use motion_config::MachineConfig;
use motion_control::{ControlRequest, ControlResponse, Request, Server};
use motion_ipc::Domain;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Status frames per second.
pub const STATUS_HZ: u64 = 100;
/// How long a request waits for the cycle to take it: its deadline.
const ACK_TIMEOUT: Duration = Duration::from_secs(1);
/// How long an answer is awaited once the cycle has taken the request (it
/// comes within a cycle of the real-time thread running on; this bounds a
/// thread that stopped for good).
const TAKEN_TIMEOUT: Duration = Duration::from_secs(10);

/// Why a request has no answer from the cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Unanswered {
    /// The cycle did not take it by its deadline: it never will, nothing
    /// was applied.
    NotApplied,
    /// The cycle took it but has not answered (stopped since): its effect
    /// is unknown.
    Unknown,
}

impl Unanswered {
    /// What the client is told: true either way.
    pub(crate) fn text(self) -> &'static str {
        match self {
            Unanswered::NotApplied => {
                "the real-time cycle did not take the request within 1 s (stalled or shutting \
                 down): nothing was applied"
            }
            Unanswered::Unknown => {
                "the real-time cycle took the request but stopped before answering: see the \
                 status for its effect"
            }
        }
    }
}

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
    /// The last paged answer, and what it answers.
    cache: Option<(pages::PageKey, Vec<u8>)>,
    hlog: Option<HlogFile>,
    ios: pump::IoWatch,
    trips: trips::TripWatch,
    all_mask: u64,
    keeper: Keeper,
    owners: owners::Owners,
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
        let owners = owners::Owners::new(s.domain.iceoryx2_config().ok());
        Self {
            keeper,
            owners,
            ios: pump::IoWatch::new(s.machine.ios.len()),
            trips: trips::TripWatch::new(s.machine.axes.len()),
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
            self.check_owners();
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
        let owners = &self.owners;
        if let Err(e) = server.publish_status(|f| {
            status_fill::fill(&self.s.machine, snap, notes, uptime, f);
            status_fill::owners(snap, |t| owners.name_of(t), f);
            crate::io_child::note_spawns(&hub.spawns, f);
        }) {
            log::warn!("status service: {e}");
        }
    }

    /// Sends `ask` to the cycle with a deadline [`ACK_TIMEOUT`] from now
    /// and waits for its answer. Past the deadline the request is given up
    /// on through the gate: the cycle never applies it after that, and the
    /// client is told nothing was applied — unless the cycle took it first,
    /// whose answer is then awaited.
    fn ask(&mut self, ask: Ask) -> Result<Ack, Unanswered> {
        let id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1).max(1);
        let deadline_ns = motion_rt::now_ns().saturating_add(ACK_TIMEOUT.as_nanos() as u64);
        let c = Control {
            id,
            deadline_ns,
            ask,
        };
        self.shared.gate.offer(id);
        let mut sent = false;
        loop {
            sent = sent || self.shared.send(c);
            if sent {
                if let Some(a) = self.ack_of(id) {
                    return if a.expired {
                        Err(Unanswered::NotApplied)
                    } else {
                        Ok(a)
                    };
                }
            }
            let late = motion_rt::now_ns() > deadline_ns;
            if late || self.shared.phase() != Phase::Running {
                if !sent || self.shared.gate.abandon(id) {
                    return Err(Unanswered::NotApplied);
                }
                return self.taken_answer(id);
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// The answer of request `id`, which the cycle has taken: awaited while
    /// the real-time thread runs, at most [`TAKEN_TIMEOUT`].
    fn taken_answer(&mut self, id: u32) -> Result<Ack, Unanswered> {
        let until = Instant::now() + TAKEN_TIMEOUT;
        while Instant::now() < until && self.shared.phase() == Phase::Running {
            if let Some(a) = self.ack_of(id) {
                return if a.expired {
                    Err(Unanswered::NotApplied)
                } else {
                    Ok(a)
                };
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        Err(Unanswered::Unknown)
    }

    /// The cycle's answer to request `id`, if it has come.
    fn ack_of(&mut self, id: u32) -> Option<Ack> {
        while let Some(a) = self.shared.acks.pop() {
            self.acks.push(a);
        }
        let p = self.acks.iter().position(|a| a.id == id)?;
        Some(self.acks.swap_remove(p))
    }

    /// One request from the control service: decoded here, once.
    fn handle(&mut self, req: &ControlRequest, r: &mut ControlResponse) {
        match Request::decode(req) {
            Ok(Request::Home {
                axes,
                parallel,
                timeout_s,
            }) => self.home(&axes, parallel, timeout_s, r),
            Ok(Request::Stop { axes }) => self.stop(&axes, r),
            Ok(Request::Unhome { axes }) => self.unhome(&axes, r),
            Ok(Request::Trace { axes }) => self.trace(&axes, r),
            Ok(Request::Status) => self.status(r),
            Ok(Request::Stats {
                since,
                reset,
                offset,
            }) => self.paged(pages::PageKey::Stats(since), reset, offset, r),
            Ok(Request::Hlog { since, offset }) => {
                self.paged(pages::PageKey::Hlog(since), false, offset, r)
            }
            Ok(Request::TraceFetch { axis, offset }) => {
                self.paged(pages::PageKey::Trace(axis), false, offset, r)
            }
            Ok(Request::Operate { axes, op }) => self.operation(&axes, op, r),
            Ok(Request::JogRenew { axes, token, end }) => self.jog_renew(&axes, token, end, r),
            Ok(Request::StreamAcquire {
                axes,
                owner,
                node_id,
            }) => self.stream_acquire(&axes, &owner, node_id, r),
            Ok(Request::StreamRelease { token }) => self.stream_release(token, r),
            Err(e) => r.bad_request(&e.to_string()),
        }
    }
}
