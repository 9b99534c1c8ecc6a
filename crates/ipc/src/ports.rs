//! The frame ports of one I/O process: the supervisor *creates* the four
//! services (exclusively: a service that exists already is refused), the I/O
//! process *opens* them. Both stamp their session key and origin into every
//! frame they publish and refuse received frames without the key.
//!
//! # QoS (identical in both processes, checked by iceoryx2 on open)
//!
//! * safe overflow ON: a full subscriber buffer drops its oldest frame, the
//!   publisher never blocks on a slow or dead peer;
//! * subscriber buffer [`SUBSCRIBER_BUFFER`] = 2, history 0 (an old frame is
//!   never acted on);
//! * one publisher and [`MAX_SUBSCRIBERS`] = 2 subscribers per topic (the
//!   peer plus one observer); one notifier, [`MAX_LISTENERS`] = 2 listeners.
//!   Only processes of the supervisor's user can open the services at all
//!   (owner-only files in a private domain, see [`crate::domain`]).
//!
//! # Real-time use
//!
//! Create everything at start-up, outside the cycle. In the cycle only
//! [`Ports::publish`], [`Ports::notify`], [`Ports::receive_latest`] and
//! [`Ports::try_wait`] are used; with a stable set of peers they allocate
//! nothing except the one reference-count block iceoryx2 makes per loaned
//! sample (see `tests/roundtrip.rs`, which counts them). When a peer joins or
//! leaves, the next send/receive/notify re-maps memory and may allocate.

use std::fmt;
use std::sync::Arc;
use std::time::Duration;

use iceoryx2::node::Node;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::{ipc, BackpressureStrategy, PlacementDefault, ServiceName, ZeroCopySend};
use iceoryx2::sample::Sample;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;
use iceoryx2::service::builder::{event, publish_subscribe};

use motion_frames::{CommandFrame, FeedbackFrame, Frame, LAYOUT_VERSION};

use crate::domain::Domain;
use crate::error::IpcError;
use crate::monotonic_ns;
use crate::names::IoServiceNames;
use crate::wait::{ppoll_until, PollWake};

/// Subscriber buffer (frames queued per subscriber before the oldest is dropped).
pub const SUBSCRIBER_BUFFER: usize = 2;
/// Samples a subscriber may hold at once: the drain in `receive_latest` holds
/// two for an instant, plus up to two the caller may still keep.
pub const SUBSCRIBER_MAX_BORROWED: usize = 4;
/// Subscribers per topic (the peer plus one observer).
pub const MAX_SUBSCRIBERS: usize = 2;
/// Listeners per event service (the peer plus one observer).
pub const MAX_LISTENERS: usize = 2;

/// A frame iceoryx2 can carry: [`Frame`]'s header access plus iceoryx2's
/// zero-copy traits, which `motion-frames` implements under its `zero-copy`
/// feature (turned on by this crate).
pub trait ShmFrame: Frame + ZeroCopySend + PlacementDefault {}

impl<T: Frame + ZeroCopySend + PlacementDefault> ShmFrame for T {}

/// Create (supervisor) or open (peer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Access {
    Create,
    Open,
}

/// A service name for iceoryx2 plus the shared string errors refer to it by.
struct Named {
    service: ServiceName,
    label: Arc<str>,
}

fn named(name: &str) -> Result<Named, IpcError> {
    let service = ServiceName::new(name).map_err(|error| IpcError::ServiceName {
        name: name.to_string(),
        error,
    })?;
    Ok(Named {
        service,
        label: Arc::from(name),
    })
}

type TopicFactory<T> =
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>;
type EventFactory = iceoryx2::service::port_factory::event::PortFactory<ipc::Service>;

/// A topic of payload `T` with the frames' settings (see the QoS above),
/// not yet created or opened. The frame ports are built from it; so is the
/// IPC bench's bare echo, whose byte-array topics must differ from the
/// frames' in nothing but the payload.
pub fn topic_builder<T: fmt::Debug + ZeroCopySend>(
    node: &Node<ipc::Service>,
    name: &ServiceName,
) -> publish_subscribe::Builder<T, (), ipc::Service> {
    node.service_builder(name)
        .publish_subscribe::<T>()
        .enable_safe_overflow(true)
        .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
        .subscriber_max_borrowed_samples(SUBSCRIBER_MAX_BORROWED)
        .history_size(0)
        .max_publishers(1)
        .max_subscribers(MAX_SUBSCRIBERS)
}

