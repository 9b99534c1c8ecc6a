//! The operations of a running supervisor as a Rust client calls them:
//! any operation of the engine with its spec ([`Client::operate`]: enable,
//! disable, reset, a move's [`MoveSpec`](crate::MoveSpec) …, exactly as the engine declares
//! them), and the hold-to-run jog ([`Jog`], a handle that renews the jog's
//! lease from a thread of its own and ends the jog when dropped). The
//! setpoint stream is in [`crate::stream`].
//!
//! Every call answers per axis (accepted, or refused with a reason and the
//! instruction's ERR / EXERR): a refusal is an [`OpError::Refused`] with the
//! whole response, so a caller can show each axis's reason.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::client::{Client, ClientError};
use crate::message::*;
use crate::request::{Axes, Request};
use motion_homing::params::JOG_LEASE_S;
use motion_homing::{JogSpec, Operation};

/// How long a request waits for its answer.
const ANSWER: Duration = Duration::from_secs(3);

/// A refused or failed operation.
#[derive(thiserror::Error)]
pub enum OpError {
    #[error(transparent)]
    Client(#[from] ClientError),
    /// The supervisor refused it (for at least one axis: see the answers).
    #[error("refused: {}", .0.message_text())]
    Refused(Box<ControlResponse>),
}

/// Short: the message and each refused axis, not the response's 36 KB.
impl std::fmt::Debug for OpError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OpError::Client(e) => write!(f, "Client({e:?})"),
            OpError::Refused(r) => {
                let axes: Vec<String> = (r.answers().iter())
                    .map(|a| format!("{} {}/{}", get_str(&a.name), a.err, a.exerr))
                    .collect();
                write!(f, "Refused({:?}: {})", r.message_text(), axes.join(", "))
            }
        }
    }
}

/// The response if accepted, else [`OpError::Refused`].
fn accepted(resp: Box<ControlResponse>) -> Result<Box<ControlResponse>, OpError> {
    if resp.result == RESULT_ACCEPTED {
        Ok(resp)
    } else {
        Err(OpError::Refused(resp))
    }
}

/// How many renewals a jog's handle sends per lease: one may be lost (or
/// late on a busy host) four times in a row before the jog stops.
const RENEWALS_PER_LEASE: u32 = 5;

impl Client {
    /// Any operation of the engine for `axes` (empty: every axis for
    /// enable, disable and reset; the others need one); the answers carry
    /// the operation ids to follow ([`crate::follow`]). A jog is better
    /// started with [`Client::jog`], whose handle renews it.
    pub fn operate(
        &mut self,
        axes: &[String],
        op: Operation,
    ) -> Result<Box<ControlResponse>, OpError> {
        let r = Request::Operate {
            axes: Axes::from_names(axes),
            op,
        };
        accepted(self.send(&r, ANSWER)?)
    }

    /// MAS: stop `axes` (empty: every axis).
    pub fn stop(&mut self, axes: &[String]) -> Result<Box<ControlResponse>, OpError> {
        let r = Request::Stop {
            axes: Axes::from_names(axes),
        };
        accepted(self.send(&r, ANSWER)?)
    }

    /// MAJ: start a hold-to-run jog of `axis` (an axis or a gantry). It
    /// runs while the returned [`Jog`] lives (its thread renews the lease
    /// five times per lease); dropping it ends the jog.
    pub fn jog(&mut self, axis: &str, j: JogSpec) -> Result<Jog, OpError> {
        let resp = self.operate(&[axis.to_string()], Operation::Jog(j))?;
        let lease = j.lease.unwrap_or(JOG_LEASE_S);
        let every = Duration::from_secs_f64(lease.clamp(0.05, 5.0)) / RENEWALS_PER_LEASE;
        let domain = self.domain();
        Ok(Jog::start(
            domain.prefix.clone(),
            domain.runtime_dir.clone(),
            resp,
            every,
        ))
    }
}

