//! A client of a running supervisor: `motionctl` uses it, and so can any Rust
//! HMI. It joins the supervisor's domain through the session file (so it only
//! ever talks to the supervisor that runs under the prefix now), sends
//! requests with the session key, and checks that every answer and status
//! frame carries that supervisor's session id.

use std::path::Path;
use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::port::client::Client as IoxClient;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{ipc, ServiceName};
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;
use iceoryx2::service::builder::request_response::RequestResponseOpenError;
use motion_ipc::names::{control_service, status_service};
use motion_ipc::{Domain, IpcError};

use crate::message::*;
use crate::request::Request;

#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// No supervisor runs under the prefix (or it is still starting).
    #[error("{0}")]
    NoSupervisor(String),
    #[error(transparent)]
    Ipc(IpcError),
    #[error("control plane service '{service}': {detail}")]
    Service { service: String, detail: String },
    /// No answer in time.
    #[error("no answer from the supervisor (pid {pid}) within {after:?} ({what})")]
    Timeout {
        what: &'static str,
        after: Duration,
        pid: u32,
    },
    /// An answer of another supervisor session (a restart in between?).
    #[error("an answer of another supervisor session arrived (the supervisor was restarted?)")]
    WrongSession,
}

impl From<IpcError> for ClientError {
    fn from(e: IpcError) -> Self {
        match e {
            IpcError::NoSupervisor(m) => ClientError::NoSupervisor(m),
            e => ClientError::Ipc(e),
        }
    }
}

type RrClient = IoxClient<ipc::Service, ControlRequest, (), ControlResponse, ()>;

pub struct Client {
    // Ports before the node: dropped first.
    control: RrClient,
    status: Subscriber<ipc::Service, StatusFrame, ()>,
    _node: Node<ipc::Service>,
    domain: Domain,
    session: u32,
    next_id: u64,
    // Last: runs after the node is gone.
    _tidy: Tidy,
}

/// Tidies the domain when the client goes: a client that outlives the
/// supervisor (an HMI's `status --watch`) is the domain's last node, and
/// iceoryx2 leaves the domain's node counter in `/dev/shm` behind it.
/// [`motion_ipc::cleanup_domain`] removes it only when no live node
/// remains, so with the supervisor running it changes nothing.
struct Tidy(Domain);

impl Drop for Tidy {
    fn drop(&mut self) {
        let _ = motion_ipc::cleanup_domain(&self.0);
    }
}

impl Client {
    /// Joins the supervisor running with `prefix`. Fails fast (milliseconds)
    /// with [`ClientError::NoSupervisor`] when there is none.
    pub fn connect(prefix: &str, runtime_dir: Option<&Path>) -> Result<Client, ClientError> {
        let domain = Domain::join(prefix, runtime_dir)?;
        let node = domain.create_node("motionctl")?;
        let cname = control_service(prefix);
        let sname = status_service(prefix);
        let not_ready = |what: &str| {
            ClientError::NoSupervisor(format!(
                "the motion-supervisor with service prefix {prefix:?} (pid {}) has no {what} \
                 service yet (still starting?)",
                domain.pid
            ))
        };
        let rr = node
            .service_builder(&ServiceName::new(&cname).map_err(|e| svc_err(&cname, e))?)
            .request_response::<ControlRequest, ControlResponse>()
            .open()
            .map_err(|e| match e {
                RequestResponseOpenError::DoesNotExist => not_ready("control"),
                e => svc_err(&cname, e),
            })?;
        let control = rr
            .client_builder()
            .create()
            .map_err(|e| svc_err(&cname, e))?;
        let st = node
            .service_builder(&ServiceName::new(&sname).map_err(|e| svc_err(&sname, e))?)
            .publish_subscribe::<StatusFrame>()
            .open()
            .map_err(|e| match e {
                PublishSubscribeOpenError::DoesNotExist => not_ready("status"),
                e => svc_err(&sname, e),
            })?;
        let status = st
            .subscriber_builder()
            .create()
            .map_err(|e| svc_err(&sname, e))?;
        let session = u32::from_str_radix(&domain.id, 16).unwrap_or(0);
        Ok(Client {
            control,
            status,
            _node: node,
            _tidy: Tidy(domain.clone()),
            domain,
            session,
            next_id: 1,
        })
    }

    pub fn domain(&self) -> &Domain {
        &self.domain
    }

