//! The supervised setpoint stream's service, `{prefix}/setpoints`: programs
//! that own axes publish [`SetpointFrame`]s, the supervisor's real-time
//! thread is the only subscriber.
//!
//! # QoS
//!
//! * publish-subscribe, created by the supervisor exclusively in its
//!   private domain (owner-only files: only the daemon's user can open it);
//! * at most [`MAX_SETPOINT_PUBLISHERS`] = 8 publishers (programs, `motionctl
//!   stream`, the Python example), exactly one subscriber (the cycle);
//! * subscriber buffer [`SETPOINT_BUFFER`] = 16 frames, safe overflow on (a
//!   publisher never blocks on the cycle; a burst beyond the buffer drops
//!   the oldest frames), history 0 (a frame from before the subscriber
//!   existed is never acted on).
//!
//! Who may move an axis is decided by the supervisor, not by iceoryx2: a
//! frame counts only with the session key and the owner token the control
//! service handed out for those axes, and a sequence number above the last
//! one (`crates/supervisor/src/core/stream.rs`).
//!
//! # Real-time use
//!
//! [`SetpointSubscriber::drain`] is a bounded loop over `receive()`, which
//! allocates nothing with a stable set of publishers. A publisher joining
//! or leaving makes the next `receive` map or unmap memory: the supervisor
//! calls [`SetpointSubscriber::update_connections`] itself in the cycle
//! that grants a stream, so that cost lands there, once per acquire.

use std::sync::Arc;

use iceoryx2::node::Node;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::{ipc, BackpressureStrategy, PlacementDefault, ServiceName};
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;

use motion_frames::{SetpointAxis, SetpointFrame, MAX_AXES, SETPOINT_LAYOUT};

use crate::domain::Domain;
use crate::error::IpcError;
use crate::names::setpoint_service;

/// Frames queued for the supervisor before the oldest is dropped: sixteen
/// cycles of one program publishing every cycle, or two cycles of all eight.
pub const SETPOINT_BUFFER: usize = 16;
/// Programs that may publish at once.
pub const MAX_SETPOINT_PUBLISHERS: usize = 8;

type Factory = iceoryx2::service::port_factory::publish_subscribe::PortFactory<
    ipc::Service,
    SetpointFrame,
    (),
>;

fn service_name(name: &str) -> Result<ServiceName, IpcError> {
    ServiceName::new(name).map_err(|error| IpcError::ServiceName {
        name: name.to_string(),
        error,
    })
}

/// The supervisor's end: the service (created exclusively) and its one
/// subscriber. Single-threaded: create and use it on the real-time thread.
pub struct SetpointSubscriber {
    subscriber: Subscriber<ipc::Service, SetpointFrame, ()>,
    _service: Factory,
    label: Arc<str>,
}

impl SetpointSubscriber {
    /// Creates `{prefix}/setpoints` exclusively and subscribes to it.
    pub fn create(node: &Node<ipc::Service>, domain: &Domain) -> Result<Self, IpcError> {
        let name = setpoint_service(&domain.prefix);
        let label: Arc<str> = Arc::from(name.as_str());
        let service = node
            .service_builder(&service_name(&name)?)
            .publish_subscribe::<SetpointFrame>()
            .enable_safe_overflow(true)
            .subscriber_max_buffer_size(SETPOINT_BUFFER)
            .subscriber_max_borrowed_samples(1)
            .history_size(0)
            .max_publishers(MAX_SETPOINT_PUBLISHERS)
            .max_subscribers(1)
            .create()
            .map_err(|error| IpcError::CreateTopic {
                service: label.clone(),
                error,
            })?;
        let subscriber = service
            .subscriber_builder()
            .buffer_size(SETPOINT_BUFFER)
            .create()
            .map_err(|error| IpcError::CreateSubscriber {
                service: label.clone(),
                error,
            })?;
        Ok(Self {
            subscriber,
            _service: service,
            label,
        })
    }

