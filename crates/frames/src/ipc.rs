//! iceoryx2 ports shared by `motion-supervisor` and `motion-io`, so service
//! names and QoS live in one place.
//!
//! # Services
//!
//! For a `service_prefix` `P` (from the TOML, e.g. `"motion"`):
//!
//! | service | pattern | writer → reader |
//! |---|---|---|
//! | `P/command` | publish-subscribe of [`CommandFrame`] | supervisor → io |
//! | `P/command_ready` | event | supervisor → io ("a command was sent") |
//! | `P/feedback` | publish-subscribe of [`FeedbackFrame`] | io → supervisor |
//! | `P/feedback_ready` | event | io → supervisor ("feedback was sent") |
//!
//! Pub/sub does not wake anybody, so every `publish` is followed by a `notify`
//! on the paired event service ([`Ports::send`] does both).
//!
//! # QoS (identical in both processes, checked by iceoryx2 on open)
//!
//! * safe overflow ON: a full subscriber buffer drops its oldest frame, the
//!   publisher never blocks on a slow or dead peer;
//! * subscriber buffer [`SUBSCRIBER_BUFFER`] = 2, history 0;
//! * [`MAX_PUBLISHERS`] = 1 per topic (a second supervisor or io with the same
//!   prefix fails to attach), [`MAX_SUBSCRIBERS`] = 3 (the peer plus observers);
//! * [`MAX_NOTIFIERS`] = 1, [`MAX_LISTENERS`] = 3 per event service.
//!
//! Every service is opened with `open_or_create`, so either process may start
//! first.
//!
//! # Real-time use
//!
//! Create everything (node, ports) and call [`Ports::update_connections`] at
//! start-up, outside the cycle. In the cycle only [`Ports::publish`],
//! [`Ports::notify`], [`Ports::receive_latest`], [`Ports::wait`] and
//! [`Ports::try_wait`] are used. With a stable set of peers they perform no heap
//! allocation except the one iceoryx2 makes per loaned sample (a reference-count
//! block; see `tests/roundtrip.rs`, which counts them). When a peer joins or
//! leaves, the next send/receive/notify re-maps memory and may allocate.
//!
//! # Files
//!
//! Shared memory lives in `/dev/shm`, named `{file_prefix}<hash>...` (see
//! [`IpcConfig::file_prefix`]); service/node files and event sockets live under
//! the root directory. Dropping all ports and nodes removes them, except one
//! small segment iceoryx2 0.10 keeps by design per domain (prefix + version):
//! `/dev/shm/{file_prefix}<hash>_node.0_10_0.global_mgmt`, a node counter that
//! is reused on the next start. Resources of a process that died (kill -9) are
//! removed by `Node::try_cleanup_dead_nodes`, and automatically when a node is
//! created or dropped or a service is opened in the same domain.
//! [`cleanup_domain`], called by each process after it dropped its node, does
//! both: it cleans dead nodes and, once no live node remains, removes the
//! node-counter segment, so nothing of the domain is left in `/dev/shm`.
//!
//! # Signals
//!
//! Nodes are created with [`SignalHandlingMode::Disabled`]: iceoryx2 installs
//! no SIGINT/SIGTERM handler; the processes handle those themselves and drop
//! their ports and node on the way out (which removes the shared memory).

use core::fmt;
use core::time::Duration;
use std::os::unix::ffi::OsStrExt;
use std::path::PathBuf;
use std::sync::Arc;

use iceoryx2::config::Config;
use iceoryx2::node::{Node, NodeBuilder, NodeCreationFailure};
use iceoryx2::port::listener::{Listener, ListenerCreateError, ListenerWaitError};
use iceoryx2::port::notifier::{Notifier, NotifierCreateError, NotifierNotifyError};
use iceoryx2::port::publisher::{Publisher, PublisherCreateError};
use iceoryx2::port::subscriber::{Subscriber, SubscriberCreateError};
use iceoryx2::port::update_connections::{ConnectionFailure, UpdateConnections};
use iceoryx2::port::{LoanError, ReceiveError, SendError};
use iceoryx2::prelude::{
    ipc, BackpressureStrategy, CallbackProgression, FileName, NodeName, NodeState, Path,
    SemanticString, ServiceName, SignalHandlingMode,
};
use iceoryx2::sample::Sample;
use iceoryx2::service::builder::event::{EventOpenError, EventOpenOrCreateError};
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeOpenError, PublishSubscribeOpenOrCreateError,
};
use iceoryx2::service::service_name::ServiceNameError;

use crate::frame::{CommandFrame, FeedbackFrame, Frame, LayoutError, LAYOUT_VERSION};
use crate::monotonic_ns;

/// Subscriber buffer (frames queued per subscriber before the oldest is dropped).
pub const SUBSCRIBER_BUFFER: usize = 2;
/// Samples a subscriber may hold at once: the drain in `receive_latest` holds
/// two for an instant, plus up to two the caller may still keep.
pub const SUBSCRIBER_MAX_BORROWED: usize = 4;
/// History delivered to late subscribers (none: an old frame is never acted on).
pub const HISTORY: usize = 0;
/// Publishers per topic.
pub const MAX_PUBLISHERS: usize = 1;
/// Subscribers per topic (the peer plus observing tools).
pub const MAX_SUBSCRIBERS: usize = 3;
/// Notifiers per event service.
pub const MAX_NOTIFIERS: usize = 1;
/// Listeners per event service (the peer plus observing tools).
pub const MAX_LISTENERS: usize = 3;