/// An event service with the frames' settings (one notifier,
/// [`MAX_LISTENERS`] listeners), not yet created or opened.
pub fn event_builder(
    node: &Node<ipc::Service>,
    name: &ServiceName,
) -> event::Builder<ipc::Service> {
    node.service_builder(name)
        .event()
        .max_notifiers(1)
        .max_listeners(MAX_LISTENERS)
}

fn topic<T: ShmFrame>(
    node: &Node<ipc::Service>,
    name: &Named,
    access: Access,
) -> Result<TopicFactory<T>, IpcError> {
    let service = name.label.clone();
    let b = topic_builder::<T>(node, &name.service);
    match access {
        Access::Create => b
            .create()
            .map_err(|error| IpcError::CreateTopic { service, error }),
        Access::Open => b.open().map_err(|error| match error {
            PublishSubscribeOpenError::IncompatibleTypes => IpcError::LayoutMismatch { service },
            PublishSubscribeOpenError::VersionMismatch => {
                IpcError::IceoryxVersionMismatch { service }
            }
            error => IpcError::OpenTopic { service, error },
        }),
    }
}

/// Opens the frame topic `name` (`T`: [`CommandFrame`] or [`FeedbackFrame`])
/// with the settings it was created with, for an observer (a topic admits
/// the peer plus one): the benches' frame spy subscribes through it.
pub fn open_topic<T: ShmFrame>(
    node: &Node<ipc::Service>,
    name: &str,
) -> Result<TopicFactory<T>, IpcError> {
    topic(node, &named(name)?, Access::Open)
}

fn event(
    node: &Node<ipc::Service>,
    name: &Named,
    access: Access,
) -> Result<EventFactory, IpcError> {
    let service = name.label.clone();
    let b = event_builder(node, &name.service);
    match access {
        Access::Create => b
            .create()
            .map_err(|error| IpcError::CreateEvent { service, error }),
        Access::Open => b
            .open()
            .map_err(|error| IpcError::OpenEvent { service, error }),
    }
}

/// What [`Ports::publish`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sent {
    /// `header.sequence` stamped into the frame.
    pub sequence: u64,
    /// Number of subscribers the frame was delivered to (0 = no peer attached).
    pub receivers: usize,
}

/// One side of the exchange: publishes `Tx` frames (+ wake-up), receives `Rx`
/// frames (+ wake-up). Use [`SupervisorPorts`] or [`IoPorts`].
///
/// Single-threaded (`ipc::Service` ports are `!Send`): create and use the ports
/// on the thread that runs the cycle.
pub struct Ports<Tx: ShmFrame, Rx: ShmFrame> {
    publisher: Publisher<ipc::Service, Tx, ()>,
    notifier: Notifier<ipc::Service>,
    subscriber: Subscriber<ipc::Service, Rx, ()>,
    listener: Listener<ipc::Service>,
    tx_service: Arc<str>,
    tx_ready: Arc<str>,
    rx_service: Arc<str>,
    rx_ready: Arc<str>,
    /// The listener's file descriptor (a unix datagram socket on Linux), read
    /// once: iceoryx2 guarantees it does not change for the port's lifetime.
    listener_fd: i32,
    next_sequence: u64,
    skipped: u64,
    /// Session key stamped into every frame sent and required in every frame
    /// received.
    key: [u64; 2],
    /// Random per process start, stamped into every frame sent.
    origin: u64,
    /// Frames refused for a wrong key since creation.
    refused: u64,
}

/// A random origin id for this process (per port set; never 0).
fn new_origin() -> u64 {
    getrandom::u64().unwrap_or_else(|_| monotonic_ns()) | 1
}

/// Supervisor side: publishes [`CommandFrame`] on `{prefix}/command` and
/// notifies `{prefix}/command_ready`; receives [`FeedbackFrame`] from
/// `{prefix}/feedback` and waits on `{prefix}/feedback_ready`.
pub type SupervisorPorts = Ports<CommandFrame, FeedbackFrame>;

