//! The one thread that talks to the daemon, as `motionctl` does (the
//! public client of `motion-control`: session file, key, control and
//! status services). iceoryx2's ports stay on this thread; the OPC UA side
//! reaches it through a channel.
//!
//! Loop (every 2 ms): run the method calls that arrived (a Jog call on a
//! jog of its own renews it), end the hold-to-run jogs whose caller may no
//! longer run them ([`crate::jogs`]), take the newest status frame, every
//! second the statistics. No frame for a second, or a
//! frame of another session: the daemon is gone or restarted — values go
//! Bad, and it joins again (every 500 ms) when the daemon is back. Nothing
//! here can hold the daemon up: the control service answers from its own
//! thread, off the cycle.

use crate::jogs::{Jogs, Watch};
use crate::methods::Call;
use crate::values::Publisher;
use motion_control::params::JOG_LEASE_S;
use motion_control::{
    Axes, Client, ClientError, ControlResponse, Operation, Request, REQ_STATS, RESULT_ACCEPTED,
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
    pub call: Call,
    /// For a hold-to-run call: the session that asks, and whether it may
    /// still run the jog.
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
    let mut jogs = Jogs::new();
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
                Some(c) => run_job(c, &mut jogs, job.call, job.watch),
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
            end_jogs(c, &mut jogs);
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

/// A method call. A Jog of a session on a jog of its own (same axis and
/// speed) renews it, answered with the supervisor's answer to the
/// renewal; any other starts a jog (replacing the axis's), kept for its
/// renewals.
fn run_job(
    c: &mut Client,
    jogs: &mut Jogs,
    call: Call,
    watch: Option<Watch>,
) -> Result<Box<ControlResponse>, BridgeError> {
    let (
        Call::Operate {
            axis,
            op: Operation::Jog(jog),
        },
        Some(watch),
    ) = (&call, watch)
    else {
        return send(c, &call.typed());
    };
    let now = Instant::now();
    if let Some(token) = jogs.running(axis, jog.speed, watch.session) {
        let r = send(c, &renewal(token, false))?;
        if r.result == RESULT_ACCEPTED {
            jogs.renewed(token, now);
        } else {
            jogs.gone(token);
        }
        return Ok(r);
    }
    let r = send(c, &call.typed())?;
    if r.result == RESULT_ACCEPTED {
        let lease = Duration::from_secs_f64(jog.lease.unwrap_or(JOG_LEASE_S));
        jogs.started(axis, jog.speed, lease, r.token, watch, now);
    }
    Ok(r)
}

/// Ends the jogs whose caller may no longer run them.
fn end_jogs(c: &mut Client, jogs: &mut Jogs) {
    if jogs.is_empty() {
        return;
    }
    for r in jogs.due(Instant::now()) {
        let _ = jog_renewal(c, r.token, true);
        log::info!("jog on axis {} ended: {}", r.axis, r.why);
    }
}

/// A renewal (or, with `end`, the end) of jog `token`.
fn renewal(token: u64, end: bool) -> Request {
    Request::JogRenew {
        axes: Axes::All,
        token,
        end,
    }
}

/// One renewal (or the end) of jog `token`: did the supervisor accept it?
fn jog_renewal(c: &mut Client, token: u64, end: bool) -> bool {
    send(c, &renewal(token, end)).is_ok_and(|r| r.result == RESULT_ACCEPTED)
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

/// Sends `req`; a daemon that does not answer is [`BridgeError::NoDaemon`].
fn send(c: &mut Client, req: &Request) -> Result<Box<ControlResponse>, BridgeError> {
    c.send(req, CALL_TIMEOUT).map_err(|e| match e {
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
    pub async fn run(&self, call: Call) -> Result<Box<ControlResponse>, BridgeError> {
        self.run_watched(call, None).await
    }

    /// [`Handle::run`] for a hold-to-run call, ended as soon as `watch`
    /// says its caller may no longer run it.
    pub async fn run_watched(
        &self,
        call: Call,
        watch: Option<Watch>,
    ) -> Result<Box<ControlResponse>, BridgeError> {
        let (tx, rx) = oneshot::channel();
        self.jobs
            .send(Job {
                call,
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