/// The iceoryx2 "instance" both processes must agree on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IpcConfig {
    /// `service_prefix` from the TOML, e.g. `"motion"`: first part of every
    /// service name, and (sanitized, see [`IpcConfig::file_prefix`]) the prefix
    /// of every file iceoryx2 creates.
    pub prefix: String,
    /// Directory for iceoryx2's service and node files; `None` = iceoryx2's
    /// default (`/tmp/iceoryx2/`). Shared memory itself always lives in `/dev/shm`.
    pub root: Option<PathBuf>,
}

/// The four service names of one prefix.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ServiceNames {
    /// `{prefix}/command` — pub/sub of [`CommandFrame`].
    pub command: String,
    /// `{prefix}/feedback` — pub/sub of [`FeedbackFrame`].
    pub feedback: String,
    /// `{prefix}/command_ready` — event.
    pub command_ready: String,
    /// `{prefix}/feedback_ready` — event.
    pub feedback_ready: String,
}

/// The one place service names are made.
pub fn service_names(prefix: &str) -> ServiceNames {
    ServiceNames {
        command: format!("{prefix}/command"),
        feedback: format!("{prefix}/feedback"),
        command_ready: format!("{prefix}/command_ready"),
        feedback_ready: format!("{prefix}/feedback_ready"),
    }
}

impl IpcConfig {
    /// Config for `prefix` with iceoryx2's default root directory.
    pub fn new(prefix: impl Into<String>) -> Self {
        Self {
            prefix: prefix.into(),
            root: None,
        }
    }

    /// Same, with an explicit root directory (tests use one per test).
    pub fn with_root(mut self, root: impl Into<PathBuf>) -> Self {
        self.root = Some(root.into());
        self
    }

    /// Prefix of every file iceoryx2 creates for this config (in `/dev/shm` and
    /// under the root): `iox2_` + the service prefix with every character
    /// outside `[A-Za-z0-9_.-]` replaced by `_` + `_`. E.g. `"motion"` →
    /// `"iox2_motion_"`.
    pub fn file_prefix(&self) -> String {
        let clean: String = self
            .prefix
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-') {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        format!("iox2_{clean}_")
    }

