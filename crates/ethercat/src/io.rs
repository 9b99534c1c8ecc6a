//! The bus thread's I/O: the raw socket on the interface
//! ([`crate::socket`]) and a minimal single-threaded executor that drives
//! ethercrab's futures.
//!
//! ethercrab's own TX/RX task is an async future that allocates a receive
//! buffer on every poll and ends on the first unexpected frame (e.g. a reply
//! that arrives after its frame timed out). Instead the bus thread does the
//! I/O itself, synchronously: poll the futures, send every frame ethercrab
//! has queued (`PduTx`), wait on the socket with `ppoll` (an exact timeout)
//! and hand each received frame to `PduRx`. One thread, fixed buffers, no
//! allocation, and a deadline per call: a cycle never waits longer than its
//! budget.

use std::future::Future;
use std::io;
use std::pin::Pin;
use std::task::{Context, Poll, Waker};

use ethercrab::{PduRx, PduTx};
use motion_rt::now_ns;

use crate::socket::{PacketSocket, Wait};

/// Frame-level counters of the socket.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IoCounters {
    pub sent: u64,
    pub received: u64,
    pub send_errors: u64,
    /// Received frames ethercrab had no waiting frame for (late answers).
    pub unmatched: u64,
    /// Waits that found the socket in error (interface down or gone).
    pub socket_errors: u64,
}

/// Sleeps to an absolute CLOCK_MONOTONIC time.
fn sleep_until(ns: u64) {
    let ts = libc::timespec {
        tv_sec: (ns / 1_000_000_000) as libc::time_t,
        tv_nsec: (ns % 1_000_000_000) as libc::c_long,
    };
    // SAFETY: valid timespec; EINTR just ends the sleep early.
    unsafe {
        libc::clock_nanosleep(
            libc::CLOCK_MONOTONIC,
            libc::TIMER_ABSTIME,
            &ts,
            std::ptr::null_mut(),
        );
    }
}

/// Socket plus ethercrab's frame queues.
pub struct BusIo<'sto> {
    socket: PacketSocket,
    tx: PduTx<'sto>,
    rx: PduRx<'sto>,
    buf: [u8; 2048],
    pub counters: IoCounters,
}

impl<'sto> BusIo<'sto> {
    /// Opens the raw socket on `interface` (needs CAP_NET_RAW).
    pub fn new(interface: &str, tx: PduTx<'sto>, rx: PduRx<'sto>) -> io::Result<BusIo<'sto>> {
        Ok(BusIo {
            socket: PacketSocket::open(interface)?,
            tx,
            rx,
            buf: [0; 2048],
            counters: IoCounters::default(),
        })
    }

    /// Sends every frame ethercrab has ready.
    pub fn flush(&mut self) {
        let socket = &self.socket;
        while let Some(frame) = self.tx.next_sendable_frame() {
            let r = frame.send_blocking(|bytes| {
                if socket.send(bytes) {
                    Ok(bytes.len())
                } else {
                    Err(ethercrab::error::Error::SendFrame)
                }
            });
            match r {
                Ok(_) => self.counters.sent += 1,
                Err(_) => self.counters.send_errors += 1,
            }
        }
    }

    /// Waits until a frame arrives or `until_ns` (CLOCK_MONOTONIC) passes,
    /// then hands every queued frame to ethercrab. Returns the number of
    /// frames received.
    pub fn receive(&mut self, until_ns: u64) -> usize {
        let now = now_ns();
        if until_ns > now && self.socket.wait(until_ns - now) == Wait::Broken {
            // the interface is gone or down: never spin on it
            self.counters.socket_errors += 1;
            sleep_until(until_ns);
            return 0;
        }
        let mut n = 0;
        while let Some(len) = self.socket.recv(&mut self.buf) {
            self.counters.received += 1;
            n += 1;
            match self.rx.receive_frame(&self.buf[..len]) {
                Ok(ethercrab::ReceiveAction::Processed) => {}
                Ok(ethercrab::ReceiveAction::Ignored) => {}
                Err(_) => self.counters.unmatched += 1,
            }
        }
        n
    }

    /// Drives `fut` to completion, or gives up at `until_ns` (then `None`;
    /// the caller drops the future, which frees its frame). `idle_ns`: the
    /// longest socket wait between polls (ethercrab's timers are only
    /// looked at when polled).
    pub fn run<F: Future>(
        &mut self,
        mut fut: Pin<&mut F>,
        until_ns: Option<u64>,
        idle_ns: u64,
    ) -> Option<F::Output> {
        let mut cx = Context::from_waker(Waker::noop());
        loop {
            if let Poll::Ready(v) = fut.as_mut().poll(&mut cx) {
                return Some(v);
            }
            self.flush();
            let now = now_ns();
            if until_ns.is_some_and(|u| now >= u) {
                return None;
            }
            let mut wake = now + idle_ns;
            if let Some(u) = until_ns {
                wake = wake.min(u);
            }
            self.receive(wake);
        }
    }

    /// Polls `fut` once more with the frames that arrived meanwhile
    /// (`None` if still pending); sends what it queued.
    pub fn poll_once<F: Future>(&mut self, fut: Pin<&mut F>) -> Option<F::Output> {
        let mut cx = Context::from_waker(Waker::noop());
        let r = fut.poll(&mut cx);
        self.flush();
        match r {
            Poll::Ready(v) => Some(v),
            Poll::Pending => None,
        }
    }
}

/// A future that is ready at `CLOCK_MONOTONIC` `until_ns`: a wait inside
/// the bus thread's futures (the executor polls them every idle period,
/// see [`BusIo::run`]).
pub(crate) struct Until(pub u64);

impl Future for Until {
    type Output = ();

    fn poll(self: Pin<&mut Self>, _: &mut Context<'_>) -> Poll<()> {
        if now_ns() >= self.0 {
            Poll::Ready(())
        } else {
            Poll::Pending
        }
    }
}
