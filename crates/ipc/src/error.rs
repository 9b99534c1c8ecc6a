//! Failures of the IPC layer, worded for a controls engineer: which service,
//! what went wrong, and what iceoryx2 said.
//!
//! The service is named by an `Arc<str>` created with the ports, so the errors
//! the cycle can produce are built without heap allocation (a reference-count
//! increment); only start-up errors format new strings.

use std::sync::Arc;

use iceoryx2::node::NodeCreationFailure;
use iceoryx2::port::listener::{ListenerCreateError, ListenerWaitError};
use iceoryx2::port::notifier::{NotifierCreateError, NotifierNotifyError};
use iceoryx2::port::publisher::PublisherCreateError;
use iceoryx2::port::subscriber::SubscriberCreateError;
use iceoryx2::port::update_connections::ConnectionFailure;
use iceoryx2::port::{LoanError, ReceiveError, SendError};
use iceoryx2::service::builder::event::{EventCreateError, EventOpenError};
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeCreateError, PublishSubscribeOpenError,
};
use iceoryx2::service::service_name::ServiceNameError;

use motion_frames::{LayoutError, LAYOUT_VERSION};

#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum IpcError {
    /// The domain cannot be turned into an iceoryx2 config.
    #[error("iceoryx2 configuration: {0}")]
    Config(String),
    /// The runtime directory, the session file or the domain's files are not
    /// what they must be (owner, mode, type, size).
    #[error("{0}")]
    Unsafe(String),
    /// No supervisor runs under this prefix (no session file, or it is stale).
    #[error("{0}")]
    NoSupervisor(String),
    /// A supervisor already runs under this prefix.
    #[error("{0}")]
    AlreadyRunning(String),
    /// The iceoryx2 node could not be created.
    #[error(
        "cannot create the iceoryx2 node (are /dev/shm and the runtime directory writable?) \
         (iceoryx2: {0:?})"
    )]
    Node(NodeCreationFailure),
    /// A service name could not be formed from the prefix.
    #[error(
        "{name:?} is not a valid iceoryx2 service name; check service_prefix (iceoryx2: {error:?})"
    )]
    ServiceName {
        name: String,
        error: ServiceNameError,
    },
    /// The service exists with a frame type of another layout.
    #[error(
        "frame layout mismatch on service '{service}': this binary speaks layout \
         {LAYOUT_VERSION}; the peer was built with another motion-frames version; rebuild both \
         from the same tree"
    )]
    LayoutMismatch { service: Arc<str> },
    /// The service was created by a process linked against another iceoryx2.
    #[error(
        "service '{service}' was created by a process linked against another iceoryx2 version \
         (this binary uses 0.10.0); rebuild both from the same tree"
    )]
    IceoryxVersionMismatch { service: Arc<str> },
    /// The supervisor creates its services exclusively: one exists already.
    #[error(
        "service '{service}' already exists: another process created it first; the \
         supervisor refuses to share its services (iceoryx2: {error:?})"
    )]
    CreateTopic {
        service: Arc<str>,
        error: PublishSubscribeCreateError,
    },
    #[error("cannot create event service '{service}' (iceoryx2: {error:?})")]
    CreateEvent {
        service: Arc<str>,
        error: EventCreateError,
    },
    /// A peer opens the supervisor's services; they must exist.
    #[error(
        "cannot open service '{service}': {} (iceoryx2: {error:?})",
        open_hint(error)
    )]
    OpenTopic {
        service: Arc<str>,
        error: PublishSubscribeOpenError,
    },
    #[error("cannot open event service '{service}' (iceoryx2: {error:?})")]
    OpenEvent {
        service: Arc<str>,
        error: EventOpenError,
    },
    #[error("cannot publish on '{service}': {} (iceoryx2: {error:?})", match error {
        PublisherCreateError::ExceedsMaxSupportedPublishers => "another process already publishes there",
        _ => "iceoryx2 refused",
    })]
    CreatePublisher {
        service: Arc<str>,
        error: PublisherCreateError,
    },
    #[error("cannot subscribe to '{service}': {} (iceoryx2: {error:?})", match error {
        SubscriberCreateError::ExceedsMaxSupportedSubscribers => "every subscriber slot is taken",
        _ => "iceoryx2 refused",
    })]
    CreateSubscriber {
        service: Arc<str>,
        error: SubscriberCreateError,
    },
    #[error("cannot notify on '{service}' (iceoryx2: {error:?})")]
    CreateNotifier {
        service: Arc<str>,
        error: NotifierCreateError,
    },
    #[error("cannot listen on '{service}' (iceoryx2: {error:?})")]
    CreateListener {
        service: Arc<str>,
        error: ListenerCreateError,
    },
    /// No shared-memory sample could be loaned for a frame.
    #[error("no shared-memory sample available to publish on '{service}' (iceoryx2: {error:?})")]
    Loan { service: Arc<str>, error: LoanError },
    /// A frame could not be delivered.
    #[error(
        "frame on '{service}' could not be delivered to every subscriber (iceoryx2: {error:?})"
    )]
    Send { service: Arc<str>, error: SendError },
    /// Receiving a frame failed.
    #[error("cannot receive on '{service}': {} (iceoryx2: {error:?})", match error {
        ReceiveError::ExceedsMaxBorrows => "too many received frames are still held",
        ReceiveError::ConnectionFailure(_) => "cannot connect to the publisher",
    })]
    Receive {
        service: Arc<str>,
        error: ReceiveError,
    },
    /// Connecting to a (new) peer port failed.
    #[error("cannot connect the ports of '{service}' (iceoryx2: {error:?})")]
    Connection {
        service: Arc<str>,
        error: ConnectionFailure,
    },
    #[error("wake-up on '{service}' failed (iceoryx2: {error:?})")]
    Notify {
        service: Arc<str>,
        error: NotifierNotifyError,
    },
    #[error("waiting for a wake-up on '{service}' failed (iceoryx2: {error:?})")]
    Wait {
        service: Arc<str>,
        error: ListenerWaitError,
    },
    /// A signal (SIGINT/SIGTERM/...) interrupted the wait; check the shutdown flag.
    #[error("waiting on '{service}' was interrupted by a signal")]
    Interrupted { service: Arc<str> },
    /// A received frame has a bad header.
    #[error("bad frame received on '{service}': {error}")]
    Layout {
        service: Arc<str>,
        error: LayoutError,
    },
    /// A received frame does not carry this session's key: it was not sent
    /// by the peer this process is bound to. Refused and counted.
    #[error("frame on '{service}' refused: it does not carry this session's key (a forged frame, or a peer of another supervisor)")]
    Forged { service: Arc<str> },
}

fn open_hint(e: &PublishSubscribeOpenError) -> &'static str {
    use PublishSubscribeOpenError as O;
    match e {
        O::DoesNotExist => {
            "no supervisor created it (is motion-supervisor running with this prefix?)"
        }
        O::InsufficientPermissions => "permission denied: run as the supervisor's user",
        O::ExceedsMaxNumberOfNodes => "too many processes are attached to this service",
        O::IncompatibleTypes => "the peer speaks another frame layout",
        O::HangsInCreation | O::ServiceInCorruptedState => {
            "the service is half-created or corrupt; restart the supervisor"
        }
        _ => "the service exists with other settings (another build?)",
    }
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

    /// True when the supervisor's services are not there (yet): a peer
    /// retries instead of giving up.
    pub fn is_no_supervisor(&self) -> bool {
        matches!(
            self,
            IpcError::NoSupervisor(_)
                | IpcError::OpenTopic {
                    error: PublishSubscribeOpenError::DoesNotExist,
                    ..
                }
                | IpcError::OpenEvent {
                    error: EventOpenError::DoesNotExist,
                    ..
                }
        )
    }
}
