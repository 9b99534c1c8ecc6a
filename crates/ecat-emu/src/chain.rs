//! The chain of emulated SubDevices and the wire: every EtherCAT frame that
//! arrives on the raw socket passes the SubDevices in chain order, each one
//! processing every datagram of the frame (auto-increment addresses counted
//! up, working counters incremented per the ESC rules), and goes back out
//! with the locally administered bit set in the source MAC address, as the
//! first real ESC does (ethercrab ignores frames carrying its own source
//! address).
//!
//! An *unplugged* SubDevice (and everything behind it) no longer sees
//! frames; the SubDevice before it closes its port, so the frame still
//! returns. With the first SubDevice unplugged (or [`Emulator::set_silent`])
//! nothing answers at all. Unplugged SubDevices keep running on their own
//! time: their SM watchdog expires.

use std::io;
use std::os::fd::AsRawFd;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::drive::{Drive, DriveConfig, DriveView};
use crate::esc::{Dropped, Esc, EscStats};

// The raw socket is the master's own (`motion_ethercat::socket`): plumbing,
// not protocol, so sharing it cannot hide a misreading of the standard.
pub use motion_ethercat::socket::ETHERTYPE;
use motion_ethercat::socket::{PacketSocket, Wait};

/// Frame-level counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ChainStats {
    pub frames: u64,
    pub replies: u64,
    pub dropped_silent: u64,
    pub malformed: u64,
}

/// The SubDevices and their plug state, without any I/O (unit tests drive
/// it with byte frames).
pub struct Chain {
    pub escs: Vec<Esc>,
    plugged: Vec<bool>,
    silent: bool,
    pub stats: ChainStats,
}

impl Chain {
    pub fn new(drives: Vec<DriveConfig>) -> Chain {
        let epoch = Instant::now();
        let escs: Vec<Esc> = drives
            .into_iter()
            .enumerate()
            .map(|(i, cfg)| Esc::new(Drive::new(cfg), i, epoch))
            .collect();
        let n = escs.len();
        let mut c = Chain {
            escs,
            plugged: vec![true; n],
            silent: false,
            stats: ChainStats::default(),
        };
        c.update_links();
        c
    }

    /// SubDevices a frame reaches (the plugged ones before the first
    /// unplugged one).
    pub fn reachable(&self) -> usize {
        if self.silent {
            return 0;
        }
        self.plugged.iter().take_while(|p| **p).count()
    }

    fn update_links(&mut self) {
        let r = self.reachable();
        for (i, e) in self.escs.iter_mut().enumerate() {
            e.port1_open = i + 1 < r;
        }
    }

    pub fn set_plugged(&mut self, position: usize, plugged: bool) {
        if let Some(p) = self.plugged.get_mut(position) {
            *p = plugged;
        }
        self.update_links();
    }

    pub fn set_silent(&mut self, silent: bool) {
        self.silent = silent;
        self.update_links();
    }

    /// Runs an Ethernet frame through the chain in place; `true` if it
    /// comes back (then `frame` is the reply).
    pub fn process(&mut self, frame: &mut [u8], now: Instant) -> bool {
        self.stats.frames += 1;
        if frame.len() < 16 || u16::from_be_bytes([frame[12], frame[13]]) != ETHERTYPE {
            self.stats.malformed += 1;
            return false;
        }
        let header = u16::from_le_bytes([frame[14], frame[15]]);
        let len = usize::from(header & 0x07FF);
        let kind = header >> 12;
        let reach = self.reachable();
        if reach == 0 {
            self.stats.dropped_silent += 1;
            return false;
        }
        if kind == 1 && 16 + len <= frame.len() {
            let pdus = &mut frame[16..16 + len];
            for s in 0..reach {
                let downstream = reach - 1 - s;
                let esc = &mut self.escs[s];
                esc.begin_frame(now, downstream);
                if !run_datagrams(esc, pdus) {
                    self.stats.malformed += 1;
                }
                esc.end_frame(now);
            }
        }
        // the first ESC sets the locally administered bit of the source
        frame[6] |= 0x02;
        self.stats.replies += 1;
        true
    }

    /// Time passes for every SubDevice (plugged or not).
    pub fn poll(&mut self, now: Instant) {
        for e in &mut self.escs {
            e.poll(now);
        }
    }
}

