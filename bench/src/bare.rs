//! Plain iceoryx2 ports carrying byte arrays of the frames' sizes, built
//! with the frames' settings (`motion_ipc::ports::{topic_builder,
//! event_builder}`), and the echo that answers on them: the IPC bench's
//! floor, what iceoryx2 itself costs with the frames' payloads, so that the
//! round trip through motion-io differs from it only in what motion-io does
//! with a frame.

use iceoryx2::node::Node;
use iceoryx2::port::{listener::Listener, notifier::Notifier};
use iceoryx2::port::{publisher::Publisher, subscriber::Subscriber};
use iceoryx2::prelude::{ipc, BackpressureStrategy, ServiceName};
use iceoryx2::sample::Sample;
use motion_frames::{CommandFrame, FeedbackFrame};
use motion_ipc::ports::{event_builder, topic_builder, SUBSCRIBER_BUFFER};
use motion_ipc::wait::{ppoll_until, PollWake};
use std::fmt::Debug;

/// The payloads: the sizes of the command and the feedback frame.
pub const PING: usize = std::mem::size_of::<CommandFrame>();
pub const PONG: usize = std::mem::size_of::<FeedbackFrame>();

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

/// An iceoryx2 error as `WHAT: error`.
fn err<E: Debug>(what: &str) -> impl FnOnce(E) -> String + '_ {
    move |e| format!("{what}: {e:?}")
}

impl<const TX: usize, const RX: usize> BareSide<TX, RX> {
    /// Publishes on `{prefix}/{tx}` (+ `_ready` event), subscribes to
    /// `{prefix}/{rx}` (+ `_ready`); whichever side comes first creates.
    pub fn create(
        node: &Node<ipc::Service>,
        prefix: &str,
        tx: &str,
        rx: &str,
    ) -> Result<Self, String> {
        let name = |s: String| ServiceName::new(&s).map_err(err(&format!("service name {s:?}")));
        let (tx, rx) = (format!("{prefix}/{tx}"), format!("{prefix}/{rx}"));
        let publisher = (topic_builder::<[u8; TX]>(node, &name(tx.clone())?).open_or_create())
            .map_err(err(&format!("open topic {tx}")))?
            .publisher_builder()
            .max_loaned_samples(1)
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .create()
            .map_err(err("publisher"))?;
        let subscriber = (topic_builder::<[u8; RX]>(node, &name(rx.clone())?).open_or_create())
            .map_err(err(&format!("open topic {rx}")))?
            .subscriber_builder()
            .buffer_size(SUBSCRIBER_BUFFER)
            .create()
            .map_err(err("subscriber"))?;
        let event = |s: &str| {
            let e = event_builder(node, &name(format!("{s}_ready"))?).open_or_create();
            e.map_err(err("open event"))
        };
        let notifier = (event(&tx)?.notifier_builder().create()).map_err(err("notifier"))?;
        let listener = (event(&rx)?.listener_builder().create()).map_err(err("listener"))?;
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

    /// Takes a pending wake-up, if there is one.
    pub fn try_wait(&mut self) -> bool {
        matches!(self.listener.try_wait(|_| {}), Ok(n) if n > 0)
    }

    /// Loans, zeroes (as `placement_default` does for a frame), stamps
    /// `seq`, sends, notifies.
    pub fn publish(&mut self, seq: u64) -> Result<(), String> {
        let mut u = self.publisher.loan_uninit().map_err(err("loan"))?;
        // SAFETY: the loaned payload is TX bytes, exclusively ours; every
        // byte is written before `assume_init`.
        let mut s = unsafe {
            std::ptr::write_bytes(u.payload_mut().as_mut_ptr() as *mut u8, 0, TX);
            u.assume_init()
        };
        s.payload_mut()[..8].copy_from_slice(&seq.to_le_bytes());
        s.send().map_err(err("send"))?;
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
        let seq = u64::from_le_bytes(s.payload()[..8].try_into().ok()?);
        self.pending = Some(s);
        Some(seq)
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

impl<const TX: usize, const RX: usize> BareSide<TX, RX> {
    /// Publishes the next sequence number (from 1); returns it.
    pub fn send_next(&mut self) -> Result<u64, String> {
        let seq = self.next;
        self.next += 1;
        self.publish(seq)?;
        Ok(seq)
    }
}

/// Echoes until `stop` says so: the newest ping answered with a pong
/// carrying its sequence number, older ones dropped (as motion-io answers
/// only the newest command). Waiting in `ppoll` on the listener's
/// descriptor, bounded so that `stop` is seen without pings, or spinning.
pub fn echo(
    x: &mut BareSide<PONG, PING>,
    spin: bool,
    mut stop: impl FnMut() -> bool,
) -> Result<(), String> {
    while !stop() {
        if !spin {
            x.wait_fd_until(motion_rt::now_ns() + 100_000_000);
        }
        match x.receive_latest() {
            Some(seq) => {
                x.pending = None;
                x.publish(seq)?;
            }
            None if spin => std::hint::spin_loop(),
            None => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_ipc::{cleanup_domain, Domain};

    #[test]
    fn a_ping_is_echoed_with_its_sequence_number() {
        let root = std::path::PathBuf::from(format!("/tmp/mhb{}", std::process::id() % 1_000_000));
        let prefix = format!("mhbare{}", std::process::id());
        let domain = Domain::establish(&prefix, Some(&root)).unwrap();
        {
            let node = domain.create_node("bench").unwrap();
            let mut ping = BareSide::<PING, PONG>::create(&node, &prefix, "ping", "pong").unwrap();
            let mut pong = BareSide::<PONG, PING>::create(&node, &prefix, "pong", "ping").unwrap();
            assert_eq!((ping.send_next(), ping.send_next()), (Ok(1), Ok(2)));
            assert!(pong.wait_fd_until(motion_rt::now_ns() + 1_000_000_000));
            let mut rounds = 0;
            echo(&mut pong, true, || {
                rounds += 1;
                rounds > 100
            })
            .unwrap();
            assert!(ping.wait_fd_until(motion_rt::now_ns() + 1_000_000_000));
            assert_eq!(
                ping.receive_latest(),
                Some(2),
                "only the newest ping answered"
            );
            assert!(!ping.try_wait() && ping.receive_latest().is_none());
        }
        assert!(cleanup_domain(&domain).domain_gone());
        domain.withdraw();
        let _ = std::fs::remove_dir_all(&root);
    }
}