/// A running hold-to-run jog: a thread renews its lease; [`Jog::end`] (or
/// dropping the handle) ends it — only this jog: if something else already
/// ended it (a stop, a limit, a fault), nothing else is stopped.
pub struct Jog {
    token: u64,
    answer: Box<ControlResponse>,
    stop: Arc<AtomicBool>,
    ended: Arc<AtomicBool>,
    thread: Option<JoinHandle<Option<String>>>,
}

impl Jog {
    fn start(
        prefix: String,
        runtime_dir: PathBuf,
        answer: Box<ControlResponse>,
        every: Duration,
    ) -> Jog {
        let token = answer.token;
        let stop = Arc::new(AtomicBool::new(false));
        let ended = Arc::new(AtomicBool::new(false));
        let (s, e) = (stop.clone(), ended.clone());
        // The renewals need a client of their own: iceoryx2 ports stay on
        // the thread that made them.
        let thread = std::thread::Builder::new()
            .name("jog-renew".into())
            .spawn(move || renew(&prefix, &runtime_dir, token, every, &s, &e))
            .ok();
        if thread.is_none() {
            ended.store(true, Ordering::Release);
        }
        Jog {
            token,
            answer,
            stop,
            ended,
            thread,
        }
    }

    /// The jog's token.
    pub fn token(&self) -> u64 {
        self.token
    }

    /// The supervisor's answer to the jog request (axes, operation ids).
    pub fn answer(&self) -> &ControlResponse {
        &self.answer
    }

    /// A renewal was refused or failed: the jog is over (stopped by
    /// something else, or the supervisor is gone).
    pub fn ended(&self) -> bool {
        self.ended.load(Ordering::Acquire)
    }

    /// Ends the jog (if it still runs) and the renewals; the failure of
    /// the last renewal or of the end request, if any, in words.
    pub fn end(mut self) -> Option<String> {
        self.finish()
    }

    fn finish(&mut self) -> Option<String> {
        self.stop.store(true, Ordering::Release);
        self.thread.take().and_then(|t| t.join().ok().flatten())
    }
}

impl Drop for Jog {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

/// The renewal thread: renews every `every` until told to stop or a
/// renewal is refused, then ends the jog (a renewal with `FLAG_END`: a stop
/// of this jog only). Returns what failed, in words.
fn renew(
    prefix: &str,
    runtime_dir: &std::path::Path,
    token: u64,
    every: Duration,
    stop: &AtomicBool,
    ended: &AtomicBool,
) -> Option<String> {
    let mut client = match Client::connect(prefix, Some(runtime_dir)) {
        Ok(c) => c,
        Err(e) => {
            ended.store(true, Ordering::Release);
            return Some(format!("jog renewal: {e}"));
        }
    };
    let mut problem = None;
    let mut next = Instant::now() + every;
    while !stop.load(Ordering::Acquire) && !ended.load(Ordering::Acquire) {
        let now = Instant::now();
        if now < next {
            std::thread::sleep((next - now).min(Duration::from_millis(10)));
            continue;
        }
        next += every;
        match renewal(&mut client, token, false) {
            Ok(true) => {}
            Ok(false) => ended.store(true, Ordering::Release),
            Err(e) => {
                problem = Some(format!("jog renewal: {e}"));
                ended.store(true, Ordering::Release);
            }
        }
    }
    if !ended.swap(true, Ordering::AcqRel) {
        if let Err(e) = renewal(&mut client, token, true) {
            problem = Some(format!("ending the jog: {e}"));
        }
    }
    problem
}

/// One renewal (or, with `end`, the end) of jog `token`: true while it
/// still runs.
fn renewal(client: &mut Client, token: u64, end: bool) -> Result<bool, ClientError> {
    let r = Request::JogRenew {
        axes: Axes::All,
        token,
        end,
    };
    Ok(client.send(&r, ANSWER)?.result == RESULT_ACCEPTED)
}
