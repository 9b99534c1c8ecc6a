//! The one thread that talks to the daemon, as `motionctl` does (the
//! public client of `motion-control`: session file, key, control and
//! status services). iceoryx2's ports stay on this thread; the OPC UA side
//! reaches it through a channel.
//!
//! Loop (every 2 ms): run the method calls that arrived, renew or end the
//! hold-to-run jogs ([`crate::jogs`]), take the newest status frame, every
//! second the statistics. No frame for a second, or a
//! frame of another session: the daemon is gone or restarted — values go
//! Bad, and it joins again (every 500 ms) when the daemon is back. Nothing
//! here can hold the daemon up: the control service answers from its own
//! thread, off the cycle.

use crate::jogs::{Jogs, Watch};
use crate::methods::{Operation, JOG_RENEW_MS};
use crate::values::Publisher;
use motion_control::{
    put_str, Axes, Client, ClientError, ControlResponse, Request, REQ_STATS, RESULT_ACCEPTED,
};
use motion_report::StatsReport;
use opcua::server::node_manager::memory::InMemoryNodeManagerImpl;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::sync::oneshot;

/// Why a call did not get the daemon's answer.
#[derive(Debug, Clone, PartialEq)]
pub enum BridgeError {
    /// No daemon (or it stopped answering).
    NoDaemon(String),
    /// Anything else the client reported.
    Failed(String),
}

/// A method call for the daemon.
pub struct Job {
    pub op: Operation,
    /// For a Jog: the session that asks (renewals only while it lives).
    pub watch: Option<Watch>,
    pub reply: oneshot::Sender<Result<Box<ControlResponse>, BridgeError>>,
}

/// Where the daemon is.
#[derive(Clone, Debug)]
pub struct Target {
    pub prefix: String,
    pub runtime_dir: Option<PathBuf>,
}

const POLL: Duration = Duration::from_millis(2);
const SILENCE: Duration = Duration::from_secs(1);
const RETRY: Duration = Duration::from_millis(500);
const STATS_EVERY: Duration = Duration::from_secs(1);
const CALL_TIMEOUT: Duration = Duration::from_secs(3);

/// Runs until `stop` is set.
pub fn run<T: InMemoryNodeManagerImpl>(
    target: Target,
    mut publisher: Publisher<T>,
    jobs: Receiver<Job>,
    stop: Arc<AtomicBool>,
) {
    let mut client: Option<Client> = None;
    let mut last_try = Instant::now() - RETRY;
    let mut last_frame = Instant::now();
    let mut last_stats = Instant::now() - STATS_EVERY;
    let mut told_missing = false;
    let mut jogs = Jogs::new(Duration::from_millis(JOG_RENEW_MS));
    while !stop.load(Ordering::Acquire) {
        if client.is_none() && last_try.elapsed() >= RETRY {
            last_try = Instant::now();
            match Client::connect(&target.prefix, target.runtime_dir.as_deref()) {
                Ok(c) => {
                    log::info!(
                        "joined motion-supervisor (pid {}, session {})",
                        c.domain().pid,
                        c.domain().id
                    );
                    client = Some(c);
                    last_frame = Instant::now();
                    told_missing = false;
                }
                Err(e) if !told_missing => {
                    log::warn!("waiting for motion-supervisor: {e}");
                    told_missing = true;
                }
                Err(_) => {}
            }
        }
        while let Ok(job) = jobs.try_recv() {
            let r = match client.as_mut() {
                Some(c) => run_job(c, &mut jogs, job.op, job.watch),
                None => Err(BridgeError::NoDaemon(
                    "motion-supervisor is not running (or not joined yet)".into(),
                )),
            };
            if matches!(r, Err(BridgeError::NoDaemon(_))) && client.is_some() {
                jogs.forget();
                drop_client(&mut client, &mut publisher, "it stopped answering");
            }
            let _ = job.reply.send(r);
        }
        if let Some(c) = client.as_mut() {
            renew_jogs(c, &mut jogs);
        } else {
            jogs.forget();
        }
        if let Some(c) = client.as_mut() {
            match c.status(Duration::ZERO) {
                Ok(f) => {
                    last_frame = Instant::now();
                    publisher.frame(&f);
                }
                Err(ClientError::Timeout { .. }) if last_frame.elapsed() < SILENCE => {}
                Err(ClientError::Timeout { .. }) => {
                    drop_client(&mut client, &mut publisher, "no status for a second")
                }
                Err(e) => drop_client(&mut client, &mut publisher, &e.to_string()),
            }
        }
        if let Some(c) = client.as_mut() {
            if last_stats.elapsed() >= STATS_EVERY {
                last_stats = Instant::now();
                if let Some(r) = stats(c) {
                    publisher.stats(&r);
                }
            }
        }
        std::thread::sleep(POLL);
    }
    if let Some(c) = client.as_mut() {
        for r in jogs.end_all("motion-opcua is stopping") {
            log::info!("jog on axis {} ended: {}", r.axis, r.why);
            let _ = jog_renewal(c, r.token, true);
        }
    }
}

