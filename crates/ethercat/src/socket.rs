//! A raw `AF_PACKET` socket for EtherCAT frames (EtherType 0x88A4) on one
//! interface: non-blocking, past the qdisc where the kernel allows it,
//! waited on with `ppoll` (an exact timeout), our own transmissions skipped
//! on receive.
//!
//! Public because the test fixture `ecat-emu` answers on the same kind of
//! socket: one definition of the raw-socket plumbing for both ends of the
//! wire (it carries no protocol rule either end could misread).

use std::io;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};

/// EtherType of EtherCAT.
pub const ETHERTYPE: u16 = 0x88A4;
const PACKET_QDISC_BYPASS: libc::c_int = 20;

/// What a wait on the socket found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wait {
    /// A frame is ready to be received.
    Readable,
    /// The time ran out (or a signal interrupted the wait).
    TimedOut,
    /// The socket is in error: the interface is down or gone.
    Broken,
}

/// The bound socket.
pub struct PacketSocket {
    fd: OwnedFd,
}

impl PacketSocket {
    /// Opens and binds the socket on `interface` (needs `CAP_NET_RAW`).
    pub fn open(interface: &str) -> io::Result<PacketSocket> {
        let proto = i32::from(ETHERTYPE.to_be());
        // SAFETY: plain socket(2); checked.
        let fd =
            unsafe { libc::socket(libc::AF_PACKET, libc::SOCK_RAW | libc::SOCK_NONBLOCK, proto) };
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
        Ok(PacketSocket { fd })
    }

    /// Sends one frame; `true` if all of it went out.
    pub fn send(&self, frame: &[u8]) -> bool {
        // SAFETY: frame is a valid slice; fd a bound packet socket.
        let n = unsafe { libc::send(self.fd.as_raw_fd(), frame.as_ptr().cast(), frame.len(), 0) };
        n >= 0 && n as usize == frame.len()
    }

    /// Waits up to `timeout_ns` for a frame.
    pub fn wait(&self, timeout_ns: u64) -> Wait {
        let ts = libc::timespec {
            tv_sec: (timeout_ns / 1_000_000_000) as libc::time_t,
            tv_nsec: (timeout_ns % 1_000_000_000) as libc::c_long,
        };
        let mut pfd = libc::pollfd {
            fd: self.fd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd, valid timespec, no signal mask.
        let r = unsafe { libc::ppoll(&mut pfd, 1, &ts, std::ptr::null()) };
        let broken = libc::POLLERR | libc::POLLHUP | libc::POLLNVAL;
        if r <= 0 {
            Wait::TimedOut
        } else if pfd.revents & libc::POLLIN == 0 && pfd.revents & broken != 0 {
            Wait::Broken
        } else {
            Wait::Readable
        }
    }

    /// The next frame someone else sent (our own transmissions are
    /// skipped), into `buf`; `None` when none is queued.
    pub fn recv(&self, buf: &mut [u8]) -> Option<usize> {
        loop {
            // SAFETY: all-zero sockaddr_ll is valid.
            let mut sa: libc::sockaddr_ll = unsafe { std::mem::zeroed() };
            let mut sl = std::mem::size_of::<libc::sockaddr_ll>() as u32;
            // SAFETY: buffer valid for its length; sa/sl as above.
            let len = unsafe {
                libc::recvfrom(
                    self.fd.as_raw_fd(),
                    buf.as_mut_ptr().cast(),
                    buf.len(),
                    libc::MSG_DONTWAIT,
                    (&mut sa as *mut libc::sockaddr_ll).cast(),
                    &mut sl,
                )
            };
            if len <= 0 {
                return None;
            }
            if sa.sll_pkttype != libc::PACKET_OUTGOING {
                return Some(len as usize);
            }
        }
    }
}
