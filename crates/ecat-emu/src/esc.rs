//! One EtherCAT SubDevice controller (ESC): register file and process RAM,
//! SII EEPROM interface, FMMUs, sync managers (mailbox and buffered process
//! data), the AL state machine with status codes, distributed-clock
//! registers and the sync-manager watchdog, with the CiA 402 drive
//! ([`Drive`]) as its application.
//!
//! Register semantics follow the Beckhoff ESC datasheet (section II) as far
//! as the master needs them; read-only registers ignore writes (the working
//! counter still counts the access), the mailbox and process-data areas
//! follow the sync managers' rules (a full write mailbox and an empty read
//! mailbox refuse the access, so the working counter does not count it).

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use crate::coe::CoeServer;
use crate::drive::Drive;
use crate::sii::{self, layout};

/// AL states and status codes.
pub mod al {
    pub const INIT: u8 = 0x01;
    pub const PREOP: u8 = 0x02;
    pub const BOOT: u8 = 0x03;
    pub const SAFEOP: u8 = 0x04;
    pub const OP: u8 = 0x08;
    pub const ERROR: u8 = 0x10;

    pub const UNSPECIFIED: u16 = 0x0001;
    pub const INVALID_STATE_CHANGE: u16 = 0x0011;
    pub const BOOTSTRAP_NOT_SUPPORTED: u16 = 0x0013;
    pub const INVALID_MAILBOX_CONFIG: u16 = 0x0016;
    pub const SYNC_ERROR: u16 = 0x001A;
    pub const SM_WATCHDOG: u16 = 0x001B;
    pub const INVALID_OUTPUT_CONFIG: u16 = 0x001D;
    pub const INVALID_INPUT_CONFIG: u16 = 0x001E;
    pub const INVALID_DC_SYNC_CONFIG: u16 = 0x0030;
}

/// Where a SubDevice falls out of OP by itself (a test fault: see
/// [`Esc::drop_out_of_op`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dropped {
    /// SAFE-OP with the error flag and this AL status code (an SM watchdog
    /// 0x001B, a sync error 0x001A, ...): its inputs are still read, its
    /// outputs no longer taken (the application deactivated the output
    /// sync manager: 0x0817 bit 0), so it counts 1 of 3 in an LRW.
    SafeOp(u16),
    /// PRE-OP (its application restarted): no process data at all, 0 of 3.
    PreOp,
}

/// Time the ESC waits in SAFE-OP for the first process data after an OP
/// request before refusing with [`al::SM_WATCHDOG`].
pub const OP_REQUEST_TIMEOUT: Duration = Duration::from_secs(2);

const MEM: usize = 0x1_0000;
const SII_CONTROL_READ_SIZE_8: u16 = 0x0040;

#[derive(Clone, Copy, Debug, Default)]
struct Events {
    al_control: Option<u16>,
    sii: bool,
    dc_latch: bool,
    mbx_written: bool,
    mbx_read: bool,
    pd_written: bool,
}

/// Counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EscStats {
    pub datagrams: u64,
    pub pd_cycles: u64,
    pub mailbox_requests: u64,
    pub watchdog_expiries: u64,
    pub al_errors: u64,
}

#[derive(Clone, Copy, Debug)]
struct Sm {
    start: u16,
    len: u16,
    control: u8,
    enabled: bool,
}

impl Sm {
    fn mailbox(&self) -> bool {
        self.control & 0x03 == 0x02
    }
    fn ecat_writes(&self) -> bool {
        (self.control >> 2) & 0x03 == 0x01
    }
    fn end(&self) -> usize {
        usize::from(self.start) + usize::from(self.len)
    }
}