/// Processes every datagram of `pdus` in one ESC; `false` if the datagram
/// list is malformed (processing stops there).
fn run_datagrams(esc: &mut Esc, pdus: &mut [u8]) -> bool {
    let mut o = 0;
    loop {
        if o + 12 > pdus.len() {
            return false;
        }
        let cmd = pdus[o];
        let lenw = u16::from_le_bytes([pdus[o + 6], pdus[o + 7]]);
        let dlen = usize::from(lenw & 0x07FF);
        let more = lenw & 0x8000 != 0;
        if o + 12 + dlen > pdus.len() {
            return false;
        }
        let (head, rest) = pdus[o..].split_at_mut(10);
        let (data, tail) = rest.split_at_mut(dlen);
        let mut wkc = u16::from_le_bytes([tail[0], tail[1]]);
        datagram(esc, cmd, head, data, &mut wkc);
        tail[..2].copy_from_slice(&wkc.to_le_bytes());
        esc.stats.datagrams += 1;
        o += 12 + dlen;
        if !more {
            return true;
        }
    }
}

fn datagram(esc: &mut Esc, cmd: u8, head: &mut [u8], data: &mut [u8], wkc: &mut u16) {
    let adp = u16::from_le_bytes([head[2], head[3]]);
    let ado = u16::from_le_bytes([head[4], head[5]]);
    let auto = matches!(cmd, 1..=3 | 7..=9 | 13);
    if auto {
        // every SubDevice counts the position up; the one that sees 0 is
        // addressed
        head[2..4].copy_from_slice(&adp.wrapping_add(1).to_le_bytes());
    }
    let addressed = match cmd {
        1..=3 | 13 => adp == 0,
        4..=6 | 14 => adp == esc.station_address(),
        _ => true,
    };
    let inc = |w: &mut u16, n: u16| *w = w.wrapping_add(n);
    match cmd {
        // APRD, FPRD
        1 | 4 if addressed && esc.read_phys(ado, data) => inc(wkc, 1),
        // APWR, FPWR, BWR
        2 | 5 | 8 if addressed && esc.write_phys(ado, data) => inc(wkc, 1),
        // APRW, FPRW: read, then write what the master sent
        3 | 6 if addressed => {
            let sent = data.to_vec();
            let mut got = vec![0u8; data.len()];
            let r = esc.read_phys(ado, &mut got);
            let w = esc.write_phys(ado, &sent);
            if r {
                data.copy_from_slice(&got);
                inc(wkc, 1);
            }
            if w {
                inc(wkc, 2);
            }
        }
        // BRD: OR of everybody's data
        7 => {
            let mut got = vec![0u8; data.len()];
            if esc.read_phys(ado, &mut got) {
                for (d, g) in data.iter_mut().zip(got) {
                    *d |= g;
                }
                inc(wkc, 1);
            }
        }
        // BRW
        9 => {
            let sent = data.to_vec();
            let mut got = vec![0u8; data.len()];
            let r = esc.read_phys(ado, &mut got);
            let w = esc.write_phys(ado, &sent);
            if r {
                for (d, g) in data.iter_mut().zip(got) {
                    *d |= g;
                }
                inc(wkc, 1);
            }
            if w {
                inc(wkc, 2);
            }
        }
        // LRD, LWR, LRW
        10..=12 => {
            let la = u32::from_le_bytes([head[2], head[3], head[4], head[5]]);
            let n = esc.logical(cmd, la, data);
            inc(wkc, n);
        }
        // ARMW, FRMW: the addressed one reads, all others write
        13 | 14 => {
            if addressed {
                if esc.read_phys(ado, data) {
                    inc(wkc, 1);
                }
            } else if esc.write_phys(ado, data) {
                inc(wkc, 1);
            }
        }
        _ => {}
    }
}

/// Test-facing read-back of one SubDevice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubDeviceView {
    pub station_address: u16,
    pub al_status: u8,
    pub al_code: u16,
    pub watchdog_expired: bool,
    pub watchdog_time: Option<Duration>,
    pub sync0_activation: u8,
    pub sync0_cycle_ns: u32,
    pub sync_type: u16,
    pub drive: DriveView,
    pub stats: EscStats,
}