    /// Hands every frame waiting (oldest first) to `each`, one sample held
    /// at a time; returns how many. Bounded: at most [`SETPOINT_BUFFER`]
    /// frames (more cannot be queued), so a flooding publisher cannot hold
    /// the cycle. No heap allocation with a stable set of publishers.
    pub fn drain(&mut self, mut each: impl FnMut(&SetpointFrame)) -> Result<usize, IpcError> {
        let mut n = 0;
        while n < SETPOINT_BUFFER {
            match self.subscriber.receive() {
                Ok(Some(sample)) => {
                    each(sample.payload());
                    n += 1;
                }
                Ok(None) => break,
                Err(error) => {
                    return Err(IpcError::Receive {
                        service: self.label.clone(),
                        error,
                    })
                }
            }
        }
        Ok(n)
    }

    /// Maps the memory of publishers that joined (and releases those that
    /// left) now, instead of inside the next `receive`.
    pub fn update_connections(&mut self) -> Result<(), IpcError> {
        self.subscriber
            .update_connections()
            .map_err(|error| IpcError::Connection {
                service: self.label.clone(),
                error,
            })
    }
}

/// A program's end: one publisher on `{prefix}/setpoints`, stamping layout,
/// session, key and an increasing sequence number into every frame.
pub struct SetpointPublisher {
    publisher: Publisher<ipc::Service, SetpointFrame, ()>,
    _service: Factory,
    label: Arc<str>,
    key: [u64; 2],
    session: u32,
    seq: u64,
}

impl SetpointPublisher {
    /// Opens the supervisor's setpoint service with `node` (a node of its
    /// domain; its id is what the stream-acquire request names, so the
    /// supervisor can tell when this program is gone).
    pub fn open(node: &Node<ipc::Service>, domain: &Domain) -> Result<Self, IpcError> {
        let name = setpoint_service(&domain.prefix);
        let label: Arc<str> = Arc::from(name.as_str());
        let service = node
            .service_builder(&service_name(&name)?)
            .publish_subscribe::<SetpointFrame>()
            .open()
            .map_err(|error| match error {
                PublishSubscribeOpenError::IncompatibleTypes => IpcError::LayoutMismatch {
                    service: label.clone(),
                },
                PublishSubscribeOpenError::VersionMismatch => IpcError::IceoryxVersionMismatch {
                    service: label.clone(),
                },
                error => IpcError::OpenTopic {
                    service: label.clone(),
                    error,
                },
            })?;
        let publisher = service
            .publisher_builder()
            .max_loaned_samples(1)
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .create()
            .map_err(|error| IpcError::CreatePublisher {
                service: label.clone(),
                error,
            })?;
        Ok(Self {
            publisher,
            _service: service,
            label,
            key: domain.key,
            session: u32::from_str_radix(&domain.id, 16).unwrap_or(0),
            seq: 0,
        })
    }

    /// Publishes one frame for owner `token` at the program's time `t_ns`:
    /// `fill` writes the entries and returns how many it wrote (at most
    /// [`MAX_AXES`]). Returns the frame's sequence number.
    pub fn publish(
        &mut self,
        token: u64,
        t_ns: u64,
        fill: impl FnOnce(&mut [SetpointAxis; MAX_AXES]) -> usize,
    ) -> Result<u64, IpcError> {
        self.seq += 1;
        let (seq, session, key) = (self.seq, self.session, self.key);
        self.publish_raw(|f| {
            f.count = fill(&mut f.axes).min(MAX_AXES) as u32;
            f.layout_version = SETPOINT_LAYOUT;
            f.session = session;
            f.key = key;
            f.token = token;
            f.seq = seq;
            f.t_ns = t_ns;
        })?;
        Ok(seq)
    }

    /// Publishes a frame exactly as `fill` writes it (on an all-zero frame;
    /// nothing stamped): for tests and tools that must send what a broken or
    /// hostile program would (replayed sequence numbers, another key).
    pub fn publish_raw(&mut self, fill: impl FnOnce(&mut SetpointFrame)) -> Result<(), IpcError> {
        let mut uninit = self
            .publisher
            .loan_uninit()
            .map_err(|error| IpcError::Loan {
                service: self.label.clone(),
                error,
            })?;
        // SAFETY: as in `publish`.
        let mut sample = unsafe {
            SetpointFrame::placement_default(uninit.payload_mut().as_mut_ptr());
            uninit.assume_init()
        };
        fill(sample.payload_mut());
        sample.send().map_err(|error| IpcError::Send {
            service: self.label.clone(),
            error,
        })?;
        Ok(())
    }

    /// The service's name.
    pub fn service(&self) -> &str {
        &self.label
    }
}