/// motion-io side: the mirror of [`SupervisorPorts`].
pub type IoPorts = Ports<FeedbackFrame, CommandFrame>;

impl Ports<CommandFrame, FeedbackFrame> {
    /// Supervisor side: creates the four services of I/O process `io`
    /// exclusively (one that exists already is refused) and the ports.
    pub fn create(node: &Node<ipc::Service>, domain: &Domain, io: &str) -> Result<Self, IpcError> {
        let n = IoServiceNames::new(&domain.prefix, io);
        Self::with_names(
            node,
            domain,
            Access::Create,
            [&n.command, &n.command_ready, &n.feedback, &n.feedback_ready],
        )
    }
}

impl Ports<FeedbackFrame, CommandFrame> {
    /// I/O process side: opens the four services the supervisor created for
    /// I/O process `io`. [`IpcError::is_no_supervisor`] tells "not there yet".
    pub fn open(node: &Node<ipc::Service>, domain: &Domain, io: &str) -> Result<Self, IpcError> {
        let n = IoServiceNames::new(&domain.prefix, io);
        Self::with_names(
            node,
            domain,
            Access::Open,
            [&n.feedback, &n.feedback_ready, &n.command, &n.command_ready],
        )
    }
}

impl<Tx: ShmFrame, Rx: ShmFrame> Ports<Tx, Rx> {
    /// `[tx topic, tx event, rx topic, rx event]`.
    fn with_names(
        node: &Node<ipc::Service>,
        domain: &Domain,
        access: Access,
        names: [&str; 4],
    ) -> Result<Self, IpcError> {
        let tx_service = named(names[0])?;
        let tx_ready = named(names[1])?;
        let rx_service = named(names[2])?;
        let rx_ready = named(names[3])?;

        // The supervisor creates everything; a peer opens everything.
        let tx = topic::<Tx>(node, &tx_service, access)?;
        let rx = topic::<Rx>(node, &rx_service, access)?;
        let tx_ev = event(node, &tx_ready, access)?;
        let rx_ev = event(node, &rx_ready, access)?;
        let (tx_service, tx_ready) = (tx_service.label, tx_ready.label);
        let (rx_service, rx_ready) = (rx_service.label, rx_ready.label);

        let publisher = tx
            .publisher_builder()
            .max_loaned_samples(1)
            // irrelevant while safe overflow is on; never block on a dead peer anyway
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .create()
            .map_err(|error| IpcError::CreatePublisher {
                service: tx_service.clone(),
                error,
            })?;
        let subscriber = rx
            .subscriber_builder()
            .buffer_size(SUBSCRIBER_BUFFER)
            .create()
            .map_err(|error| IpcError::CreateSubscriber {
                service: rx_service.clone(),
                error,
            })?;
        let notifier =
            tx_ev
                .notifier_builder()
                .create()
                .map_err(|error| IpcError::CreateNotifier {
                    service: tx_ready.clone(),
                    error,
                })?;
        let listener =
            rx_ev
                .listener_builder()
                .create()
                .map_err(|error| IpcError::CreateListener {
                    service: rx_ready.clone(),
                    error,
                })?;

        // SAFETY: only the number is kept; the listener owns the descriptor and
        // outlives every use (it is a field of the same struct).
        let listener_fd = unsafe {
            iceoryx2_bb_posix::file_descriptor::FileDescriptorBased::file_descriptor(&listener)
                .native_handle()
        };
        Ok(Self {
            publisher,
            notifier,
            subscriber,
            listener,
            listener_fd,
            tx_service,
            tx_ready,
            rx_service,
            rx_ready,
            next_sequence: 1,
            skipped: 0,
            key: domain.key,
            origin: new_origin(),
            refused: 0,
        })
    }