/// The ESC.
pub struct Esc {
    mem: Vec<u8>,
    pub drive: Drive,
    coe: CoeServer,
    eeprom: Vec<u8>,
    dc: bool,
    al_state: u8,
    al_error: bool,
    al_code: u16,
    op_requested_at: Option<Instant>,
    mbx_out_full: bool,
    mbx_in_full: bool,
    mbx_queue: VecDeque<Vec<u8>>,
    last_pd_write: Option<Instant>,
    wd_counter: u8,
    wd_expired: bool,
    /// This ESC's local clock: ns since `epoch` plus this offset.
    clock_base: u64,
    epoch: Instant,
    ev: Events,
    /// Port 1 has a link (a SubDevice follows).
    pub port1_open: bool,
    /// Position in the chain and SubDevices reachable behind it (for the
    /// DC receive times).
    position: usize,
    downstream: usize,
    frame_local: u64,
    next_tick: Option<Instant>,
    /// Test fault: logical (FMMU) accesses are refused — the working
    /// counter comes back short while the AL state stays as it is.
    pub pd_refused: bool,
    /// The output sync manager (SM2) is deactivated by the application
    /// (its PDI control register 0x0817 bit 0, ESC datasheet: "SyncManager
    /// deactivated by PDI"):
    /// EtherCAT writes to it are refused and not counted. Set when an error
    /// takes the ESC from OP to SAFE-OP; cleared when OP is asked for.
    out_sm_off: bool,
    /// Test fault: SAFE-OP → OP is refused with this AL status code.
    pub op_refused: Option<u16>,
    /// Clock drift, parts per million (the drive's `clock_ppm`).
    clock_ppm: f64,
    /// While recording: the target position (0x607A) of every frame whose
    /// outputs the drive took in cyclic synchronous position mode, and
    /// when the frame passed.
    pub targets: Option<Vec<(i32, Instant)>>,
    pub stats: EscStats,
}

fn u16_at(m: &[u8], a: usize) -> u16 {
    u16::from_le_bytes([m[a], m[a + 1]])
}
fn u32_at(m: &[u8], a: usize) -> u32 {
    u32::from_le_bytes([m[a], m[a + 1], m[a + 2], m[a + 3]])
}
fn u64_at(m: &[u8], a: usize) -> u64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&m[a..a + 8]);
    u64::from_le_bytes(b)
}

impl Esc {
    /// Power-on: registers at their reset values, AL INIT, station address 0.
    pub fn new(drive: Drive, position: usize, epoch: Instant) -> Esc {
        let dc = drive.cfg.dc;
        let clock_ppm = drive.cfg.clock_ppm;
        let info = sii::SiiInfo {
            name: drive.cfg.name.clone(),
            vendor_id: drive.cfg.vendor_id,
            product_code: drive.cfg.product_code,
            revision: drive.cfg.revision,
            serial: drive.cfg.serial,
            alias: 0,
            default_rx_bytes: drive.rx_bytes() as u16,
            default_tx_bytes: drive.tx_bytes() as u16,
        };
        let mut e = Esc {
            mem: vec![0; MEM],
            drive,
            coe: CoeServer::new(),
            eeprom: sii::image(&info),
            dc,
            al_state: al::INIT,
            al_error: false,
            al_code: 0,
            op_requested_at: None,
            mbx_out_full: false,
            mbx_in_full: false,
            mbx_queue: VecDeque::new(),
            last_pd_write: None,
            wd_counter: 0,
            wd_expired: false,
            // distinct clocks per SubDevice: offsets of whole seconds
            clock_base: 1_000_000_000 * (position as u64 + 1) + 12_345,
            epoch,
            ev: Events::default(),
            port1_open: false,
            position,
            downstream: 0,
            frame_local: 0,
            next_tick: None,
            pd_refused: false,
            out_sm_off: false,
            op_refused: None,
            clock_ppm,
            targets: None,
            stats: EscStats::default(),
        };
        e.reset_registers();
        e
    }