/// A method call: a Jog is started (or extended) and then renewed here.
fn run_job(
    c: &mut Client,
    jogs: &mut Jogs,
    op: Operation,
    watch: Option<Watch>,
) -> Result<Box<ControlResponse>, BridgeError> {
    let (
        Operation::Jog {
            axis,
            speed,
            duration_s,
        },
        Some(watch),
    ) = (&op, watch)
    else {
        return call(c, &op);
    };
    let duration = Duration::from_secs_f64(*duration_s);
    let now = Instant::now();
    if let Some(token) = jogs.extend(axis, *speed, duration, watch.session, now) {
        let mut r = ControlResponse::zeroed();
        r.result = RESULT_ACCEPTED;
        r.axis_count = 1;
        put_str(&mut r.axes[0].name, axis);
        r.axes[0].accepted = 1;
        r.token = token;
        return Ok(r);
    }
    let r = call(c, &op)?;
    if r.result == RESULT_ACCEPTED {
        jogs.started(axis, *speed, duration, r.token, watch, now);
    }
    Ok(r)
}

/// Renews the jogs that may run on, ends the others.
fn renew_jogs(c: &mut Client, jogs: &mut Jogs) {
    if jogs.is_empty() {
        return;
    }
    for r in jogs.due(Instant::now()) {
        let ok = jog_renewal(c, r.token, r.end);
        if r.end {
            log::info!("jog on axis {} ended: {}", r.axis, r.why);
        } else if !ok {
            log::info!("jog on axis {} ended by the supervisor", r.axis);
            jogs.gone(r.token);
        }
    }
}

/// One renewal (or the end) of jog `token`: did the supervisor accept it?
fn jog_renewal(c: &mut Client, token: u64, end: bool) -> bool {
    let req = Request::JogRenew {
        axes: Axes::All,
        token,
        end,
    };
    c.send(&req, CALL_TIMEOUT)
        .is_ok_and(|r| r.result == RESULT_ACCEPTED)
}

fn drop_client<T: InMemoryNodeManagerImpl>(
    client: &mut Option<Client>,
    publisher: &mut Publisher<T>,
    why: &str,
) {
    log::warn!("lost motion-supervisor ({why}): values are BadNoCommunication until it is back");
    *client = None;
    publisher.lost();
}

fn call(c: &mut Client, op: &Operation) -> Result<Box<ControlResponse>, BridgeError> {
    c.call(&op.request(), CALL_TIMEOUT).map_err(|e| match e {
        ClientError::NoSupervisor(_) | ClientError::Timeout { .. } | ClientError::WrongSession => {
            BridgeError::NoDaemon(e.to_string())
        }
        e => BridgeError::Failed(e.to_string()),
    })
}

/// Latency since the daemon started (`motionctl stats --json`).
fn stats(c: &mut Client) -> Option<StatsReport> {
    let (data, resp) = c.fetch(REQ_STATS, 0, &[], CALL_TIMEOUT).ok()?;
    if resp.result != RESULT_ACCEPTED {
        return None;
    }
    serde_json::from_slice(&data).ok()
}

/// The OPC UA side's handle: sends a job and awaits the answer.
#[derive(Clone)]
pub struct Handle {
    pub jobs: Sender<Job>,
}

impl Handle {
    pub async fn run(&self, op: Operation) -> Result<Box<ControlResponse>, BridgeError> {
        self.run_watched(op, None).await
    }

    /// [`Handle::run`] for a Jog, renewed while `watch` says its session
    /// lives.
    pub async fn run_watched(
        &self,
        op: Operation,
        watch: Option<Watch>,
    ) -> Result<Box<ControlResponse>, BridgeError> {
        let (tx, rx) = oneshot::channel();
        self.jobs
            .send(Job {
                op,
                watch,
                reply: tx,
            })
            .map_err(|_| BridgeError::Failed("the daemon thread has ended".into()))?;
        match tokio::time::timeout(CALL_TIMEOUT + Duration::from_secs(2), rx).await {
            Ok(Ok(r)) => r,
            Ok(Err(_)) => Err(BridgeError::Failed("the daemon thread has ended".into())),
            Err(_) => Err(BridgeError::NoDaemon("no answer in time".into())),
        }
    }
}
