//! The bare side of the `bare-*` modes: plain iceoryx2 ports carrying byte
//! arrays of the frames' sizes, with the frames' QoS, used by both the
//! measuring thread and the echo peer. Same sizes and settings as the
//! frames, so that the bare round trip differs from motion-io's only in
//! what motion-io does with a frame.

use crate::exchange::Exchange;
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{ipc, BackpressureStrategy, ServiceName};
use iceoryx2::sample::Sample;
use motion_frames::{CommandFrame, FeedbackFrame};
use motion_ipc::ports::{
    MAX_LISTENERS, MAX_SUBSCRIBERS, SUBSCRIBER_BUFFER, SUBSCRIBER_MAX_BORROWED,
};
use motion_ipc::wait::{ppoll_until, PollWake};

// The rest of the frames' QoS (`motion_ipc::ports` sets these inline).
const HISTORY: usize = 0;
const MAX_NOTIFIERS: usize = 1;
const MAX_PUBLISHERS: usize = 1;

/// Bare payloads: the sizes of the frames.
pub const PING: usize = std::mem::size_of::<CommandFrame>();
pub const PONG: usize = std::mem::size_of::<FeedbackFrame>();

/// A `[u8; N]` topic with the frames' QoS (the same settings as
/// `motion_ipc::ports`, so the bare peer differs only in payload type).
fn open_topic<const N: usize>(
    node: &Node<ipc::Service>,
    name: &str,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, [u8; N], ()>,
    String,
> {
    node.service_builder(&service(name)?)
        .publish_subscribe::<[u8; N]>()
        .enable_safe_overflow(true)
        .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
        .subscriber_max_borrowed_samples(SUBSCRIBER_MAX_BORROWED)
        .history_size(HISTORY)
        .max_publishers(MAX_PUBLISHERS)
        .max_subscribers(MAX_SUBSCRIBERS)
        .open_or_create()
        .map_err(|x| format!("open topic {name}: {x:?}"))
}

/// Plain iceoryx2 ports for `[u8; TX]` out and `[u8; RX]` in; the first 8
/// bytes carry the sequence number.
pub struct BareSide<const TX: usize, const RX: usize> {
    publisher: Publisher<ipc::Service, [u8; TX], ()>,
    subscriber: Subscriber<ipc::Service, [u8; RX], ()>,
    notifier: Notifier<ipc::Service>,
    listener: Listener<ipc::Service>,
    fd: i32,
    next: u64,
    /// The newest received sample, kept until the next one (as the cycle
    /// keeps its feedback).
    pub pending: Option<Sample<ipc::Service, [u8; RX], ()>>,
}

/// `name` as an iceoryx2 service name.
fn service(name: &str) -> Result<ServiceName, String> {
    ServiceName::new(name).map_err(|e| format!("service name {name:?}: {e:?}"))
}

impl<const TX: usize, const RX: usize> BareSide<TX, RX> {
    /// Publishes on `{prefix}/{tx}` (+ `_ready` event), subscribes to
    /// `{prefix}/{rx}` (+ `_ready`), with the frames' QoS.
    pub fn create(
        node: &Node<ipc::Service>,
        prefix: &str,
        tx: &str,
        rx: &str,
    ) -> Result<Self, String> {
        let topic_tx = open_topic::<TX>(node, &format!("{prefix}/{tx}"))?;
        let topic_rx = open_topic::<RX>(node, &format!("{prefix}/{rx}"))?;
        let event = |name: String| {
            node.service_builder(&service(&name)?)
                .event()
                .max_notifiers(MAX_NOTIFIERS)
                .max_listeners(MAX_LISTENERS)
                .open_or_create()
                .map_err(|x| format!("open event: {x:?}"))
        };
        let ev_tx = event(format!("{prefix}/{tx}_ready"))?;
        let ev_rx = event(format!("{prefix}/{rx}_ready"))?;
        let publisher = topic_tx
            .publisher_builder()
            .max_loaned_samples(1)
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .create()
            .map_err(|x| format!("publisher: {x:?}"))?;
        let subscriber = topic_rx
            .subscriber_builder()
            .buffer_size(SUBSCRIBER_BUFFER)
            .create()
            .map_err(|x| format!("subscriber: {x:?}"))?;
        let notifier = ev_tx
            .notifier_builder()
            .create()
            .map_err(|x| format!("notifier: {x:?}"))?;
        let listener = ev_rx
            .listener_builder()
            .create()
            .map_err(|x| format!("listener: {x:?}"))?;
        // SAFETY: only the number is kept; the listener owns the descriptor
        // and lives as long as `self`.
        let fd = unsafe {
            iceoryx2_bb_posix::file_descriptor::FileDescriptorBased::file_descriptor(&listener)
                .native_handle()
        };
        Ok(Self {
            publisher,
            subscriber,
            notifier,
            listener,
            fd,
            next: 1,
            pending: None,
        })
    }

    fn try_wait(&mut self) -> bool {
        matches!(self.listener.try_wait(|_| {}), Ok(n) if n > 0)
    }

    /// Loans, zeroes (as `placement_default` does for a frame), stamps
    /// `seq`, sends, notifies.
    pub fn publish(&mut self, seq: u64) -> Result<(), String> {
        let mut u = self
            .publisher
            .loan_uninit()
            .map_err(|e| format!("loan: {e:?}"))?;
        // SAFETY: the loaned payload is TX bytes, exclusively ours; every
        // byte is written before `assume_init`.
        let mut s = unsafe {
            std::ptr::write_bytes(u.payload_mut().as_mut_ptr() as *mut u8, 0, TX);
            u.assume_init()
        };
        s.payload_mut()[..8].copy_from_slice(&seq.to_le_bytes());
        s.send().map_err(|e| format!("send: {e:?}"))?;
        let _ = self.notifier.notify();
        Ok(())
    }

    /// The newest received message's sequence number (older ones dropped).
    pub fn receive_latest(&mut self) -> Option<u64> {
        let mut latest = None;
        while let Ok(Some(s)) = self.subscriber.receive() {
            latest = Some(s);
        }
        let s = latest?;
        let mut b = [0u8; 8];
        b.copy_from_slice(&s.payload()[..8]);
        self.pending = Some(s);
        Some(u64::from_le_bytes(b))
    }

    /// As `motion_ipc::Ports::wait_until`: `try_wait`, else `ppoll` on
    /// the listener's descriptor until the deadline.
    pub fn wait_fd_until(&mut self, deadline_ns: u64) -> bool {
        loop {
            if self.try_wait() {
                return true;
            }
            if ppoll_until(self.fd, deadline_ns) == PollWake::Deadline {
                return self.try_wait();
            }
        }
    }
}

impl<const TX: usize, const RX: usize> Exchange for BareSide<TX, RX> {
    fn clear(&mut self) {
        let _ = self.try_wait();
    }
    fn send(&mut self) -> Result<u64, String> {
        let seq = self.next;
        self.next += 1;
        self.publish(seq)?;
        Ok(seq)
    }
    fn wait_until(&mut self, deadline_ns: u64) -> bool {
        self.wait_fd_until(deadline_ns)
    }
    fn answer(&mut self) -> Option<u64> {
        self.receive_latest()
    }
}