    fn reset_registers(&mut self) {
        let m = &mut self.mem;
        m[..0x1000].fill(0);
        m[0x0000] = 0x11; // type
        m[0x0001] = 0x01; // revision
        m[0x0002..0x0004].copy_from_slice(&1u16.to_le_bytes()); // build
        m[0x0004] = 8; // FMMUs
        m[0x0005] = 8; // sync managers
        m[0x0006] = 8; // RAM, KiB
        m[0x0007] = 0x0F; // ports 0 and 1: MII
        let features: u16 = if self.dc { 0x010C } else { 0x0000 };
        m[0x0008..0x000A].copy_from_slice(&features.to_le_bytes());
        let alias = u16_at(&self.eeprom, 8);
        m[0x0012..0x0014].copy_from_slice(&alias.to_le_bytes());
        m[0x0120] = al::INIT;
        m[0x0400..0x0402].copy_from_slice(&2498u16.to_le_bytes());
        m[0x0410..0x0412].copy_from_slice(&1000u16.to_le_bytes());
        m[0x0420..0x0422].copy_from_slice(&1000u16.to_le_bytes());
        m[0x0502..0x0504].copy_from_slice(&SII_CONTROL_READ_SIZE_8.to_le_bytes());
    }

    /// Power cycle: everything back to power-on — registers, AL state,
    /// station address 0, the drive's dictionary and state machine — but
    /// the mechanics stay where they are; the drive's encoder restarts at
    /// its start value (an incremental encoder's position is lost).
    pub fn power_cycle(&mut self) {
        let drive = self.drive.power_cycled();
        let epoch = self.epoch;
        let position = self.position;
        *self = Esc::new(drive, position, epoch);
    }

    pub fn station_address(&self) -> u16 {
        u16_at(&self.mem, 0x0010)
    }

    pub fn al_state(&self) -> u8 {
        self.al_state
    }

    /// AL status as in 0x0130 (state | error flag).
    pub fn al_status(&self) -> u8 {
        self.al_state | if self.al_error { al::ERROR } else { 0 }
    }

    pub fn al_code(&self) -> u16 {
        self.al_code
    }

    pub fn watchdog_expired(&self) -> bool {
        self.wd_expired
    }

    /// DC SYNC0 activation register 0x0981 and cycle 0x09A0.
    pub fn sync0(&self) -> (u8, u32) {
        (self.mem[0x0981], u32_at(&self.mem, 0x09A0))
    }

    /// SM watchdog time in force (0x0400 / 0x0420), `None` if disabled.
    pub fn watchdog_time(&self) -> Option<Duration> {
        let divider = u64::from(u16_at(&self.mem, 0x0400));
        let time = u64::from(u16_at(&self.mem, 0x0420));
        let enabled = self.sm(2).control & 0x40 != 0;
        (time != 0 && enabled).then(|| Duration::from_nanos((divider + 2) * 40 * time))
    }

    /// This ESC's local clock at `now`: it runs `clock_ppm` off the host's.
    fn local_time(&self, now: Instant) -> u64 {
        let ns = now.duration_since(self.epoch).as_nanos() as u64;
        let drift = (ns as f64 * self.clock_ppm * 1e-6) as i64;
        ns.wrapping_add_signed(drift) + self.clock_base
    }

    fn sm(&self, n: usize) -> Sm {
        let a = 0x0800 + 8 * n;
        Sm {
            start: u16_at(&self.mem, a),
            len: u16_at(&self.mem, a + 2),
            control: self.mem[a + 4],
            enabled: self.mem[a + 6] & 0x01 != 0,
        }
    }

    fn pd_active(&self) -> bool {
        self.al_state == al::SAFEOP || self.al_state == al::OP
    }

    // ------------------------------------------------------------- frames

    /// Start of a frame's pass through this ESC.
    pub fn begin_frame(&mut self, now: Instant, downstream: usize) {
        self.downstream = downstream;
        self.frame_local = self.local_time(now) + 500 * self.position as u64;
        self.refresh(now);
    }