    /// Names of this domain's files in `/dev/shm`, sorted: what
    /// [`cleanup_domain`] must leave empty once every process has gone (and
    /// what the tests check).
    pub fn shm_files(&self) -> Vec<String> {
        let prefix = self.file_prefix();
        let mut v: Vec<String> = std::fs::read_dir("/dev/shm")
            .map(|rd| {
                rd.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .filter(|n| n.starts_with(&prefix))
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    }

    /// The service names of this prefix.
    pub fn service_names(&self) -> ServiceNames {
        service_names(&self.prefix)
    }

    /// Builds the iceoryx2 config: `Config::default()` (deterministic: no
    /// `iceoryx2.toml` is read) with `global.prefix` = [`Self::file_prefix`] and
    /// `global.root_path` = [`Self::root`] if given.
    pub fn iceoryx2_config(&self) -> Result<Config, IpcError> {
        if self.prefix.is_empty() {
            return Err(IpcError::Config(
                "service_prefix is empty; set [supervisor] service_prefix, e.g. \"motion\"".into(),
            ));
        }
        let mut cfg = Config::default();
        let file_prefix = self.file_prefix();
        cfg.global.prefix = FileName::new(file_prefix.as_bytes()).map_err(|e| {
            IpcError::Config(format!(
                "service_prefix {:?} gives the file prefix {file_prefix:?}, which iceoryx2 \
                 rejects ({e:?}); use a shorter prefix of letters, digits, '_', '-', '.'",
                self.prefix
            ))
        })?;
        if let Some(root) = &self.root {
            let mut bytes = root.as_os_str().as_bytes().to_vec();
            if !bytes.ends_with(b"/") {
                bytes.push(b'/');
            }
            let path = Path::new(&bytes).map_err(|e| {
                IpcError::Config(format!(
                    "iceoryx2 root directory {} is not usable ({e:?})",
                    root.display()
                ))
            })?;
            cfg.global.set_root_path(&path);
        }
        Ok(cfg)
    }

    /// Creates an iceoryx2 node for this config, named `name` (e.g.
    /// `"motion-supervisor"`), with iceoryx2's signal handling disabled.
    pub fn create_node(&self, name: &str) -> Result<Node<ipc::Service>, IpcError> {
        let cfg = self.iceoryx2_config()?;
        let node_name = NodeName::new(name).map_err(|e| {
            IpcError::Config(format!(
                "node name {name:?} is not valid for iceoryx2 ({e:?})"
            ))
        })?;
        NodeBuilder::new()
            .name(&node_name)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .config(&cfg)
            .create::<ipc::Service>()
            .map_err(IpcError::Node)
    }
}

/// Failures of the port helpers, worded for a controls engineer: which service,
/// what went wrong, and what iceoryx2 said.
///
/// The service is named by an `Arc<str>` created with the ports, so the errors
/// the cycle can produce are built without heap allocation (a reference-count
/// increment); only start-up errors format new strings.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IpcError {
    /// The [`IpcConfig`] cannot be turned into an iceoryx2 config.
    Config(String),
    /// The iceoryx2 node could not be created.
    Node(NodeCreationFailure),
    /// A service name could not be formed from the prefix.
    ServiceName {
        name: String,
        error: ServiceNameError,
    },
    /// The service exists with a frame type of another layout: the peer was
    /// built from another motion-frames version.
    LayoutMismatch { service: Arc<str> },
    /// The service was created by a process linked against another iceoryx2.
    IceoryxVersionMismatch { service: Arc<str> },
    /// A publish-subscribe service could not be opened or created.
    OpenTopic {
        service: Arc<str>,
        error: PublishSubscribeOpenOrCreateError,
    },
    /// An event service could not be opened or created.
    OpenEvent {
        service: Arc<str>,
        error: EventOpenOrCreateError,
    },
    CreatePublisher {
        service: Arc<str>,
        error: PublisherCreateError,
    },
    CreateSubscriber {
        service: Arc<str>,
        error: SubscriberCreateError,
    },
    CreateNotifier {
        service: Arc<str>,
        error: NotifierCreateError,
    },
    CreateListener {
        service: Arc<str>,
        error: ListenerCreateError,
    },
    /// No shared-memory sample could be loaned for a frame.
    Loan { service: Arc<str>, error: LoanError },
    /// A frame could not be delivered.
    Send { service: Arc<str>, error: SendError },
    /// Receiving a frame failed.
    Receive {
        service: Arc<str>,
        error: ReceiveError,
    },
    /// Connecting to a (new) peer port failed.
    Connection {
        service: Arc<str>,
        error: ConnectionFailure,
    },
    /// The wake-up could not be sent.
    Notify {
        service: Arc<str>,
        error: NotifierNotifyError,
    },
    /// Waiting for a wake-up failed.
    Wait {
        service: Arc<str>,
        error: ListenerWaitError,
    },
    /// A signal (SIGINT/SIGTERM/...) interrupted the wait; check the shutdown flag.
    Interrupted { service: Arc<str> },
    /// A received frame has a bad header.
    Layout {
        service: Arc<str>,
        error: LayoutError,
    },
}

impl IpcError {
    /// True for the cross-version cases (frame layout or iceoryx2 version).
    pub fn is_version_mismatch(&self) -> bool {
        matches!(
            self,
            IpcError::LayoutMismatch { .. }
                | IpcError::IceoryxVersionMismatch { .. }
                | IpcError::Layout {
                    error: LayoutError::VersionMismatch { .. },
                    ..
                }
        )
    }
}

fn open_topic_hint(e: &PublishSubscribeOpenOrCreateError) -> &'static str {
    use PublishSubscribeOpenError as O;
    match e {
        PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(o) => match o {
            O::InsufficientPermissions => {
                "permission denied: both processes must run as the same user"
            }
            O::IncompatibleOverflowBehavior
            | O::DoesNotSupportRequestedAmountOfPublishers
            | O::DoesNotSupportRequestedAmountOfSubscribers
            | O::DoesNotSupportRequestedMinBufferSize
            | O::DoesNotSupportRequestedMinHistorySize
            | O::DoesNotSupportRequestedMinSubscriberBorrowedSamples
            | O::DoesNotSupportRequestedAmountOfNodes => {
                "the service exists with other QoS settings: the peer was built from another \
                 tree; rebuild both from the same tree"
            }
            O::ExceedsMaxNumberOfNodes => "too many processes are attached to this service",
            O::HangsInCreation | O::ServiceInCorruptedState => {
                "a process crashed while creating the service; stop all motion processes \
                 and start again (stale resources are cleaned up on start)"
            }
            O::IncompatibleMessagingPattern => {
                "a service of another kind uses this name; is service_prefix shared with \
                 another application?"
            }
            _ => "iceoryx2 refused to open the service",
        },
        PublishSubscribeOpenOrCreateError::PublishSubscribeCreateError(_) => {
            "iceoryx2 could not create the service (is /dev/shm writable and not full?)"
        }
        PublishSubscribeOpenOrCreateError::SystemInFlux => {
            "the service is being created and removed repeatedly by another process"
        }
    }
}

fn open_event_hint(e: &EventOpenOrCreateError) -> &'static str {
    use EventOpenError as O;
    match e {
        EventOpenOrCreateError::EventOpenError(o) => match o {
            O::InsufficientPermissions => {
                "permission denied: both processes must run as the same user"
            }
            O::DoesNotSupportRequestedAmountOfNotifiers
            | O::DoesNotSupportRequestedAmountOfListeners
            | O::DoesNotSupportRequestedMaxEventId
            | O::DoesNotSupportRequestedAmountOfNodes
            | O::IncompatibleDeadline
            | O::IncompatibleNotifierCreatedEvent
            | O::IncompatibleNotifierDroppedEvent
            | O::IncompatibleNotifierDeadEvent => {
                "the service exists with other settings: the peer was built from another \
                 tree; rebuild both from the same tree"
            }
            O::HangsInCreation | O::ServiceInCorruptedState => {
                "a process crashed while creating the service; stop all motion processes \
                 and start again (stale resources are cleaned up on start)"
            }
            O::IncompatibleMessagingPattern => {
                "a service of another kind uses this name; is service_prefix shared with \
                 another application?"
            }
            _ => "iceoryx2 refused to open the service",
        },
        EventOpenOrCreateError::EventCreateError(_) => {
            "iceoryx2 could not create the service (is /dev/shm writable and not full?)"
        }
        EventOpenOrCreateError::SystemInFlux => {
            "the service is being created and removed repeatedly by another process"
        }
    }
}

