//! The process data layout of one drive as it is in force: the entries of
//! the assigned RxPDOs (master → drive) and TxPDOs (drive → master) in
//! order, each at its bit offset, and the packing / unpacking of the
//! drive's slice of the process image (little endian).
//!
//! The layout is whatever start-up settled on ([`crate::mapping`]): the
//! backend's own mapping written to a writable PDO, a predefined one
//! assigned, or a fixed one as the drive has it. Entries the backend does
//! not know (a fixed mapping's 0x60FF target velocity, padding) are carried
//! as zeros on the way out and skipped on the way in; objects the layout
//! lacks read as absent ([`Present`]), never as zero values that look real.
//! ethercrab reads the mapping back to size the sync managers and FMMUs, so
//! the bytes here and ethercrab's view agree by construction (checked at
//! start-up).

use crate::objects::*;

/// Most entries per direction.
pub const MAX_ENTRIES: usize = 32;
/// Most PDOs assigned per direction.
pub const MAX_PDOS: usize = 4;

/// Which objects carry the torque limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TorqueLimits {
    /// 0x60E0 / 0x60E1: one limit per direction.
    PerDirection,
    /// 0x6072 only: the larger of the two limits for both directions.
    MaxTorque,
}

/// One entry of the layout at its bit offset in its direction's image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mapped {
    pub entry: PdoEntry,
    pub bit: u16,
}

/// What the drive's inputs carry (a fixed mapping may lack any of it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Present {
    pub velocity: bool,
    pub torque: bool,
    pub digital_inputs: bool,
    pub touch_probes: bool,
    pub error_code: bool,
    pub mode_display: bool,
    /// The outputs carry 0x6060.
    pub mode: bool,
    /// The outputs carry a torque limit (per direction or 0x6072).
    pub torque_limit: Option<TorqueLimits>,
}

/// The layout of one drive's process data.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PdoLayout {
    rx: heapless::Vec<Mapped, MAX_ENTRIES>,
    tx: heapless::Vec<Mapped, MAX_ENTRIES>,
    rx_bits: u32,
    tx_bits: u32,
    /// The assigned PDO objects (0x1C12 / 0x1C13), in order.
    pub rx_pdos: heapless::Vec<u16, MAX_PDOS>,
    pub tx_pdos: heapless::Vec<u16, MAX_PDOS>,
    pub present: Present,
}

/// What the master writes each cycle (RxPDO values).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DriveOutputs {
    pub controlword: u16,
    pub target_position: i32,
    pub touch_probe_function: u16,
    /// Per mille of rated torque.
    pub torque_limit_positive: u16,
    /// Per mille of rated torque.
    pub torque_limit_negative: u16,
    pub mode: i8,
}

/// What the drive reports each cycle (TxPDO values; what the layout lacks
/// is 0, see [`PdoLayout::present`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DriveInputs {
    pub statusword: u16,
    pub position: i32,
    /// Counts/s (the drive's velocity unit must be counts/s).
    pub velocity: i32,
    /// Per mille of rated torque.
    pub torque: i16,
    pub digital_inputs: u32,
    pub touch_probe_status: u16,
    pub probe1_positive: i32,
    pub probe1_negative: i32,
    pub probe2_positive: i32,
    pub probe2_negative: i32,
    pub error_code: u16,
    pub mode_display: i8,
}

/// Why a list of entries is not a layout.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TooMany;

impl PdoLayout {
    /// The layout of `rx` then `tx` entries in that order (the entries of
    /// the assigned PDOs, `rx_pdos` / `tx_pdos`, concatenated).
    pub fn from_entries(
        rx: &[PdoEntry],
        tx: &[PdoEntry],
        rx_pdos: &[u16],
        tx_pdos: &[u16],
    ) -> Result<PdoLayout, TooMany> {
        let place =
            |list: &[PdoEntry]| -> Result<(heapless::Vec<Mapped, MAX_ENTRIES>, u32), TooMany> {
                let mut out = heapless::Vec::new();
                let mut bit = 0u32;
                for e in list {
                    out.push(Mapped {
                        entry: *e,
                        bit: u16::try_from(bit).map_err(|_| TooMany)?,
                    })
                    .map_err(|_| TooMany)?;
                    bit += u32::from(e.bits);
                }
                Ok((out, bit))
            };
        let (rx, rx_bits) = place(rx)?;
        let (tx, tx_bits) = place(tx)?;
        let mut l = PdoLayout {
            rx,
            tx,
            rx_bits,
            tx_bits,
            rx_pdos: heapless::Vec::from_slice(rx_pdos).map_err(|_| TooMany)?,
            tx_pdos: heapless::Vec::from_slice(tx_pdos).map_err(|_| TooMany)?,
            present: Present::default(),
        };
        let has_tx = |i: u16| l.has_tx(i);
        let has_rx = |i: u16| l.has_rx(i);
        l.present = Present {
            velocity: has_tx(0x606C),
            torque: has_tx(0x6077),
            digital_inputs: has_tx(0x60FD),
            touch_probes: has_rx(0x60B8) && has_tx(0x60B9),
            error_code: has_tx(0x603F),
            mode_display: has_tx(0x6061),
            mode: has_rx(0x6060),
            torque_limit: if has_rx(0x60E0) && has_rx(0x60E1) {
                Some(TorqueLimits::PerDirection)
            } else if has_rx(0x6072) {
                Some(TorqueLimits::MaxTorque)
            } else {
                None
            },
        };
        Ok(l)
    }