/// What to start.
#[derive(Clone, Debug)]
pub struct EmulatorConfig {
    /// Interface the raw socket binds to.
    pub interface: String,
    /// Network namespace (`ip netns` name) the interface lives in.
    pub netns: Option<String>,
    pub drives: Vec<DriveConfig>,
    /// SCHED_FIFO priority of the emulator thread (if permitted).
    pub priority: Option<i32>,
}

/// A running emulator: its thread answers frames until dropped.
pub struct Emulator {
    chain: Arc<Mutex<Chain>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

fn enter_netns(name: &str) -> io::Result<()> {
    let path = format!("/var/run/netns/{name}");
    let f = std::fs::File::open(&path)?;
    // SAFETY: setns on a valid namespace descriptor, this thread only.
    let r = unsafe { libc::setns(f.as_raw_fd(), libc::CLONE_NEWNET) };
    if r < 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(())
}

fn set_fifo(priority: i32) -> bool {
    let p = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: sets this thread's policy; the result is checked.
    unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &p) == 0 }
}

impl Emulator {
    /// Opens the socket (in the namespace) and starts answering.
    pub fn start(cfg: EmulatorConfig) -> io::Result<Emulator> {
        let chain = Arc::new(Mutex::new(Chain::new(cfg.drives.clone())));
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = std::sync::mpsc::channel::<io::Result<()>>();
        let thread = {
            let chain = chain.clone();
            let stop = stop.clone();
            std::thread::Builder::new()
                .name("ecat-emu".into())
                .spawn(move || {
                    let opened = (|| {
                        if let Some(ns) = &cfg.netns {
                            enter_netns(ns)?;
                        }
                        PacketSocket::open(&cfg.interface)
                    })();
                    let socket = match opened {
                        Ok(x) => {
                            let _ = tx.send(Ok(()));
                            x
                        }
                        Err(e) => {
                            let _ = tx.send(Err(e));
                            return;
                        }
                    };
                    if let Some(p) = cfg.priority {
                        set_fifo(p);
                    }
                    serve(&socket, &chain, &stop);
                })?
        };
        match rx.recv() {
            Ok(Ok(())) => Ok(Emulator {
                chain,
                stop,
                thread: Some(thread),
            }),
            Ok(Err(e)) => {
                let _ = thread.join();
                Err(e)
            }
            Err(_) => Err(io::Error::other("emulator thread died")),
        }
    }

    /// The chain, locked (tests inspect and change it; the emulator thread
    /// waits meanwhile).
    pub fn chain(&self) -> MutexGuard<'_, Chain> {
        self.chain.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Pull the cable in front of SubDevice `position`.
    pub fn unplug(&self, position: usize) {
        self.chain().set_plugged(position, false);
    }

    /// Plug it in again (it kept power and configuration).
    pub fn replug(&self, position: usize) {
        self.chain().set_plugged(position, true);
    }

    /// SubDevice `position` loses its power: it (and everything behind it)
    /// no longer answers; its mechanics coast where they are.
    pub fn power_off(&self, position: usize) {
        self.chain().set_plugged(position, false);
    }

    /// Its power returns: the ESC and the drive start from power-on (INIT,
    /// station address 0, default dictionary, the encoder at its start
    /// value), the mechanics where they were.
    pub fn power_on(&self, position: usize) {
        let mut c = self.chain();
        if let Some(e) = c.escs.get_mut(position) {
            e.power_cycle();
        }
        c.set_plugged(position, true);
    }

    /// Nothing answers at all (all frames lost).
    pub fn set_silent(&self, silent: bool) {
        self.chain().set_silent(silent);
    }

    /// SubDevice `position` refuses process data (working counter short)
    /// while staying in its AL state.
    pub fn refuse_process_data(&self, position: usize, refuse: bool) {
        if let Some(e) = self.chain().escs.get_mut(position) {
            e.pd_refused = refuse;
        }
    }

    /// SubDevice `position` falls out of OP by itself while it still
    /// answers its AL status (see [`Esc::drop_out_of_op`]): its working
    /// counter comes back short (1 of 3 in SAFE-OP, 0 in PRE-OP).
    pub fn drop_out_of_op(&self, position: usize, to: Dropped) {
        if let Some(e) = self.chain().escs.get_mut(position) {
            e.drop_out_of_op(to);
        }
    }