impl fmt::Display for IpcError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IpcError::Config(msg) => write!(f, "iceoryx2 configuration: {msg}"),
            IpcError::Node(e) => write!(
                f,
                "cannot create the iceoryx2 node (are /dev/shm and the iceoryx2 root \
                 directory writable?) (iceoryx2: {e:?})"
            ),
            IpcError::ServiceName { name, error } => write!(
                f,
                "{name:?} is not a valid iceoryx2 service name; check service_prefix \
                 (iceoryx2: {error:?})"
            ),
            IpcError::LayoutMismatch { service } => write!(
                f,
                "frame layout mismatch on service '{service}': this binary speaks layout \
                 {LAYOUT_VERSION}; the peer was built with another motion-frames version; \
                 rebuild both from the same tree"
            ),
            IpcError::IceoryxVersionMismatch { service } => write!(
                f,
                "service '{service}' was created by a process linked against another iceoryx2 \
                 version (this binary uses 0.10.0); rebuild both from the same tree"
            ),
            IpcError::OpenTopic { service, error } => write!(
                f,
                "cannot open or create service '{service}': {} (iceoryx2: {error:?})",
                open_topic_hint(error)
            ),
            IpcError::OpenEvent { service, error } => write!(
                f,
                "cannot open or create event service '{service}': {} (iceoryx2: {error:?})",
                open_event_hint(error)
            ),
            IpcError::CreatePublisher { service, error } => match error {
                PublisherCreateError::ExceedsMaxSupportedPublishers => write!(
                    f,
                    "cannot publish on '{service}': another process already publishes there; \
                     is a second supervisor or motion-io running with the same \
                     service_prefix? (iceoryx2: {error:?})"
                ),
                _ => write!(
                    f,
                    "cannot create the publisher on '{service}' (iceoryx2: {error:?})"
                ),
            },
            IpcError::CreateSubscriber { service, error } => write!(
                f,
                "cannot subscribe to '{service}'{} (iceoryx2: {error:?})",
                if *error == SubscriberCreateError::ExceedsMaxSupportedSubscribers {
                    ": too many subscribers (observers) are attached"
                } else {
                    ""
                }
            ),
            IpcError::CreateNotifier { service, error } => match error {
                NotifierCreateError::ExceedsMaxSupportedNotifiers => write!(
                    f,
                    "cannot notify on '{service}': another process already does; is a second \
                     supervisor or motion-io running with the same service_prefix? \
                     (iceoryx2: {error:?})"
                ),
                _ => write!(
                    f,
                    "cannot create the notifier on '{service}' (iceoryx2: {error:?})"
                ),
            },
            IpcError::CreateListener { service, error } => {
                write!(f, "cannot listen on '{service}' (iceoryx2: {error:?})")
            }
            IpcError::Loan { service, error } => write!(
                f,
                "no shared-memory sample available to publish on '{service}' \
                 (iceoryx2: {error:?})"
            ),
            IpcError::Send { service, error } => write!(
                f,
                "frame on '{service}' could not be delivered to every subscriber \
                 (iceoryx2: {error:?})"
            ),
            IpcError::Receive { service, error } => match error {
                ReceiveError::ExceedsMaxBorrows => write!(
                    f,
                    "cannot receive on '{service}': more than {SUBSCRIBER_MAX_BORROWED} received \
                     frames are still held; drop old samples (iceoryx2: {error:?})"
                ),
                ReceiveError::ConnectionFailure(_) => write!(
                    f,
                    "cannot connect to the publisher of '{service}' (iceoryx2: {error:?})"
                ),
            },
            IpcError::Connection { service, error } => write!(
                f,
                "cannot connect the ports of '{service}' (iceoryx2: {error:?})"
            ),
            IpcError::Notify { service, error } => {
                write!(f, "wake-up on '{service}' failed (iceoryx2: {error:?})")
            }
            IpcError::Wait { service, error } => write!(
                f,
                "waiting for a wake-up on '{service}' failed (iceoryx2: {error:?})"
            ),
            IpcError::Interrupted { service } => {
                write!(f, "waiting on '{service}' was interrupted by a signal")
            }
            IpcError::Layout { service, error } => {
                write!(f, "bad frame received on '{service}': {error}")
            }
        }
    }
}