    /// The layout the backend writes when a drive lets it (and the one the
    /// unit tests use): every object it uses, the torque limits as given,
    /// 0x6060 / 0x6061 with `mode`.
    pub fn standard(torque: TorqueLimits, mode: bool) -> PdoLayout {
        let mut rx = vec![CONTROLWORD, TARGET_POSITION, TOUCH_PROBE_FUNCTION];
        match torque {
            TorqueLimits::PerDirection => rx.extend([POSITIVE_TORQUE_LIMIT, NEGATIVE_TORQUE_LIMIT]),
            TorqueLimits::MaxTorque => rx.push(MAX_TORQUE),
        }
        let mut tx = vec![
            STATUSWORD,
            POSITION_ACTUAL,
            VELOCITY_ACTUAL,
            TORQUE_ACTUAL,
            DIGITAL_INPUTS,
            TOUCH_PROBE_STATUS,
            TOUCH_PROBE_1_POSITIVE,
            TOUCH_PROBE_1_NEGATIVE,
            TOUCH_PROBE_2_POSITIVE,
            TOUCH_PROBE_2_NEGATIVE,
            ERROR_CODE,
        ];
        if mode {
            rx.push(MODES_OF_OPERATION);
            tx.push(MODES_OF_OPERATION_DISPLAY);
        }
        PdoLayout::from_entries(&rx, &tx, &[RXPDO_INDEX], &[TXPDO_INDEX])
            .expect("the standard layout fits")
    }

    /// RxPDO entries, in order, with their bit offsets.
    pub fn rx(&self) -> &[Mapped] {
        &self.rx
    }

    /// TxPDO entries, in order, with their bit offsets.
    pub fn tx(&self) -> &[Mapped] {
        &self.tx
    }

    pub fn has_rx(&self, index: u16) -> bool {
        self.rx.iter().any(|m| m.entry.index == index)
    }

    pub fn has_tx(&self, index: u16) -> bool {
        self.tx.iter().any(|m| m.entry.index == index)
    }

    /// Output (RxPDO) bytes.
    pub fn rx_bytes(&self) -> usize {
        self.rx_bits.div_ceil(8) as usize
    }

    /// Input (TxPDO) bytes.
    pub fn tx_bytes(&self) -> usize {
        self.tx_bits.div_ceil(8) as usize
    }

    /// Packs `out` into `buf` (the drive's output slice); entries the
    /// backend does not drive are 0. A short buffer leaves the rest
    /// unwritten: never panics.
    pub fn pack_outputs(&self, out: &DriveOutputs, buf: &mut [u8]) {
        for m in self.rx.iter() {
            let v: u32 = match m.entry.index {
                0x6040 => u32::from(out.controlword),
                0x607A => out.target_position as u32,
                0x60B8 => u32::from(out.touch_probe_function),
                0x60E0 => u32::from(out.torque_limit_positive),
                0x60E1 => u32::from(out.torque_limit_negative),
                0x6072 => u32::from(out.torque_limit_positive.max(out.torque_limit_negative)),
                0x6060 => out.mode as u8 as u32,
                _ => 0,
            };
            put_bits(buf, usize::from(m.bit), m.entry.bits, v);
        }
    }