    /// Sends `req` (its layout, key and request id are set here) and waits up
    /// to `timeout` for the answer.
    pub fn call(
        &mut self,
        req: &ControlRequest,
        timeout: Duration,
    ) -> Result<Box<ControlResponse>, ClientError> {
        let mut r = *req;
        r.layout_version = CONTROL_LAYOUT;
        r.key = self.domain.key;
        r.request_id = self.next_id;
        self.next_id += 1;
        let pending = self
            .control
            .send_copy(r)
            .map_err(|e| svc_err("control", e))?;
        let until = Instant::now() + timeout;
        loop {
            if let Some(resp) = pending.receive().map_err(|e| svc_err("control", e))? {
                let p = resp.payload();
                if p.session != self.session {
                    return Err(ClientError::WrongSession);
                }
                if p.request_id == r.request_id {
                    return Ok(Box::new(*p));
                }
            }
            if Instant::now() >= until {
                return Err(ClientError::Timeout {
                    what: "control request",
                    after: timeout,
                    pid: self.domain.pid,
                });
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Sends a typed request and waits up to `timeout` for the answer.
    pub fn send(
        &mut self,
        req: &Request,
        timeout: Duration,
    ) -> Result<Box<ControlResponse>, ClientError> {
        let m = req.encode().ok_or_else(too_many_names)?;
        self.call(&m, timeout)
    }

    /// A request of `kind` for `axes` (empty: every axis).
    pub fn simple(
        &mut self,
        kind: u32,
        flags: u32,
        axes: &[String],
        timeout: Duration,
    ) -> Result<Box<ControlResponse>, ClientError> {
        let mut req = ControlRequest::zeroed();
        req.kind = kind;
        req.flags = flags;
        if !req.set_axes(axes) {
            return Err(too_many_names());
        }
        self.call(&req, timeout)
    }

    /// Fetches every page of a paged answer (`REQ_STATS`, `REQ_TRACE_FETCH`,
    /// `REQ_HLOG`) and returns the whole data and the last response.
    pub fn fetch(
        &mut self,
        kind: u32,
        flags: u32,
        axes: &[String],
        timeout: Duration,
    ) -> Result<(Vec<u8>, Box<ControlResponse>), ClientError> {
        let mut data = Vec::new();
        let mut req = ControlRequest::zeroed();
        req.kind = kind;
        req.flags = flags;
        req.set_axes(axes);
        // Bounded: 64 MB of pages at most.
        for _ in 0..2048 {
            req.offset = data.len() as u64;
            let resp = self.call(&req, timeout)?;
            if resp.result != RESULT_ACCEPTED {
                return Ok((data, resp));
            }
            data.extend_from_slice(resp.data_bytes());
            if data.len() as u64 >= resp.total || resp.data_len == 0 {
                return Ok((data, resp));
            }
            // Only the first page may reset.
            req.flags &= !FLAG_RESET;
        }
        Err(ClientError::Service {
            service: "control".into(),
            detail: "answer too large".into(),
        })
    }

    /// The newest status frame; waits up to `timeout` for one.
    pub fn status(&mut self, timeout: Duration) -> Result<Box<StatusFrame>, ClientError> {
        let until = Instant::now() + timeout;
        loop {
            let mut newest: Option<Box<StatusFrame>> = None;
            // Bounded by the subscriber's buffer.
            for _ in 0..16 {
                match self.status.receive().map_err(|e| svc_err("status", e))? {
                    Some(s) => newest = Some(Box::new(*s.payload())),
                    None => break,
                }
            }
            if let Some(s) = newest {
                if s.session != self.session {
                    return Err(ClientError::WrongSession);
                }
                return Ok(s);
            }
            if Instant::now() >= until {
                return Err(ClientError::Timeout {
                    what: "status frame",
                    after: timeout,
                    pid: self.domain.pid,
                });
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}

/// A request naming more axes, or longer names, than a message carries.
pub(crate) fn too_many_names() -> ClientError {
    ClientError::Service {
        service: "control".into(),
        detail: format!("at most {MAX_AXES} axis names of at most {NAME_LEN} bytes"),
    }
}

fn svc_err(service: &str, e: impl std::fmt::Debug) -> ClientError {
    ClientError::Service {
        service: service.to_string(),
        detail: format!("iceoryx2: {e:?}"),
    }
}