    /// SubDevice `position` refuses SAFE-OP → OP with AL status code
    /// `code` (`None`: it accepts again).
    pub fn refuse_op(&self, position: usize, code: Option<u16>) {
        if let Some(e) = self.chain().escs.get_mut(position) {
            e.op_refused = code;
        }
    }

    /// Drive `position` records the target position (0x607A) of every
    /// process-data frame it takes in cyclic synchronous position mode
    /// (`false`: stops and forgets them).
    pub fn record_targets(&self, position: usize, on: bool) {
        if let Some(e) = self.chain().escs.get_mut(position) {
            e.targets = on.then(Vec::new);
        }
    }

    /// The targets drive `position` recorded so far (taken: the record
    /// starts empty again).
    pub fn take_targets(&self, position: usize) -> Vec<i32> {
        let timed = self.take_timed_targets(position);
        timed.into_iter().map(|(t, _)| t).collect()
    }

    /// The targets drive `position` recorded so far with when their frames
    /// passed (taken: the record starts empty again).
    pub fn take_timed_targets(&self, position: usize) -> Vec<(i32, Instant)> {
        self.chain()
            .escs
            .get_mut(position)
            .and_then(|e| e.targets.as_mut().map(std::mem::take))
            .unwrap_or_default()
    }

    /// The drive at `position` faults with `code` (0x603F) at its next cycle.
    pub fn inject_fault(&self, position: usize, code: u16) {
        if let Some(e) = self.chain().escs.get_mut(position) {
            e.drive.inject_fault(code);
        }
    }

    /// Read-back of SubDevice `position`.
    pub fn view(&self, position: usize) -> Option<SubDeviceView> {
        let c = self.chain();
        let e = c.escs.get(position)?;
        let (act, cycle) = e.sync0();
        Some(SubDeviceView {
            station_address: e.station_address(),
            al_status: e.al_status(),
            al_code: e.al_code(),
            watchdog_expired: e.watchdog_expired(),
            watchdog_time: e.watchdog_time(),
            sync0_activation: act,
            sync0_cycle_ns: cycle,
            sync_type: e.drive.sync_type(),
            drive: e.drive.view(),
            stats: e.stats,
        })
    }

    pub fn stats(&self) -> ChainStats {
        self.chain().stats
    }

    /// Stops the thread (also on drop).
    pub fn stop(mut self) {
        self.shutdown();
    }

    fn shutdown(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        self.shutdown();
    }
}