    /// Unpacks the drive's input slice. Missing bytes read as 0.
    pub fn unpack_inputs(&self, buf: &[u8]) -> DriveInputs {
        let mut d = DriveInputs::default();
        for m in self.tx.iter() {
            let v = get_bits(buf, usize::from(m.bit), m.entry.bits);
            match m.entry.index {
                0x6041 => d.statusword = v as u16,
                0x6064 => d.position = v as i32,
                0x606C => d.velocity = v as i32,
                0x6077 => d.torque = v as u16 as i16,
                0x60FD => d.digital_inputs = v,
                0x60B9 => d.touch_probe_status = v as u16,
                0x60BA => d.probe1_positive = v as i32,
                0x60BB => d.probe1_negative = v as i32,
                0x60BC => d.probe2_positive = v as i32,
                0x60BD => d.probe2_negative = v as i32,
                0x603F => d.error_code = v as u16,
                0x6061 => d.mode_display = v as u8 as i8,
                _ => {}
            }
        }
        d
    }

    /// The layout in words for the start-up log: `RxPDO 0x1600 (12 B):
    /// 0x6040 controlword @0.0/16, …`.
    pub fn describe(&self) -> Vec<String> {
        let side = |name: &str, pdos: &[u16], list: &[Mapped], bytes: usize| {
            let pdos: Vec<String> = pdos.iter().map(|p| format!("{p:#06X}")).collect();
            let entries: Vec<String> = list
                .iter()
                .map(|m| {
                    format!(
                        "{} @{}.{}/{}",
                        m.entry.label(),
                        m.bit / 8,
                        m.bit % 8,
                        m.entry.bits
                    )
                })
                .collect();
            format!(
                "{name} {} ({bytes} B): {}",
                pdos.join("+"),
                entries.join(", ")
            )
        };
        vec![
            side("RxPDO", &self.rx_pdos, &self.rx, self.rx_bytes()),
            side("TxPDO", &self.tx_pdos, &self.tx, self.tx_bytes()),
        ]
    }
}

/// Writes the low `bits` bits of `v` at bit offset `at` (little endian).
fn put_bits(buf: &mut [u8], at: usize, bits: u8, v: u32) {
    let bits = usize::from(bits).min(32);
    if at % 8 == 0 && bits % 8 == 0 {
        let n = bits / 8;
        if let Some(dst) = buf.get_mut(at / 8..at / 8 + n) {
            dst.copy_from_slice(&v.to_le_bytes()[..n]);
        }
        return;
    }
    for k in 0..bits {
        let (byte, bit) = ((at + k) / 8, (at + k) % 8);
        if let Some(b) = buf.get_mut(byte) {
            if v & (1 << k) != 0 {
                *b |= 1 << bit;
            } else {
                *b &= !(1 << bit);
            }
        }
    }
}