    fn refresh(&mut self, now: Instant) {
        self.drive
            .set_operational(matches!(self.al_state, al::SAFEOP | al::OP));
        let mut dl: u16 = 0x0003 | 0x0010 | 0x0200 | 0x5000;
        if self.port1_open {
            dl |= 0x0020 | 0x0800;
        } else {
            dl |= 0x0400;
        }
        let status = u16::from(self.al_status());
        let code = self.al_code;
        let t = self.local_time(now);
        let wd = u16::from(!self.wd_expired);
        let m = &mut self.mem;
        m[0x0110..0x0112].copy_from_slice(&dl.to_le_bytes());
        m[0x0130..0x0132].copy_from_slice(&status.to_le_bytes());
        m[0x0134..0x0136].copy_from_slice(&code.to_le_bytes());
        m[0x0440..0x0442].copy_from_slice(&wd.to_le_bytes());
        m[0x0442] = self.wd_counter;
        for n in 0..8 {
            let a = 0x0800 + 8 * n;
            let full = match n {
                0 => self.mbx_out_full,
                1 => self.mbx_in_full,
                _ => false,
            };
            m[a + 5] = if full { 0x08 } else { 0x00 };
        }
        m[0x0817] = u8::from(self.out_sm_off);
        if self.dc {
            let sys = t.wrapping_add(u64_at(m, 0x0920));
            m[0x0910..0x0918].copy_from_slice(&sys.to_le_bytes());
        }
    }

    /// Register access is possible for this byte range (a SubDevice without
    /// DC has no DC registers: the access is not counted).
    fn implemented(&self, addr: usize, len: usize) -> bool {
        let end = addr + len;
        if end > MEM {
            return false;
        }
        !(!self.dc && addr < 0x0A00 && end > 0x0900)
    }

    /// Reads physical memory with the sync-manager rules; `false`: refused.
    pub fn read_phys(&mut self, addr: u16, out: &mut [u8]) -> bool {
        let a = usize::from(addr);
        if !self.implemented(a, out.len()) {
            return false;
        }
        let end = a + out.len();
        for n in 0..8 {
            let sm = self.sm(n);
            if !sm.enabled || sm.len == 0 || end <= usize::from(sm.start) || a >= sm.end() {
                continue;
            }
            if sm.mailbox() {
                if !sm.ecat_writes() {
                    if !self.mbx_in_full {
                        return false;
                    }
                    if end >= sm.end() {
                        self.ev.mbx_read = true;
                    }
                }
            } else {
                if !self.pd_active() {
                    return false;
                }
                if sm.ecat_writes() {
                    // reading the output buffer: allowed
                }
            }
        }
        out.copy_from_slice(&self.mem[a..end]);
        true
    }