fn serve(socket: &PacketSocket, chain: &Mutex<Chain>, stop: &AtomicBool) {
    let mut buf = vec![0u8; 2048];
    while !stop.load(Ordering::Relaxed) {
        match socket.wait(1_000_000) {
            // interface gone: do not spin
            Wait::Broken => std::thread::sleep(Duration::from_millis(1)),
            Wait::Readable => {
                while let Some(n) = socket.recv(&mut buf) {
                    let now = Instant::now();
                    let reply = {
                        let mut c = chain.lock().unwrap_or_else(|e| e.into_inner());
                        c.process(&mut buf[..n], now)
                    };
                    if reply {
                        socket.send(&buf[..n]);
                    }
                }
            }
            Wait::TimedOut => {}
        }
        let now = Instant::now();
        chain.lock().unwrap_or_else(|e| e.into_inner()).poll(now);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An Ethernet frame with the given datagrams (cmd, adp, ado, data).
    fn frame(dgrams: &[(u8, u16, u16, Vec<u8>)]) -> Vec<u8> {
        let mut pdus = Vec::new();
        for (k, (cmd, adp, ado, data)) in dgrams.iter().enumerate() {
            pdus.push(*cmd);
            pdus.push(k as u8);
            pdus.extend_from_slice(&adp.to_le_bytes());
            pdus.extend_from_slice(&ado.to_le_bytes());
            let more = if k + 1 < dgrams.len() { 0x8000 } else { 0 };
            pdus.extend_from_slice(&(data.len() as u16 | more).to_le_bytes());
            pdus.extend_from_slice(&[0, 0]);
            pdus.extend_from_slice(data);
            pdus.extend_from_slice(&[0, 0]);
        }
        let mut f = vec![0xFF; 6];
        f.extend_from_slice(&[0x10; 6]);
        f.extend_from_slice(&ETHERTYPE.to_be_bytes());
        f.extend_from_slice(&(pdus.len() as u16 | 0x1000).to_le_bytes());
        f.extend_from_slice(&pdus);
        f
    }

    /// (data, wkc) of datagram `k` of a processed frame.
    fn result(f: &[u8], k: usize) -> (Vec<u8>, u16) {
        let mut o = 16;
        for i in 0.. {
            let len = usize::from(u16::from_le_bytes([f[o + 6], f[o + 7]]) & 0x7FF);
            if i == k {
                let d = f[o + 10..o + 10 + len].to_vec();
                let w = u16::from_le_bytes([f[o + 10 + len], f[o + 11 + len]]);
                return (d, w);
            }
            o += 12 + len;
        }
        unreachable!()
    }

    fn chain(n: usize) -> Chain {
        Chain::new((0..n).map(|i| DriveConfig::new(&format!("D{i}"))).collect())
    }

    fn run(c: &mut Chain, dgrams: &[(u8, u16, u16, Vec<u8>)]) -> Option<Vec<u8>> {
        let mut f = frame(dgrams);
        c.process(&mut f, Instant::now()).then_some(f)
    }

    #[test]
    fn broadcast_counts_and_reply_source_address() {
        let mut c = chain(3);
        let f = run(&mut c, &[(7, 0, 0x0000, vec![0])]).unwrap();
        assert_eq!(result(&f, 0), (vec![0x11], 3));
        assert_eq!(&f[6..12], &[0x12, 0x10, 0x10, 0x10, 0x10, 0x10]);
        // unplugged behind the first: only it answers; silent: no reply
        c.set_plugged(1, false);
        assert_eq!(result(&run(&mut c, &[(7, 0, 0, vec![0])]).unwrap(), 0).1, 1);
        c.set_plugged(1, true);
        c.set_silent(true);
        assert!(run(&mut c, &[(7, 0, 0, vec![0])]).is_none());
    }

    #[test]
    fn auto_increment_then_configured_addressing() {
        let mut c = chain(3);
        // APWR to position 1 (ADP = -1), then FPRD of its AL status
        let f = run(
            &mut c,
            &[
                (
                    2,
                    0u16.wrapping_sub(1),
                    0x0010,
                    0x1001u16.to_le_bytes().to_vec(),
                ),
                (4, 0x1001, 0x0130, vec![0, 0]),
                (4, 0x2222, 0x0130, vec![0, 0]),
            ],
        )
        .unwrap();
        assert_eq!(result(&f, 0).1, 1);
        assert_eq!(c.escs[1].station_address(), 0x1001);
        assert_eq!(c.escs[0].station_address(), 0);
        // the FPRD ran in the same frame, after the APWR passed SubDevice 1
        assert_eq!(result(&f, 1), (vec![0x01, 0x00], 1));
        assert_eq!(result(&f, 2).1, 0, "nobody at 0x2222");
    }

    #[test]
    fn al_state_rules_and_codes() {
        let mut c = chain(1);
        run(&mut c, &[(2, 0, 0x0010, 0x1000u16.to_le_bytes().to_vec())]);
        // INIT → SAFE-OP is not a transition
        run(
            &mut c,
            &[(5, 0x1000, 0x0120, 0x0004u16.to_le_bytes().to_vec())],
        );
        assert_eq!((c.escs[0].al_status(), c.escs[0].al_code()), (0x11, 0x0011));
        // not acknowledged: a new request is ignored
        run(
            &mut c,
            &[(5, 0x1000, 0x0120, 0x0002u16.to_le_bytes().to_vec())],
        );
        assert_eq!(c.escs[0].al_status(), 0x11);
        // acknowledged; PRE-OP without mailbox sync managers is refused
        run(
            &mut c,
            &[(5, 0x1000, 0x0120, 0x0012u16.to_le_bytes().to_vec())],
        );
        assert_eq!((c.escs[0].al_status(), c.escs[0].al_code()), (0x11, 0x0016));
        // configure SM0/SM1 as the EEPROM says, then PRE-OP works
        let sm = |start: u16, control: u8| {
            let mut v = start.to_le_bytes().to_vec();
            v.extend_from_slice(&128u16.to_le_bytes());
            v.extend_from_slice(&[control, 0, 1, 0]);
            v
        };
        run(
            &mut c,
            &[
                (5, 0x1000, 0x0800, sm(0x1000, 0x26)),
                (5, 0x1000, 0x0808, sm(0x1080, 0x22)),
                (5, 0x1000, 0x0120, 0x0012u16.to_le_bytes().to_vec()),
            ],
        );
        assert_eq!((c.escs[0].al_status(), c.escs[0].al_code()), (0x02, 0));
        // the read mailbox is empty: reading it is refused (wkc 0); a
        // mailbox write is accepted once, then refused while full
        let f = run(&mut c, &[(4, 0x1000, 0x1080, vec![0; 128])]).unwrap();
        assert_eq!(result(&f, 0).1, 0);
        // a CoE upload of 0x1000 device type
        let mut req = vec![
            0x0A, 0, 0, 0, 0, 0x13, 0x00, 0x20, 0x40, 0x00, 0x10, 0, 0, 0, 0, 0,
        ];
        req.resize(128, 0);
        let f = run(&mut c, &[(5, 0x1000, 0x1000, req.clone())]).unwrap();
        assert_eq!(result(&f, 0).1, 1);
        let f = run(&mut c, &[(4, 0x1000, 0x080D, vec![0])]).unwrap();
        assert_eq!(result(&f, 0).0, [0x08], "response waiting");
        let f = run(&mut c, &[(4, 0x1000, 0x1080, vec![0; 128])]).unwrap();
        let (resp, wkc) = result(&f, 0);
        assert_eq!(wkc, 1);
        assert_eq!(&resp[8..16], &[0x43, 0x00, 0x10, 0, 0x92, 0x01, 0x02, 0x00]);
        let f = run(&mut c, &[(4, 0x1000, 0x080D, vec![0])]).unwrap();
        assert_eq!(result(&f, 0).0, [0x00], "read: empty again");
    }

    #[test]
    fn sii_reads_the_generated_image() {
        let mut c = chain(1);
        run(&mut c, &[(2, 0, 0x0010, 0x1000u16.to_le_bytes().to_vec())]);
        // read word 0x0008 (vendor id): control + address in one write
        let req = vec![0x00, 0x01, 0x08, 0x00, 0x00, 0x00];
        run(&mut c, &[(5, 0x1000, 0x0502, req)]);
        let f = run(
            &mut c,
            &[
                (4, 0x1000, 0x0502, vec![0; 2]),
                (4, 0x1000, 0x0508, vec![0; 8]),
            ],
        )
        .unwrap();
        let (ctl, _) = result(&f, 0);
        assert_eq!(ctl[1] & 0x80, 0, "not busy");
        assert_eq!(ctl[0] & 0x40, 0x40, "8-byte reads");
        let (data, _) = result(&f, 1);
        assert_eq!(u32::from_le_bytes(data[0..4].try_into().unwrap()), 0x0EC7);
    }

    #[test]
    fn dc_registers_only_where_supported() {
        let mut cfg = DriveConfig::new("NODC");
        cfg.dc = false;
        let mut c = Chain::new(vec![DriveConfig::new("DC"), cfg]);
        // latch receive times: counted by the DC SubDevice only
        let f = run(&mut c, &[(8, 0, 0x0900, vec![0; 4])]).unwrap();
        assert_eq!(result(&f, 0).1, 1);
        run(&mut c, &[(2, 0, 0x0010, 0x1000u16.to_le_bytes().to_vec())]);
        let f = run(
            &mut c,
            &[
                (4, 0x1000, 0x0900, vec![0; 16]),
                (4, 0x1000, 0x0008, vec![0; 2]),
            ],
        )
        .unwrap();
        let (times, w) = result(&f, 0);
        assert_eq!(w, 1);
        let p0 = u32::from_le_bytes(times[0..4].try_into().unwrap());
        let p1 = u32::from_le_bytes(times[4..8].try_into().unwrap());
        assert!(p1 > p0, "the frame comes back later through port 1");
        assert_eq!(
            result(&f, 1).0,
            0x010Cu16.to_le_bytes(),
            "DC, 64 bit, SYNC0"
        );
    }
}