/// Reads `bits` bits at bit offset `at` (little endian; missing bits 0).
fn get_bits(buf: &[u8], at: usize, bits: u8) -> u32 {
    let bits = usize::from(bits).min(32);
    if at % 8 == 0 && bits % 8 == 0 {
        let mut b = [0u8; 4];
        let n = bits / 8;
        if let Some(src) = buf.get(at / 8..at / 8 + n) {
            b[..n].copy_from_slice(src);
        }
        return u32::from_le_bytes(b);
    }
    let mut v = 0u32;
    for k in 0..bits {
        let (byte, bit) = ((at + k) / 8, (at + k) % 8);
        if buf.get(byte).is_some_and(|b| b & (1 << bit) != 0) {
            v |= 1 << k;
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_order() {
        let l = PdoLayout::standard(TorqueLimits::PerDirection, false);
        let rx: Vec<u16> = l.rx().iter().map(|m| m.entry.index).collect();
        assert_eq!(rx, [0x6040, 0x607A, 0x60B8, 0x60E0, 0x60E1]);
        assert_eq!(l.rx_bytes(), 12);
        let tx: Vec<u16> = l.tx().iter().map(|m| m.entry.index).collect();
        assert_eq!(
            tx,
            [
                0x6041, 0x6064, 0x606C, 0x6077, 0x60FD, 0x60B9, 0x60BA, 0x60BB, 0x60BC, 0x60BD,
                0x603F
            ]
        );
        assert_eq!(l.tx_bytes(), 2 + 4 + 4 + 2 + 4 + 2 + 16 + 2);
        assert_eq!(l.present.torque_limit, Some(TorqueLimits::PerDirection));
        assert!(l.present.velocity && l.present.touch_probes && !l.present.mode);

        let m = PdoLayout::standard(TorqueLimits::MaxTorque, true);
        let rx: Vec<u16> = m.rx().iter().map(|m| m.entry.index).collect();
        assert_eq!(rx, [0x6040, 0x607A, 0x60B8, 0x6072, 0x6060]);
        assert_eq!(m.rx_bytes(), 11);
        assert!(m.present.mode && m.present.mode_display);
        assert_eq!(
            m.describe()[0],
            "RxPDO 0x1600 (11 B): 0x6040 controlword @0.0/16, 0x607A target position @2.0/32, \
             0x60B8 touch probe function @6.0/16, 0x6072 max torque @8.0/16, 0x6060 modes of \
             operation @10.0/8"
        );
    }

    #[test]
    fn pack_unpack() {
        let l = PdoLayout::standard(TorqueLimits::PerDirection, false);
        let out = DriveOutputs {
            controlword: 0x000F,
            target_position: -2,
            touch_probe_function: 0x1115,
            torque_limit_positive: 1000,
            torque_limit_negative: 300,
            mode: 8,
        };
        let mut buf = [0u8; 12];
        l.pack_outputs(&out, &mut buf);
        assert_eq!(
            buf,
            [0x0F, 0, 0xFE, 0xFF, 0xFF, 0xFF, 0x15, 0x11, 0xE8, 0x03, 0x2C, 0x01]
        );
        // short buffers never panic
        l.pack_outputs(&out, &mut buf[..3]);

        let m = PdoLayout::standard(TorqueLimits::MaxTorque, true);
        let mut b2 = [0u8; 11];
        m.pack_outputs(&out, &mut b2);
        assert_eq!(&b2[8..], &[0xE8, 0x03, 8]);

        let mut ibuf = vec![0u8; l.tx_bytes()];
        let vals: [(usize, &[u8]); 4] = [
            (0, &[0x37, 0x16]),
            (2, &(-123456i32).to_le_bytes()),
            (10, &(-50i16).to_le_bytes()),
            (34, &0x8611u16.to_le_bytes()),
        ];
        for (at, b) in vals {
            ibuf[at..at + b.len()].copy_from_slice(b);
        }
        let d = l.unpack_inputs(&ibuf);
        assert_eq!(d.statusword, 0x1637);
        assert_eq!(d.position, -123456);
        assert_eq!(d.torque, -50);
        assert_eq!(d.error_code, 0x8611);
        assert_eq!(l.unpack_inputs(&[]), DriveInputs::default());
    }

    #[test]
    fn fixed_mappings_with_foreign_entries_and_bit_padding() {
        // a drive's fixed mapping: statusword, 4 bits padding, 4 bits of a
        // vendor object, position, following error actual
        let pad = PdoEntry::from_mapping_value(0x0000_0004);
        let vendor = PdoEntry::from_mapping_value(0x2010_0104);
        let tx = [
            STATUSWORD,
            pad,
            vendor,
            POSITION_ACTUAL,
            PdoEntry::from_mapping_value(0x60F4_0020),
        ];
        let rx = [
            CONTROLWORD,
            TARGET_POSITION,
            PdoEntry::from_mapping_value(0x60FF_0020),
        ];
        let l = PdoLayout::from_entries(&rx, &tx, &[0x1701], &[0x1B01]).unwrap();
        assert_eq!((l.rx_bytes(), l.tx_bytes()), (10, 11));
        assert_eq!(
            l.present,
            Present::default(),
            "no velocity, torque, inputs, probes, error code"
        );
        let mut ibuf = [0u8; 11];
        ibuf[0] = 0x37;
        ibuf[1] = 0x02;
        ibuf[2] = 0xA5; // padding low nibble, vendor high nibble
        ibuf[3..7].copy_from_slice(&77i32.to_le_bytes());
        let d = l.unpack_inputs(&ibuf);
        assert_eq!((d.statusword, d.position), (0x0237, 77));
        let mut obuf = [0xFFu8; 10];
        l.pack_outputs(
            &DriveOutputs {
                controlword: 0x000F,
                target_position: 5,
                ..DriveOutputs::default()
            },
            &mut obuf,
        );
        assert_eq!(
            obuf,
            [0x0F, 0, 5, 0, 0, 0, 0, 0, 0, 0],
            "unknown entries are 0"
        );
        // bit-level round trip
        let mut b = [0u8; 3];
        put_bits(&mut b, 3, 12, 0xABC);
        assert_eq!(get_bits(&b, 3, 12), 0xABC);
        assert_eq!(get_bits(&b, 0, 3), 0);
        assert!(PdoLayout::from_entries(&[CONTROLWORD; 33], &[], &[], &[]).is_err());
    }
}