impl std::error::Error for IpcError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            IpcError::Node(e) => Some(e),
            IpcError::ServiceName { error, .. } => Some(error),
            IpcError::OpenTopic { error, .. } => Some(error),
            IpcError::OpenEvent { error, .. } => Some(error),
            IpcError::CreatePublisher { error, .. } => Some(error),
            IpcError::CreateSubscriber { error, .. } => Some(error),
            IpcError::CreateNotifier { error, .. } => Some(error),
            IpcError::CreateListener { error, .. } => Some(error),
            IpcError::Loan { error, .. } => Some(error),
            IpcError::Send { error, .. } => Some(error),
            IpcError::Receive { error, .. } => Some(error),
            IpcError::Connection { error, .. } => Some(error),
            IpcError::Notify { error, .. } => Some(error),
            IpcError::Wait { error, .. } => Some(error),
            IpcError::Layout { error, .. } => Some(error),
            IpcError::Config(_)
            | IpcError::LayoutMismatch { .. }
            | IpcError::IceoryxVersionMismatch { .. }
            | IpcError::Interrupted { .. } => None,
        }
    }
}

/// A service name for iceoryx2 plus the shared string errors refer to it by.
#[derive(Clone)]
struct Named {
    service: ServiceName,
    label: Arc<str>,
}

fn make_service_name(name: &str) -> Result<Named, IpcError> {
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

fn open_topic<T: Frame>(
    node: &Node<ipc::Service>,
    name: &Named,
) -> Result<TopicFactory<T>, IpcError> {
    let service = name.label.clone();
    node.service_builder(&name.service)
        .publish_subscribe::<T>()
        .enable_safe_overflow(true)
        .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
        .subscriber_max_borrowed_samples(SUBSCRIBER_MAX_BORROWED)
        .history_size(HISTORY)
        .max_publishers(MAX_PUBLISHERS)
        .max_subscribers(MAX_SUBSCRIBERS)
        .open_or_create()
        .map_err(|error| match error {
            PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                PublishSubscribeOpenError::IncompatibleTypes,
            ) => IpcError::LayoutMismatch { service },
            PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                PublishSubscribeOpenError::VersionMismatch,
            ) => IpcError::IceoryxVersionMismatch { service },
            error => IpcError::OpenTopic { service, error },
        })
}

fn open_event(node: &Node<ipc::Service>, name: &Named) -> Result<EventFactory, IpcError> {
    let service = name.label.clone();
    node.service_builder(&name.service)
        .event()
        .max_notifiers(MAX_NOTIFIERS)
        .max_listeners(MAX_LISTENERS)
        .open_or_create()
        .map_err(|error| match error {
            EventOpenOrCreateError::EventOpenError(EventOpenError::VersionMismatch) => {
                IpcError::IceoryxVersionMismatch { service }
            }
            error => IpcError::OpenEvent { service, error },
        })
}

/// What [`ppoll_until`] saw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PollWake {
    /// The descriptor is readable (a wake-up is pending).
    Readable,
    /// The deadline passed (or had passed already).
    Deadline,
    /// A signal arrived (EINTR).
    Interrupted,
    /// `ppoll` failed otherwise.
    Error,
}