    /// Loans a sample in shared memory, initializes it in place to the all-zero
    /// frame (iceoryx2's `PlacementDefault`, no 3 KB value on the stack), lets
    /// `f` fill it, stamps `header.layout_version`, `header.sequence` and
    /// `header.timestamp_ns` (CLOCK_MONOTONIC, right before sending; `f` must
    /// not rely on setting those) and sends it. `f` sets `header.axis_count` and
    /// the axes (and, for feedback, `answers_sequence` / `io_received_ns`).
    ///
    /// Heap: 1 allocation (iceoryx2's per-sample reference-count block, made in
    /// `loan_uninit`), 0 in `send` with a stable set of peers.
    ///
    /// Does not wake the peer: call [`Self::notify`] afterwards, or use
    /// [`Self::send`].
    pub fn publish(&mut self, f: impl FnOnce(&mut Tx)) -> Result<Sent, IpcError> {
        let mut uninit = self
            .publisher
            .loan_uninit()
            .map_err(|error| IpcError::Loan {
                service: self.tx_service.clone(),
                error,
            })?;
        // SAFETY: `payload_mut()` is the properly aligned, exclusively loaned
        // payload memory of one `Tx`; `placement_default` writes every field
        // (the frame types have no implicit padding), so the payload is
        // initialized before `assume_init`.
        let mut sample = unsafe {
            Tx::placement_default(uninit.payload_mut().as_mut_ptr());
            uninit.assume_init()
        };
        let frame = sample.payload_mut();
        f(frame);
        let sequence = self.next_sequence;
        self.next_sequence += 1;
        let header = frame.header_mut();
        header.layout_version = LAYOUT_VERSION;
        header.sequence = sequence;
        header.origin = self.origin;
        header.key = self.key;
        header.timestamp_ns = monotonic_ns();
        let receivers = sample.send().map_err(|error| IpcError::Send {
            service: self.tx_service.clone(),
            error,
        })?;
        Ok(Sent {
            sequence,
            receivers,
        })
    }

    /// Wakes the peer (and observers) listening on the paired event service.
    /// Returns the number of listeners notified. No heap allocation with a
    /// stable set of peers.
    pub fn notify(&mut self) -> Result<usize, IpcError> {
        self.notifier.notify().map_err(|error| IpcError::Notify {
            service: self.tx_ready.clone(),
            error,
        })
    }

    /// [`Self::publish`] then [`Self::notify`].
    pub fn send(&mut self, f: impl FnOnce(&mut Tx)) -> Result<Sent, IpcError> {
        let sent = self.publish(f)?;
        self.notify()?;
        Ok(sent)
    }

    /// Drains the subscriber buffer and returns the newest frame (`None` if
    /// nothing arrived). Older frames found in the buffer are dropped and
    /// counted in [`Self::skipped`]. The newest frame's header is checked
    /// ([`motion_frames::FrameHeader::check`]) and must carry the session key (else
    /// [`IpcError::Forged`], counted in [`Self::refused`]). If a receive fails after a frame was
    /// already taken, that frame is returned and the failure shows again on the
    /// next call.
    ///
    /// The sample borrows shared memory until dropped: drop it before the next
    /// cycle (at most two may be kept, see [`SUBSCRIBER_MAX_BORROWED`]).
    pub fn receive_latest(&mut self) -> Result<Option<Sample<ipc::Service, Rx, ()>>, IpcError> {
        let mut latest: Option<Sample<ipc::Service, Rx, ()>> = None;
        loop {
            match self.subscriber.receive() {
                Ok(Some(sample)) => {
                    if latest.is_some() {
                        self.skipped += 1;
                    }
                    latest = Some(sample);
                }
                Ok(None) => break,
                Err(error) => {
                    if latest.is_some() {
                        break;
                    }
                    return Err(IpcError::Receive {
                        service: self.rx_service.clone(),
                        error,
                    });
                }
            }
        }
        if let Some(sample) = &latest {
            let h = sample.payload().header();
            h.check().map_err(|error| IpcError::Layout {
                service: self.rx_service.clone(),
                error,
            })?;
            if h.key != self.key {
                self.refused += 1;
                return Err(IpcError::Forged {
                    service: self.rx_service.clone(),
                });
            }
        }
        Ok(latest)
    }

    /// Blocks until the peer notifies or `timeout` passes
    /// (`Listener::timed_wait`). `Ok(true)` = woken (all pending wake-ups are
    /// consumed), `Ok(false)` = timed out. A wake-up that arrived after an
    /// earlier timeout is still pending and makes this return at once: match
    /// frames by sequence number, or call [`Self::try_wait`] to clear it first.
    pub fn wait(&mut self, timeout: Duration) -> Result<bool, IpcError> {
        let service = self.rx_ready.clone();
        match self.listener.timed_wait(|_| {}, timeout) {
            Ok(n) => Ok(n > 0),
            Err(ListenerWaitError::InterruptSignal) => Err(IpcError::Interrupted { service }),
            Err(error) => Err(IpcError::Wait { service, error }),
        }
    }

