//! The daemon's side of the control plane: the control service (request-
//! response) and the status service (publish-subscribe), both created
//! exclusively in the supervisor's domain and used from one normal thread
//! (iceoryx2 `ipc::Service` ports are `!Send`).
//!
//! Off the real-time path by design: iceoryx2's server allocates twice per
//! request and response, and a client joining or leaving makes the next call
//! re-map memory. Neither may happen in the cycle.

use iceoryx2::node::Node;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::server::Server as IoxServer;
use iceoryx2::prelude::{ipc, PlacementDefault, ServiceName};
use motion_ipc::names::{control_service, status_service};
use motion_ipc::{Domain, IpcError};

use crate::message::*;

/// Clients the control service accepts at once (motionctl, HMIs, PLC bridges).
pub const MAX_CLIENTS: usize = 16;
/// Subscribers of the status service.
pub const MAX_STATUS_SUBSCRIBERS: usize = 16;

#[derive(Debug, thiserror::Error)]
pub enum ServerError {
    #[error(transparent)]
    Ipc(#[from] IpcError),
    #[error("control plane service '{service}': {detail}")]
    Service { service: String, detail: String },
}

fn svc_err(service: &str, e: impl std::fmt::Debug) -> ServerError {
    ServerError::Service {
        service: service.to_string(),
        detail: format!("iceoryx2: {e:?}"),
    }
}

type RrServer = IoxServer<ipc::Service, ControlRequest, (), ControlResponse, ()>;

pub struct Server {
    // Ports before the node: dropped first.
    server: RrServer,
    status: Publisher<ipc::Service, StatusFrame, ()>,
    _node: Node<ipc::Service>,
    key: [u64; 2],
    session: u32,
    status_sequence: u64,
    /// Requests refused for a wrong session key or layout.
    refused: u64,
    control_name: String,
}

impl Server {
    /// Creates the node and both services (exclusively: if they exist, some
    /// other process got there first, and the supervisor refuses to start).
    pub fn create(domain: &Domain) -> Result<Server, ServerError> {
        let node = domain.create_node("motion-control")?;
        let control_name = control_service(&domain.prefix);
        let status_name = status_service(&domain.prefix);
        let rr = node
            .service_builder(
                &ServiceName::new(&control_name).map_err(|e| svc_err(&control_name, e))?,
            )
            .request_response::<ControlRequest, ControlResponse>()
            .max_servers(1)
            .max_clients(MAX_CLIENTS)
            .max_active_requests_per_client(2)
            .max_response_buffer_size(2)
            .max_borrowed_responses_per_pending_response(2)
            .enable_fire_and_forget_requests(false)
            .create()
            .map_err(|e| svc_err(&control_name, e))?;
        let server = rr
            .server_builder()
            .max_loaned_responses_per_request(1)
            .create()
            .map_err(|e| svc_err(&control_name, e))?;
        let st = node
            .service_builder(&ServiceName::new(&status_name).map_err(|e| svc_err(&status_name, e))?)
            .publish_subscribe::<StatusFrame>()
            .enable_safe_overflow(true)
            .history_size(1)
            .subscriber_max_buffer_size(2)
            .subscriber_max_borrowed_samples(2)
            .max_publishers(1)
            .max_subscribers(MAX_STATUS_SUBSCRIBERS)
            .create()
            .map_err(|e| svc_err(&status_name, e))?;
        let status = st
            .publisher_builder()
            .max_loaned_samples(1)
            .create()
            .map_err(|e| svc_err(&status_name, e))?;
        Ok(Server {
            server,
            status,
            _node: node,
            key: domain.key,
            session: u32::from_str_radix(&domain.id, 16).unwrap_or(0),
            status_sequence: 0,
            refused: 0,
            control_name,
        })
    }

    /// The session id responses and status frames carry.
    pub fn session(&self) -> u32 {
        self.session
    }

    /// Requests refused for a wrong key or layout since start.
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// Answers every waiting request with `handle`, which fills the response
    /// (it is zeroed, with kind, request id and session set). Requests
    /// without this session's key, or of another layout, are answered
    /// `RESULT_FORBIDDEN` / `RESULT_BAD_REQUEST` without calling `handle`.
    /// Returns the number of requests answered. Never blocks.
    pub fn serve(
        &mut self,
        mut handle: impl FnMut(&ControlRequest, &mut ControlResponse),
    ) -> Result<usize, ServerError> {
        let mut n = 0;
        // Bounded: at most every client's active requests.
        for _ in 0..MAX_CLIENTS * 2 {
            let Some(active) = self
                .server
                .receive()
                .map_err(|e| svc_err(&self.control_name, e))?
            else {
                break;
            };
            let req: ControlRequest = *active.payload();
            let mut uninit = match active.loan_uninit() {
                Ok(u) => u,
                Err(e) => return Err(svc_err(&self.control_name, e)),
            };
            // SAFETY: the loaned payload is a properly aligned, exclusively
            // owned ControlResponse; placement_default writes every field
            // (no implicit padding), so it is initialized before assume_init.
            let mut resp = unsafe {
                ControlResponse::placement_default(uninit.payload_mut().as_mut_ptr());
                uninit.assume_init()
            };
            let r = resp.payload_mut();
            r.layout_version = CONTROL_LAYOUT;
            r.kind = req.kind;
            r.request_id = req.request_id;
            r.session = self.session;
            if req.layout_version != CONTROL_LAYOUT {
                r.result = RESULT_BAD_REQUEST;
                put_str(
                    &mut r.message,
                    &format!(
                        "request layout {} is not this supervisor's {CONTROL_LAYOUT}",
                        req.layout_version
                    ),
                );
                self.refused += 1;
            } else if req.key != self.key {
                r.result = RESULT_FORBIDDEN;
                put_str(
                    &mut r.message,
                    "refused: the request does not carry this supervisor's session key",
                );
                self.refused += 1;
            } else {
                handle(&req, r);
            }
            resp.send().map_err(|e| svc_err(&self.control_name, e))?;
            n += 1;
        }
        Ok(n)
    }

    /// Publishes one status frame filled by `fill` (zeroed first; layout,
    /// session and sequence are set here).
    pub fn publish_status(
        &mut self,
        fill: impl FnOnce(&mut StatusFrame),
    ) -> Result<(), ServerError> {
        let mut uninit = self
            .status
            .loan_uninit()
            .map_err(|e| svc_err("status", e))?;
        // SAFETY: as in `serve`.
        let mut sample = unsafe {
            StatusFrame::placement_default(uninit.payload_mut().as_mut_ptr());
            uninit.assume_init()
        };
        let f = sample.payload_mut();
        fill(f);
        self.status_sequence += 1;
        f.layout_version = CONTROL_LAYOUT;
        f.session = self.session;
        f.sequence = self.status_sequence;
        sample.send().map_err(|e| svc_err("status", e))?;
        Ok(())
    }
}