    /// Writes physical memory with the register and sync-manager rules;
    /// `false`: refused (not counted).
    pub fn write_phys(&mut self, addr: u16, data: &[u8]) -> bool {
        let a = usize::from(addr);
        if !self.implemented(a, data.len()) {
            return false;
        }
        let end = a + data.len();
        if a >= 0x1000 {
            let mut pd_last = false;
            let mut mbx_last = false;
            for n in 0..8 {
                let sm = self.sm(n);
                if !sm.enabled || sm.len == 0 || end <= usize::from(sm.start) || a >= sm.end() {
                    continue;
                }
                if !sm.ecat_writes() {
                    return false;
                }
                if sm.mailbox() {
                    if self.mbx_out_full {
                        return false;
                    }
                    mbx_last |= end >= sm.end();
                } else {
                    if !self.pd_active() || self.out_sm_off {
                        return false;
                    }
                    pd_last |= end >= sm.end();
                }
            }
            self.mem[a..end].copy_from_slice(data);
            if mbx_last {
                self.mbx_out_full = true;
                self.ev.mbx_written = true;
            }
            if pd_last {
                self.ev.pd_written = true;
            }
            return true;
        }
        for (i, &b) in data.iter().enumerate() {
            let r = a + i;
            if self.register_writable(r) {
                self.mem[r] = b;
            }
        }
        let touches = |lo: usize, hi: usize| a < hi && end > lo;
        if touches(0x0120, 0x0122) {
            self.ev.al_control = Some(u16_at(&self.mem, 0x0120));
        }
        if touches(0x0502, 0x0504) {
            self.ev.sii = true;
        }
        if self.dc && touches(0x0900, 0x0901) {
            self.ev.dc_latch = true;
        }
        if self.dc && touches(0x0910, 0x0918) && a == 0x0910 {
            // a received system time: the difference to ours
            let mut b = [0u8; 8];
            let n = data.len().min(8);
            b[..n].copy_from_slice(&data[..n]);
            let received = u64::from_le_bytes(b);
            let ours = u64_at(&self.mem, 0x0910);
            let ours = if n == 4 { ours & 0xFFFF_FFFF } else { ours };
            let diff = ours as i128 - received as i128;
            let mag = diff.unsigned_abs().min(0x7FFF_FFFF) as u32;
            let v = if diff < 0 { mag | 0x8000_0000 } else { mag };
            self.mem[0x092C..0x0930].copy_from_slice(&v.to_le_bytes());
        }
        for n in 0..8 {
            let base = 0x0800 + 8 * n;
            if touches(base, base + 8) {
                self.sm_changed(n);
            }
        }
        true
    }

    fn register_writable(&self, r: usize) -> bool {
        let dc = self.dc;
        matches!(r,
            0x0010..=0x0013
            | 0x0100..=0x0103
            | 0x0120..=0x0121
            | 0x0200..=0x0203
            | 0x0300..=0x0313
            | 0x0400..=0x0401
            | 0x0410..=0x0411
            | 0x0420..=0x0421
            | 0x0500
            | 0x0502..=0x050F
            | 0x0600..=0x06FF)
            || (0x0800..0x0880).contains(&r) && !matches!((r - 0x0800) % 8, 5 | 7)
            || dc
                && matches!(r,
                0x0920..=0x092B
                | 0x0930..=0x0935
                | 0x0980..=0x0981
                | 0x0990..=0x0997
                | 0x09A0..=0x09A7)
    }

    fn sm_changed(&mut self, n: usize) {
        let sm = self.sm(n);
        if n <= 1 && !sm.enabled {
            if n == 0 {
                self.mbx_out_full = false;
            } else {
                self.mbx_in_full = false;
                self.mbx_queue.clear();
            }
        }
    }

    /// Logical (FMMU) access of `cmd` 10 LRD / 11 LWR / 12 LRW at logical
    /// address `la`; returns the working-counter increment.
    pub fn logical(&mut self, cmd: u8, la: u32, data: &mut [u8]) -> u16 {
        if self.pd_refused {
            return 0;
        }
        let orig = data.to_vec();
        let (mut read, mut wrote) = (false, false);
        for f in 0..8 {
            let b = 0x0600 + 16 * f;
            if self.mem[b + 12] & 0x01 == 0 {
                continue;
            }
            let ls = u32_at(&self.mem, b);
            let len = u32::from(u16_at(&self.mem, b + 4));
            let ps = u32::from(u16_at(&self.mem, b + 8));
            let ty = self.mem[b + 11];
            let lo = ls.max(la);
            let hi = (ls + len).min(la + data.len() as u32);
            if lo >= hi {
                continue;
            }
            let d0 = (lo - la) as usize;
            let n = (hi - lo) as usize;
            let phys = (ps + (lo - ls)) as u16;
            if ty & 0x01 != 0 && (cmd == 10 || cmd == 12) {
                let mut buf = vec![0u8; n];
                if self.read_phys(phys, &mut buf) {
                    data[d0..d0 + n].copy_from_slice(&buf);
                    read = true;
                }
            }
            if ty & 0x02 != 0
                && (cmd == 11 || cmd == 12)
                && self.write_phys(phys, &orig[d0..d0 + n])
            {
                wrote = true;
            }
        }
        let mut wkc = 0;
        if read {
            wkc += 1;
        }
        if wrote {
            wkc += if cmd == 12 { 2 } else { 1 };
        }
        wkc
    }

