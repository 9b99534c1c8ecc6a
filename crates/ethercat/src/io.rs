//! The bus thread's I/O: an AF_PACKET raw socket on the interface
//! (EtherType 0x88A4) and a minimal single-threaded executor that drives
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
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::pin::Pin;
use std::task::{Context, Poll, Waker};

use ethercrab::{PduRx, PduTx};
use motion_rt::now_ns;

const ETHERTYPE: u16 = 0x88A4;
const PACKET_QDISC_BYPASS: libc::c_int = 20;

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
    fd: OwnedFd,
    tx: PduTx<'sto>,
    rx: PduRx<'sto>,
    buf: [u8; 2048],
    pub counters: IoCounters,
}

fn open(interface: &str) -> io::Result<OwnedFd> {
    let proto = i32::from(ETHERTYPE.to_be());
    // SAFETY: plain socket(2); checked.
    let fd = unsafe { libc::socket(libc::AF_PACKET, libc::SOCK_RAW | libc::SOCK_NONBLOCK, proto) };
    if fd < 0 {
        return Err(io::Error::last_os_error());
    }
    // SAFETY: a fresh descriptor we own.
    let fd = unsafe { OwnedFd::from_raw_fd(fd) };
    let name = std::ffi::CString::new(interface)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "interface name"))?;
    // SAFETY: valid C string.
    let ifindex = unsafe { libc::if_nametoindex(name.as_ptr()) };
    if ifindex == 0 {
        return Err(io::Error::new(
            io::ErrorKind::NotFound,
            format!("no network interface {interface:?}"),
        ));
    }
    // SAFETY: all-zero sockaddr_ll is valid; fields set below.
    let mut sa: libc::sockaddr_ll = unsafe { std::mem::zeroed() };
    sa.sll_family = libc::AF_PACKET as u16;
    sa.sll_protocol = ETHERTYPE.to_be();
    sa.sll_ifindex = ifindex as i32;
    // SAFETY: sa is a valid sockaddr_ll of that size.
    let r = unsafe {
        libc::bind(
            fd.as_raw_fd(),
            (&sa as *const libc::sockaddr_ll).cast(),
            std::mem::size_of::<libc::sockaddr_ll>() as u32,
        )
    };
    if r < 0 {
        return Err(io::Error::last_os_error());
    }
    // Straight to the driver, past the qdisc (lower latency on real NICs);
    // not fatal where unsupported.
    let one: libc::c_int = 1;
    // SAFETY: valid option value pointer and length.
    unsafe {
        libc::setsockopt(
            fd.as_raw_fd(),
            libc::SOL_PACKET,
            PACKET_QDISC_BYPASS,
            (&one as *const libc::c_int).cast(),
            std::mem::size_of::<libc::c_int>() as u32,
        );
    }
    Ok(fd)
}

impl<'sto> BusIo<'sto> {
    /// Opens the raw socket on `interface` (needs CAP_NET_RAW).
    pub fn new(interface: &str, tx: PduTx<'sto>, rx: PduRx<'sto>) -> io::Result<BusIo<'sto>> {
        Ok(BusIo {
            fd: open(interface)?,
            tx,
            rx,
            buf: [0; 2048],
            counters: IoCounters::default(),
        })
    }

    /// Sends every frame ethercrab has ready.
    pub fn flush(&mut self) {
        let fd = self.fd.as_raw_fd();
        while let Some(frame) = self.tx.next_sendable_frame() {
            let r = frame.send_blocking(|bytes| {
                // SAFETY: bytes is a valid slice; fd a bound packet socket.
                let n = unsafe { libc::send(fd, bytes.as_ptr().cast(), bytes.len(), 0) };
                if n < 0 || n as usize != bytes.len() {
                    Err(ethercrab::error::Error::SendFrame)
                } else {
                    Ok(n as usize)
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
        if until_ns > now {
            let wait = until_ns - now;
            let ts = libc::timespec {
                tv_sec: (wait / 1_000_000_000) as libc::time_t,
                tv_nsec: (wait % 1_000_000_000) as libc::c_long,
            };
            let mut pfd = libc::pollfd {
                fd: self.fd.as_raw_fd(),
                events: libc::POLLIN,
                revents: 0,
            };
            // SAFETY: one valid pollfd, valid timespec, no signal mask.
            let r = unsafe { libc::ppoll(&mut pfd, 1, &ts, std::ptr::null()) };
            let broken = libc::POLLERR | libc::POLLHUP | libc::POLLNVAL;
            if r > 0 && pfd.revents & libc::POLLIN == 0 && pfd.revents & broken != 0 {
                // the interface is gone or down: never spin on it
                self.counters.socket_errors += 1;
                sleep_until(until_ns);
                return 0;
            }
        }
        let mut n = 0;
        loop {
            // SAFETY: all-zero sockaddr_ll is valid.
            let mut sa: libc::sockaddr_ll = unsafe { std::mem::zeroed() };
            let mut sl = std::mem::size_of::<libc::sockaddr_ll>() as u32;
            // SAFETY: buffer valid for its length; sa/sl as above.
            let len = unsafe {
                libc::recvfrom(
                    self.fd.as_raw_fd(),
                    self.buf.as_mut_ptr().cast(),
                    self.buf.len(),
                    libc::MSG_DONTWAIT,
                    (&mut sa as *mut libc::sockaddr_ll).cast(),
                    &mut sl,
                )
            };
            if len <= 0 {
                break;
            }
            if sa.sll_pkttype == libc::PACKET_OUTGOING {
                continue; // our own transmission
            }
            self.counters.received += 1;
            n += 1;
            match self.rx.receive_frame(&self.buf[..len as usize]) {
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