/// Waits until `fd` is readable or the absolute `CLOCK_MONOTONIC` time
/// `deadline_ns` passes, with `ppoll`: its timeout is an hrtimer (exact, no
/// slack for a SCHED_FIFO thread), unlike a socket's `SO_RCVTIMEO`, which is
/// counted in jiffies. The mechanism of [`Ports::wait_until`], for callers
/// that hold a raw iceoryx2 listener (the IPC benchmark's bare peer).
pub fn ppoll_until(fd: i32, deadline_ns: u64) -> PollWake {
    let now = monotonic_ns();
    if now >= deadline_ns {
        return PollWake::Deadline;
    }
    let rem = deadline_ns - now;
    let ts = libc::timespec {
        tv_sec: (rem / 1_000_000_000) as libc::time_t,
        tv_nsec: (rem % 1_000_000_000) as libc::c_long,
    };
    let mut pfd = libc::pollfd {
        fd,
        events: libc::POLLIN,
        revents: 0,
    };
    // SAFETY: one valid pollfd, a valid timespec, no signal mask.
    match unsafe { libc::ppoll(&mut pfd, 1, &ts, core::ptr::null()) } {
        0 => PollWake::Deadline,
        rc if rc > 0 => PollWake::Readable,
        _ if std::io::Error::last_os_error().raw_os_error() == Some(libc::EINTR) => {
            PollWake::Interrupted
        }
        _ => PollWake::Error,
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
pub struct Ports<Tx: Frame, Rx: Frame> {
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
}

/// Supervisor side: publishes [`CommandFrame`] on `{prefix}/command` and
/// notifies `{prefix}/command_ready`; receives [`FeedbackFrame`] from
/// `{prefix}/feedback` and waits on `{prefix}/feedback_ready`.
pub type SupervisorPorts = Ports<CommandFrame, FeedbackFrame>;

/// motion-io side: the mirror of [`SupervisorPorts`].
pub type IoPorts = Ports<FeedbackFrame, CommandFrame>;

impl Ports<CommandFrame, FeedbackFrame> {
    /// Opens (or creates) the four services of `prefix` and the supervisor's ports.
    pub fn create(node: &Node<ipc::Service>, prefix: &str) -> Result<Self, IpcError> {
        let n = service_names(prefix);
        Self::create_with_names(
            node,
            &n.command,
            &n.command_ready,
            &n.feedback,
            &n.feedback_ready,
        )
    }
}

impl Ports<FeedbackFrame, CommandFrame> {
    /// Opens (or creates) the four services of `prefix` and motion-io's ports.
    pub fn create(node: &Node<ipc::Service>, prefix: &str) -> Result<Self, IpcError> {
        let n = service_names(prefix);
        Self::create_with_names(
            node,
            &n.feedback,
            &n.feedback_ready,
            &n.command,
            &n.command_ready,
        )
    }
}

impl<Tx: Frame, Rx: Frame> Ports<Tx, Rx> {
    pub(crate) fn create_with_names(
        node: &Node<ipc::Service>,
        tx_topic: &str,
        tx_event: &str,
        rx_topic: &str,
        rx_event: &str,
    ) -> Result<Self, IpcError> {
        let tx_service = make_service_name(tx_topic)?;
        let tx_ready = make_service_name(tx_event)?;
        let rx_service = make_service_name(rx_topic)?;
        let rx_ready = make_service_name(rx_event)?;

        let tx = open_topic::<Tx>(node, &tx_service)?;
        let rx = open_topic::<Rx>(node, &rx_service)?;
        let tx_ev = open_event(node, &tx_ready)?;
        let rx_ev = open_event(node, &rx_ready)?;
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
    /// ([`crate::FrameHeader::check`]). If a receive fails after a frame was
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
            sample
                .payload()
                .header()
                .check()
                .map_err(|error| IpcError::Layout {
                    service: self.rx_service.clone(),
                    error,
                })?;
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

impl<Tx: Frame, Rx: Frame> fmt::Debug for Ports<Tx, Rx> {
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

/// What [`cleanup_domain`] found and did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CleanupReport {
    /// Nodes of the domain whose process is alive (e.g. the peer still runs).
    pub alive: usize,
    /// Dead nodes (process gone without cleaning up, e.g. after `kill -9`)
    /// whose stale resources were removed now.
    pub dead_cleaned: usize,
    /// Dead nodes whose resources could not be removed (permissions, another
    /// process still busy cleaning them, another iceoryx2 version).
    pub dead_failed: usize,
    /// Nodes whose state could not be determined (another user's, or a node
    /// caught half-created). Counted as alive: the domain is not torn down.
    pub unknown: usize,
    /// The domain's persistent node-counter segment
    /// (`/dev/shm/{file_prefix}…_node.0_10_0.global_mgmt`) was removed.
    pub removed_global_mgmt: bool,
    /// Why the domain could not be inspected or the segment not removed, if so.
    pub error: Option<String>,
}

impl CleanupReport {
    /// True if nothing of the domain is known to remain: no live, unknown or
    /// uncleanable node and no error (the segment itself may have been absent).
    pub fn domain_gone(&self) -> bool {
        self.alive == 0 && self.unknown == 0 && self.dead_failed == 0 && self.error.is_none()
    }
}

impl fmt::Display for CleanupReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} live node(s), {} dead node(s) cleaned",
            self.alive + self.unknown,
            self.dead_cleaned
        )?;
        if self.dead_failed > 0 {
            write!(f, ", {} dead node(s) NOT cleaned", self.dead_failed)?;
        }
        if self.removed_global_mgmt {
            write!(f, ", node-counter segment removed")?;
        }
        if let Some(e) = &self.error {
            write!(f, "; {e}")?;
        }
        Ok(())
    }
}

/// How long [`cleanup_domain`] waits for another process that is cleaning up
/// the same dead node at the same moment.
const CLEANUP_WAIT: Duration = Duration::from_millis(200);