    /// End of a frame's pass: the events raised by the accesses.
    pub fn end_frame(&mut self, now: Instant) {
        let ev = std::mem::take(&mut self.ev);
        if let Some(v) = ev.al_control {
            self.al_control(v, now);
        }
        if ev.sii {
            self.sii_command();
        }
        if ev.dc_latch {
            let t0 = self.frame_local;
            let t1 = if self.port1_open {
                t0 + 1000 * self.downstream as u64 + 200
            } else {
                0
            };
            let m = &mut self.mem;
            m[0x0900..0x0904].copy_from_slice(&(t0 as u32).to_le_bytes());
            m[0x0904..0x0908].copy_from_slice(&(t1 as u32).to_le_bytes());
            m[0x0908..0x0910].fill(0);
            m[0x0918..0x0920].copy_from_slice(&t0.to_le_bytes());
        }
        if ev.mbx_written {
            self.stats.mailbox_requests += 1;
            let sm0 = self.sm(0);
            let req = self.mem[usize::from(sm0.start)..sm0.end()].to_vec();
            self.mbx_out_full = false;
            if self.al_state != al::INIT {
                let preop = self.al_state == al::PREOP;
                let size = usize::from(self.sm(1).len);
                if let Some(resp) = self.coe.handle(&req, &mut self.drive, preop, size) {
                    self.mbx_queue.push_back(resp);
                }
            }
        }
        if ev.mbx_read {
            self.mbx_in_full = false;
        }
        if !self.mbx_in_full {
            if let Some(resp) = self.mbx_queue.pop_front() {
                let sm1 = self.sm(1);
                if sm1.enabled && sm1.len > 0 {
                    let area = &mut self.mem[usize::from(sm1.start)..sm1.end()];
                    area.fill(0);
                    let n = resp.len().min(area.len());
                    area[..n].copy_from_slice(&resp[..n]);
                    self.mbx_in_full = true;
                }
            }
        }
        if ev.pd_written {
            self.last_pd_write = Some(now);
            if self.al_state == al::SAFEOP && self.op_requested_at.is_some() {
                self.op_requested_at = None;
                self.al_state = al::OP;
            }
            let valid = self.al_state == al::OP;
            if valid {
                let sm2 = self.sm(2);
                let out = self.mem[usize::from(sm2.start)..sm2.end()].to_vec();
                self.drive.apply_outputs(&out);
                if let (Some(t), 8) = (&mut self.targets, self.drive.mode()) {
                    t.push((self.drive.od.get_signed(0x607A, 0) as i32, now));
                }
            }
            self.drive.cycle(valid);
            self.write_inputs();
            self.stats.pd_cycles += 1;
        }
        self.refresh(now);
    }

    fn write_inputs(&mut self) {
        let sm3 = self.sm(3);
        if sm3.len > 0 {
            let mut buf = vec![0u8; usize::from(sm3.len)];
            self.drive.fill_inputs(&mut buf);
            self.mem[usize::from(sm3.start)..sm3.end()].copy_from_slice(&buf);
        }
    }

    fn error(&mut self, code: u16) {
        self.al_error = true;
        self.al_code = code;
        self.stats.al_errors += 1;
    }

