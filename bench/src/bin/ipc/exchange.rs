//! What the measuring thread does with a peer, whatever the peer is: the
//! [`Exchange`] of one message and its answer. [`FrameSide`] is the
//! supervisor's own ports with real frames (the motion-io modes); the bare
//! modes' side is `motion_bench::bare::BareSide`. One trait, so that both
//! are measured by the very same loop.

use iceoryx2::prelude::ipc;
use iceoryx2::sample::Sample;
use motion_bench::bare::BareSide;
use motion_frames::FeedbackFrame;
use motion_ipc::SupervisorPorts;

/// The measuring side of one exchange.
pub trait Exchange {
    /// Clears wake-ups left over from earlier answers.
    fn clear(&mut self);
    /// Publishes one message and notifies; returns its sequence number.
    fn send(&mut self) -> Result<u64, String>;
    /// Waits for a wake-up until the absolute monotonic `deadline_ns`.
    fn wait_until(&mut self, deadline_ns: u64) -> bool;
    /// The sequence number answered by the newest reply, if one arrived.
    fn answer(&mut self) -> Option<u64>;
}

/// As the supervisor: `SupervisorPorts` with real frames.
pub struct FrameSide {
    ports: SupervisorPorts,
    axes: u32,
    pending: Option<Sample<ipc::Service, FeedbackFrame, ()>>,
}

impl FrameSide {
    /// The supervisor's ports, publishing commands for `axes` axes.
    pub fn new(ports: SupervisorPorts, axes: u32) -> Self {
        FrameSide {
            ports,
            axes,
            pending: None,
        }
    }
}

impl Exchange for FrameSide {
    fn clear(&mut self) {
        let _ = self.ports.try_wait();
    }
    fn send(&mut self) -> Result<u64, String> {
        let n = self.axes;
        let sent = self
            .ports
            .publish(|f| f.header.axis_count = n)
            .map_err(|e| e.to_string())?;
        let _ = self.ports.notify();
        Ok(sent.sequence)
    }
    fn wait_until(&mut self, deadline_ns: u64) -> bool {
        // Err (e.g. EINTR) counts as a wake-up, as in the cycle
        !matches!(self.ports.wait_until(deadline_ns), Ok(false))
    }
    fn answer(&mut self) -> Option<u64> {
        let s = self.ports.receive_latest().ok()??;
        let a = s.payload().answers_sequence;
        self.pending = Some(s); // kept until the next answer, as the cycle does
        Some(a)
    }
}

impl<const TX: usize, const RX: usize> Exchange for BareSide<TX, RX> {
    fn clear(&mut self) {
        let _ = self.try_wait();
    }
    fn send(&mut self) -> Result<u64, String> {
        self.send_next()
    }
    fn wait_until(&mut self, deadline_ns: u64) -> bool {
        self.wait_fd_until(deadline_ns)
    }
    fn answer(&mut self) -> Option<u64> {
        self.receive_latest()
    }
}