/// Tidies the iceoryx2 domain of `cfg` on the way out. Call it after this
/// process dropped all its ports and its node (`motion-supervisor` and
/// `motion-io` both do); it creates nothing (no node, no service).
///
/// 1. Lists the nodes of the domain (`Node::list`).
/// 2. Removes the stale resources of every dead node (a peer killed with
///    SIGKILL leaves its shared memory, its ports in the services and its node
///    files behind).
/// 3. If no live (or undeterminable) node remains and every dead one was
///    cleaned, removes the domain's persistent node-counter segment, the one
///    file iceoryx2 0.10 never removes by itself (see the module docs). After
///    that nothing named `{file_prefix}*` is left in `/dev/shm`.
///
/// # The race, and why it is acceptable
///
/// Between the listing (step 1) and the removal (step 3) another process may
/// start a node in the same domain. Node creation only uses the segment to
/// draw a node counter: a process that already opened it keeps its mapping
/// and works normally; the next node simply creates a fresh segment whose
/// counter starts again at 0. Node ids combine pid, counter and creation time
/// (ns), so a restarted counter does not produce duplicate ids. Only if the
/// removal hits the few microseconds in which the other process is *creating*
/// the segment can its node creation fail; it then reports the error and a
/// restart succeeds. The window exists only while the domain has no live node
/// at all, i.e. at the moment the last process leaves, which makes it
/// practically irrelevant; a lock across processes would cost more than it
/// saves.
///
/// Never panics; failures are reported in [`CleanupReport::error`].
pub fn cleanup_domain(cfg: &IpcConfig) -> CleanupReport {
    let mut report = CleanupReport::default();
    let icfg = match cfg.iceoryx2_config() {
        Ok(c) => c,
        Err(e) => {
            report.error = Some(e.to_string());
            return report;
        }
    };
    let listed = Node::<ipc::Service>::list(&icfg, |state| {
        match state {
            NodeState::Alive(_) => report.alive += 1,
            NodeState::Dead(dead) => match dead.blocking_remove_stale_resources(CLEANUP_WAIT) {
                Ok(()) => report.dead_cleaned += 1,
                Err(_) => report.dead_failed += 1,
            },
            NodeState::Inaccessible(_) | NodeState::Undefined(_) => report.unknown += 1,
        }
        CallbackProgression::Continue
    });
    if let Err(e) = listed {
        report.error = Some(format!(
            "cannot list the nodes of the iceoryx2 domain {:?} (iceoryx2: {e:?})",
            cfg.file_prefix()
        ));
        return report;
    }
    if !report.domain_gone() {
        return report;
    }
    // SAFETY: no process of the domain is alive (just checked); see the race
    // discussion above for a node created between the check and this call.
    match unsafe { iceoryx2::testing::remove_global_mgmt_segment::<ipc::Service>(&icfg) } {
        Ok(removed) => report.removed_global_mgmt = removed,
        Err(e) => {
            report.error = Some(format!(
                "cannot remove the node-counter segment of {:?} (iceoryx2: {e:?})",
                cfg.file_prefix()
            ))
        }
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FrameHeader, MAX_AXES};
    use iceoryx2::prelude::{PlacementDefault, ZeroCopySend};
    use std::sync::atomic::{AtomicU32, Ordering};

    static COUNTER: AtomicU32 = AtomicU32::new(0);

    /// Unique prefix + root per test, removed on drop.
    struct TestEnv {
        cfg: IpcConfig,
    }

    impl TestEnv {
        fn new(tag: &str) -> Self {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let pid = std::process::id();
            let root = std::env::temp_dir().join(format!("mf-unit-{tag}-{pid}-{n}"));
            std::fs::create_dir_all(&root).unwrap();
            Self {
                cfg: IpcConfig::new(format!("mfu{tag}{pid}x{n}")).with_root(root),
            }
        }
    }

    impl Drop for TestEnv {
        fn drop(&mut self) {
            // iceoryx2 keeps one persistent node-counter segment per domain in
            // /dev/shm (`*.global_mgmt`); remove it for the test-private domain.
            if let Ok(cfg) = self.cfg.iceoryx2_config() {
                // SAFETY: the test's ports and nodes are dropped before the env.
                unsafe {
                    let _ = iceoryx2::testing::remove_global_mgmt_segment::<ipc::Service>(&cfg);
                }
            }
            if let Some(root) = &self.cfg.root {
                let _ = std::fs::remove_dir_all(root);
            }
        }
    }

    /// A command frame as a future motion-frames version might define it: same
    /// service name, another layout (and so another type name).
    #[repr(C)]
    #[derive(Clone, Copy, Debug, Default, ZeroCopySend, PlacementDefault)]
    #[type_name("motion_frames::CommandFrame@layout999")]
    struct CommandFrameV2 {
        header: FrameHeader,
        extra: u64,
    }

    impl Frame for CommandFrameV2 {
        const NAME: &'static str = "command frame v2";
        const TYPE_NAME: &'static str = "motion_frames::CommandFrame@layout999";
        fn header(&self) -> &FrameHeader {
            &self.header
        }
        fn header_mut(&mut self) -> &mut FrameHeader {
            &mut self.header
        }
    }

    #[test]
    fn cleanup_domain_keeps_a_live_domain_and_removes_an_empty_one() {
        let env = TestEnv::new("cln");
        {
            let node = env.cfg.create_node("motion-io").unwrap();
            let _io = IoPorts::create(&node, &env.cfg.prefix).unwrap();
            let r = cleanup_domain(&env.cfg);
            assert_eq!(r.alive, 1, "{r:?}");
            assert!(!r.removed_global_mgmt && !r.domain_gone(), "{r:?}");
            assert!(!env.cfg.shm_files().is_empty());
        }
        let r = cleanup_domain(&env.cfg);
        println!("after drop: {r}");
        assert_eq!(r.alive, 0, "{r:?}");
        assert!(r.removed_global_mgmt && r.domain_gone(), "{r:?}");
        assert_eq!(env.cfg.shm_files(), Vec::<String>::new());
        // idempotent, and creates nothing
        let r = cleanup_domain(&env.cfg);
        assert!(!r.removed_global_mgmt && r.domain_gone(), "{r:?}");
        assert_eq!(env.cfg.shm_files(), Vec::<String>::new());
    }

    #[test]
    fn names_and_prefixes() {
        let n = service_names("motion");
        assert_eq!(n.command, "motion/command");
        assert_eq!(n.feedback, "motion/feedback");
        assert_eq!(n.command_ready, "motion/command_ready");
        assert_eq!(n.feedback_ready, "motion/feedback_ready");
        assert_eq!(IpcConfig::new("motion").file_prefix(), "iox2_motion_");
        assert_eq!(IpcConfig::new("cell 1/m").file_prefix(), "iox2_cell_1_m_");
        let cfg = IpcConfig::new("motion")
            .with_root("/tmp/x")
            .iceoryx2_config()
            .unwrap();
        assert_eq!(cfg.global.prefix.as_str(), "iox2_motion_");
        assert_eq!(cfg.global.root_path().to_string(), "/tmp/x/");
        assert!(matches!(
            IpcConfig::new("").iceoryx2_config(),
            Err(IpcError::Config(_))
        ));
    }

    #[test]
    fn peer_with_other_layout_cannot_attach_either_way() {
        let env = TestEnv::new("lay");
        let node = env.cfg.create_node("motion-supervisor").unwrap();
        let names = env.cfg.service_names();

        // current binary first, "newer" peer second
        let sup = SupervisorPorts::create(&node, &env.cfg.prefix).unwrap();
        let err = Ports::<CommandFrameV2, FeedbackFrame>::create_with_names(
            &node,
            &names.command,
            &names.command_ready,
            &names.feedback,
            &names.feedback_ready,
        )
        .unwrap_err();
        assert!(matches!(err, IpcError::LayoutMismatch { .. }), "{err:?}");
        assert!(err.is_version_mismatch());
        let msg = err.to_string();
        println!("{msg}");
        assert!(msg.contains("frame layout mismatch"), "{msg}");
        assert!(
            msg.contains(&format!("this binary speaks layout {LAYOUT_VERSION}")),
            "{msg}"
        );
        assert!(msg.contains("rebuild both from the same tree"), "{msg}");
        assert!(msg.contains(&names.command), "{msg}");
        drop(sup);

        // "newer" peer first, current binary second
        let v2 = Ports::<CommandFrameV2, FeedbackFrame>::create_with_names(
            &node,
            &names.command,
            &names.command_ready,
            &names.feedback,
            &names.feedback_ready,
        )
        .unwrap();
        let err = IoPorts::create(&node, &env.cfg.prefix).unwrap_err();
        assert!(matches!(err, IpcError::LayoutMismatch { .. }), "{err:?}");
        drop(v2);

        // with the v2 peer gone the services are free again
        let _io = IoPorts::create(&node, &env.cfg.prefix).unwrap();
    }

    #[test]
    fn second_supervisor_is_refused() {
        let env = TestEnv::new("dup");
        let node = env.cfg.create_node("motion-supervisor").unwrap();
        let _a = SupervisorPorts::create(&node, &env.cfg.prefix).unwrap();
        let err = SupervisorPorts::create(&node, &env.cfg.prefix).unwrap_err();
        assert!(
            matches!(
                err,
                IpcError::CreatePublisher {
                    error: PublisherCreateError::ExceedsMaxSupportedPublishers,
                    ..
                }
            ),
            "{err:?}"
        );
        println!("{err}");
        assert!(err.to_string().contains("same service_prefix"), "{err}");
    }

    #[test]
    fn bad_header_is_reported() {
        let env = TestEnv::new("hdr");
        let node = env.cfg.create_node("motion-io").unwrap();
        let mut sup = SupervisorPorts::create(&node, &env.cfg.prefix).unwrap();
        let mut io = IoPorts::create(&node, &env.cfg.prefix).unwrap();

        sup.publish(|f| f.header.axis_count = MAX_AXES as u32 + 1)
            .unwrap();
        let err = io.receive_latest().unwrap_err();
        assert!(
            matches!(
                err,
                IpcError::Layout {
                    error: LayoutError::TooManyAxes { .. },
                    ..
                }
            ),
            "{err:?}"
        );
        sup.publish(|f| f.header.axis_count = 1).unwrap();
        let s = io.receive_latest().unwrap().unwrap();
        assert_eq!(s.header.sequence, 2);
        assert_eq!(s.header.layout_version, LAYOUT_VERSION);
    }

    #[test]
    fn receive_latest_keeps_the_newest() {
        let env = TestEnv::new("lat");
        let node = env.cfg.create_node("motion-io").unwrap();
        let mut sup = SupervisorPorts::create(&node, &env.cfg.prefix).unwrap();
        let mut io = IoPorts::create(&node, &env.cfg.prefix).unwrap();
        assert!(io.receive_latest().unwrap().is_none());
        assert!(!io.try_wait().unwrap());
        for i in 0..5u32 {
            let sent = sup
                .send(|f| {
                    f.header.axis_count = 1;
                    f.axes[0].target_position = i64::from(i);
                })
                .unwrap();
            assert_eq!(sent.sequence, u64::from(i) + 1);
            assert_eq!(sent.receivers, 1);
        }
        assert!(io.try_wait().unwrap());
        assert!(!io.try_wait().unwrap());
        let s = io.receive_latest().unwrap().unwrap();
        assert_eq!(s.header.sequence, 5);
        assert_eq!(s.axes[0].target_position, 4);
        // buffer 2 with safe overflow: 3 frames were overwritten in the buffer,
        // 1 was drained and dropped here
        assert_eq!(io.skipped(), 1);
        assert!(io.receive_latest().unwrap().is_none());
        // the wait times out
        let t = std::time::Instant::now();
        assert!(!io.wait(Duration::from_millis(20)).unwrap());
        assert!(t.elapsed() >= Duration::from_millis(15));
    }
}