    fn al_control(&mut self, value: u16, now: Instant) {
        let req = (value & 0x0F) as u8;
        let ack = value & 0x10 != 0;
        if self.al_error && !ack {
            // an error must be acknowledged before anything else happens
            return;
        }
        if ack {
            self.al_error = false;
            self.al_code = 0;
        }
        let cur = self.al_state;
        if req == cur {
            if req == al::SAFEOP {
                self.op_requested_at = None;
            }
            return;
        }
        match (cur, req) {
            (_, al::INIT) => {
                if cur == al::OP {
                    self.drive.outputs_lost(false);
                }
                self.al_state = al::INIT;
                self.op_requested_at = None;
                self.out_sm_off = false;
                self.mbx_out_full = false;
                self.mbx_in_full = false;
                self.mbx_queue.clear();
                self.coe = CoeServer::new();
            }
            (al::INIT, al::PREOP) => {
                let (s0, s1) = (self.sm(0), self.sm(1));
                let ok = s0.enabled
                    && s0.start == layout::MBX_OUT_START
                    && s0.len == layout::MBX_SIZE
                    && s0.control == layout::SM0_CONTROL
                    && s1.enabled
                    && s1.start == layout::MBX_IN_START
                    && s1.len == layout::MBX_SIZE
                    && s1.control == layout::SM1_CONTROL;
                if ok {
                    self.al_state = al::PREOP;
                } else {
                    self.error(al::INVALID_MAILBOX_CONFIG);
                }
            }
            (al::PREOP, al::SAFEOP) => match self.check_pd_config() {
                Ok(()) => {
                    self.al_state = al::SAFEOP;
                    self.write_inputs();
                }
                Err(code) => self.error(code),
            },
            (al::SAFEOP, al::OP) if self.op_refused.is_some() => {
                self.error(self.op_refused.unwrap_or(al::UNSPECIFIED));
            }
            (al::SAFEOP, al::OP) => {
                // the application takes outputs again
                self.out_sm_off = false;
                let recent = self.last_pd_write.is_some_and(|t| {
                    now.duration_since(t)
                        < self.watchdog_time().unwrap_or(Duration::from_millis(100))
                });
                if recent {
                    self.al_state = al::OP;
                } else {
                    self.op_requested_at = Some(now);
                }
            }
            (al::OP, al::SAFEOP) => {
                self.drive.outputs_lost(false);
                self.al_state = al::SAFEOP;
            }
            (al::OP | al::SAFEOP, al::PREOP) => {
                if cur == al::OP {
                    self.drive.outputs_lost(false);
                }
                self.op_requested_at = None;
                self.out_sm_off = false;
                self.al_state = al::PREOP;
            }
            (_, al::BOOT) => self.error(al::BOOTSTRAP_NOT_SUPPORTED),
            _ => self.error(al::INVALID_STATE_CHANGE),
        }
    }

    fn check_pd_config(&self) -> Result<(), u16> {
        let (s2, s3) = (self.sm(2), self.sm(3));
        let rx = self.drive.rx_bytes();
        let tx = self.drive.tx_bytes();
        let out_ok = s2.start == layout::PD_OUT_START
            && usize::from(s2.len) == rx
            && s2.control & 0x0F == 0x04
            && (s2.enabled || rx == 0);
        if !out_ok {
            return Err(al::INVALID_OUTPUT_CONFIG);
        }
        let in_ok = s3.start == layout::PD_IN_START
            && usize::from(s3.len) == tx
            && s3.control & 0x0F == 0x00
            && (s3.enabled || tx == 0);
        if !in_ok {
            return Err(al::INVALID_INPUT_CONFIG);
        }
        if self.drive.sync_type() == 2 {
            let (act, cycle) = self.sync0();
            if !self.dc || act & 0x03 != 0x03 || cycle == 0 {
                return Err(al::INVALID_DC_SYNC_CONFIG);
            }
        }
        Ok(())
    }