    /// Waits for the peer's wake-up until the absolute `CLOCK_MONOTONIC`
    /// time `deadline_ns` (ns); `Ok(true)` = woken, `Ok(false)` = deadline.
    ///
    /// Use this, not [`Self::wait`], where timing matters. `Listener::timed_wait`
    /// relies on the socket's `SO_RCVTIMEO`, which the kernel counts in jiffies
    /// (a 0.5 ms timeout sleeps up to 4 ms at HZ=250) and which treats a
    /// timeout below 1 µs as "forever". Here the descriptor is polled with
    /// `ppoll`, whose timeout is an hrtimer (no slack for a SCHED_FIFO
    /// thread), and the wake-up is then consumed with `try_wait`. A past
    /// deadline returns at once. A signal ends the wait early with
    /// [`IpcError::Interrupted`], so the caller can look at its flags. No heap
    /// allocation.
    pub fn wait_until(&mut self, deadline_ns: u64) -> Result<bool, IpcError> {
        loop {
            if self.try_wait()? {
                return Ok(true);
            }
            match ppoll_until(self.listener_fd, deadline_ns) {
                PollWake::Deadline => return self.try_wait(),
                PollWake::Interrupted => {
                    return Err(IpcError::Interrupted {
                        service: self.rx_ready.clone(),
                    })
                }
                // Readable: consumed at the top. A descriptor error is
                // reported by try_wait at the top; the deadline bounds the loop.
                PollWake::Readable | PollWake::Error => {}
            }
        }
    }

    /// Non-blocking [`Self::wait`]: consumes pending wake-ups, `Ok(true)` if
    /// there were any.
    pub fn try_wait(&mut self) -> Result<bool, IpcError> {
        let service = self.rx_ready.clone();
        match self.listener.try_wait(|_| {}) {
            Ok(n) => Ok(n > 0),
            Err(ListenerWaitError::InterruptSignal) => Err(IpcError::Interrupted { service }),
            Err(error) => Err(IpcError::Wait { service, error }),
        }
    }

    /// Connects to peers that appeared (or releases those that left) now,
    /// instead of inside the next `publish`/`receive`/`notify`. Call at
    /// start-up, outside the real-time cycle, once the peer is attached.
    pub fn update_connections(&mut self) -> Result<(), IpcError> {
        self.publisher
            .update_connections()
            .map_err(|error| IpcError::Connection {
                service: self.tx_service.clone(),
                error,
            })?;
        self.subscriber
            .update_connections()
            .map_err(|error| IpcError::Connection {
                service: self.rx_service.clone(),
                error,
            })?;
        self.notifier
            .update_connections()
            .map_err(|error| IpcError::Connection {
                service: self.tx_ready.clone(),
                error,
            })?;
        Ok(())
    }

    /// Sequence number the next published frame gets (the first is 1).
    pub fn next_sequence(&self) -> u64 {
        self.next_sequence
    }

    /// Frames that were overtaken by a newer one and dropped unseen by
    /// [`Self::receive_latest`] since creation.
    pub fn skipped(&self) -> u64 {
        self.skipped
    }

    /// Received frames refused for a wrong session key since creation.
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// The origin id this side stamps into its frames.
    pub fn origin(&self) -> u64 {
        self.origin
    }

    /// `[published topic, its event, received topic, its event]`.
    pub fn services(&self) -> [&str; 4] {
        [
            &self.tx_service,
            &self.tx_ready,
            &self.rx_service,
            &self.rx_ready,
        ]
    }
}

impl<Tx: ShmFrame, Rx: ShmFrame> fmt::Debug for Ports<Tx, Rx> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Ports")
            .field("publishes", &self.tx_service)
            .field("notifies", &self.tx_ready)
            .field("subscribes", &self.rx_service)
            .field("listens", &self.rx_ready)
            .field("next_sequence", &self.next_sequence)
            .field("skipped", &self.skipped)
            .finish()
    }
}