    fn sii_command(&mut self) {
        let ctl = u16_at(&self.mem, 0x0502);
        let addr = u32_at(&self.mem, 0x0504) as usize;
        if ctl & 0x0100 != 0 {
            let mut b = [0xFFu8; 8];
            for (i, v) in b.iter_mut().enumerate() {
                if let Some(x) = self.eeprom.get(addr * 2 + i) {
                    *v = *x;
                }
            }
            self.mem[0x0508..0x0510].copy_from_slice(&b);
        } else if ctl & 0x0200 != 0 && ctl & 0x0001 != 0 {
            let d = [self.mem[0x0508], self.mem[0x0509]];
            if let Some(w) = self.eeprom.get_mut(addr * 2..addr * 2 + 2) {
                w.copy_from_slice(&d);
            }
        }
        // commands complete at once: not busy, read size 8 bytes
        let done = (ctl & 0x0001) | SII_CONTROL_READ_SIZE_8;
        self.mem[0x0502..0x0504].copy_from_slice(&done.to_le_bytes());
    }

    /// Time passes without a frame: the SM watchdog, an OP request waiting
    /// for process data, ramps of a drive without process data.
    pub fn poll(&mut self, now: Instant) {
        if self.al_state == al::OP {
            if let (Some(wd), Some(t)) = (self.watchdog_time(), self.last_pd_write) {
                if now.duration_since(t) > wd {
                    self.wd_expired = true;
                    self.wd_counter = self.wd_counter.wrapping_add(1);
                    self.stats.watchdog_expiries += 1;
                    self.al_state = al::SAFEOP;
                    self.error(al::SM_WATCHDOG);
                    self.out_sm_off = true;
                    self.drive.outputs_lost(true);
                }
            }
        }
        if let Some(t) = self.op_requested_at {
            if now.duration_since(t) > OP_REQUEST_TIMEOUT {
                self.op_requested_at = None;
                self.error(al::SM_WATCHDOG);
            }
        }
        let dt = Duration::from_secs_f64(self.drive.dt().max(1e-5));
        let exchanging = self.al_state == al::OP
            && self
                .last_pd_write
                .is_some_and(|t| now.duration_since(t) < dt * 3);
        if exchanging {
            self.next_tick = None;
        } else {
            let mut next = self.next_tick.unwrap_or(now);
            let mut n = 0;
            while next <= now && n < 1000 {
                self.drive.tick();
                next += dt;
                n += 1;
            }
            if n > 0 {
                self.write_inputs();
            }
            self.next_tick = Some(next);
        }
        self.refresh(now);
    }

    /// The SubDevice falls out of OP by itself (from OP or SAFE-OP), as a
    /// drive does after an SM-watchdog trip, an AL error or a restart of its
    /// application, while it still answers its AL status: a drive in
    /// Operation enabled takes its reaction to the lost outputs (ETG.6010,
    /// the abort connection option 0x6007 — here: a quick stop to Switch
    /// on disabled, or after an SM watchdog its fault reaction to Fault).
    pub fn drop_out_of_op(&mut self, to: Dropped) {
        if !matches!(self.al_state, al::OP | al::SAFEOP) {
            return;
        }
        let was_op = self.al_state == al::OP;
        self.op_requested_at = None;
        match to {
            Dropped::SafeOp(code) => {
                if was_op {
                    self.drive.outputs_lost(code == al::SM_WATCHDOG);
                }
                self.al_state = al::SAFEOP;
                self.out_sm_off = true;
                self.error(code);
            }
            Dropped::PreOp => {
                if was_op {
                    self.drive.outputs_lost(false);
                }
                self.al_state = al::PREOP;
                self.out_sm_off = false;
            }
        }
        self.refresh(Instant::now());
    }

    /// The CoE server's counters.
    pub fn coe_stats(&self) -> crate::coe::CoeStats {
        self.coe.stats
    }

    /// Raw register / RAM read without side effects (tests).
    pub fn peek(&self, addr: u16, len: usize) -> Vec<u8> {
        let a = usize::from(addr);
        self.mem[a..(a + len).min(MEM)].to_vec()
    }
}
