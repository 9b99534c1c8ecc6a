//! The process data layout: which CiA 402 objects travel in the RxPDO
//! (0x1600, master → drive) and the TxPDO (0x1A00, drive → master), their
//! mapping values for the CoE mapping objects, and packing / unpacking of one
//! drive's slice of the process image (little endian, in mapping order).
//!
//! The layout is fixed by the master and written to the drive over CoE at
//! PRE-OP (see [`crate::startup`]); ethercrab reads it back to size the
//! sync managers and FMMUs, so the bytes here and ethercrab's view agree by
//! construction.

/// One object in a PDO mapping (CiA 301: index, sub-index, bit length).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PdoEntry {
    pub index: u16,
    pub sub: u8,
    pub bits: u8,
    /// Name for messages ("touch probe function").
    pub name: &'static str,
}

impl PdoEntry {
    /// The 32-bit value written to a mapping object's sub-index:
    /// index << 16 | sub-index << 8 | bit length.
    pub const fn mapping_value(&self) -> u32 {
        ((self.index as u32) << 16) | ((self.sub as u32) << 8) | self.bits as u32
    }

    /// Inverse of [`mapping_value`](Self::mapping_value) (name unknown).
    pub const fn from_mapping_value(v: u32) -> PdoEntry {
        PdoEntry {
            index: (v >> 16) as u16,
            sub: (v >> 8) as u8,
            bits: v as u8,
            name: "",
        }
    }

    pub const fn bytes(&self) -> usize {
        self.bits as usize / 8
    }
}

const fn entry(index: u16, bits: u8, name: &'static str) -> PdoEntry {
    PdoEntry {
        index,
        sub: 0,
        bits,
        name,
    }
}

pub const CONTROLWORD: PdoEntry = entry(0x6040, 16, "controlword");
pub const STATUSWORD: PdoEntry = entry(0x6041, 16, "statusword");
pub const MODES_OF_OPERATION: PdoEntry = entry(0x6060, 8, "modes of operation");
pub const MODES_OF_OPERATION_DISPLAY: PdoEntry = entry(0x6061, 8, "modes of operation display");
pub const TARGET_POSITION: PdoEntry = entry(0x607A, 32, "target position");
pub const POSITION_ACTUAL: PdoEntry = entry(0x6064, 32, "position actual value");
pub const VELOCITY_ACTUAL: PdoEntry = entry(0x606C, 32, "velocity actual value");
pub const TORQUE_ACTUAL: PdoEntry = entry(0x6077, 16, "torque actual value");
pub const DIGITAL_INPUTS: PdoEntry = entry(0x60FD, 32, "digital inputs");
pub const ERROR_CODE: PdoEntry = entry(0x603F, 16, "error code");
pub const TOUCH_PROBE_FUNCTION: PdoEntry = entry(0x60B8, 16, "touch probe function");
pub const TOUCH_PROBE_STATUS: PdoEntry = entry(0x60B9, 16, "touch probe status");
pub const TOUCH_PROBE_1_POSITIVE: PdoEntry = entry(0x60BA, 32, "touch probe 1 positive edge");
pub const TOUCH_PROBE_1_NEGATIVE: PdoEntry = entry(0x60BB, 32, "touch probe 1 negative edge");
pub const TOUCH_PROBE_2_POSITIVE: PdoEntry = entry(0x60BC, 32, "touch probe 2 positive edge");
pub const TOUCH_PROBE_2_NEGATIVE: PdoEntry = entry(0x60BD, 32, "touch probe 2 negative edge");
pub const POSITIVE_TORQUE_LIMIT: PdoEntry = entry(0x60E0, 16, "positive torque limit value");
pub const NEGATIVE_TORQUE_LIMIT: PdoEntry = entry(0x60E1, 16, "negative torque limit value");
pub const MAX_TORQUE: PdoEntry = entry(0x6072, 16, "max torque");
/// Not mapped: written over SDO when the commanded position error
/// tolerance changes (optional object).
pub const FOLLOWING_ERROR_WINDOW: PdoEntry = entry(0x6065, 32, "following error window");

/// RxPDO mapping object used.
pub const RXPDO_INDEX: u16 = 0x1600;
/// TxPDO mapping object used.
pub const TXPDO_INDEX: u16 = 0x1A00;
/// SM2 (outputs) PDO assignment.
pub const RXPDO_ASSIGN: u16 = 0x1C12;
/// SM3 (inputs) PDO assignment.
pub const TXPDO_ASSIGN: u16 = 0x1C13;
/// Cyclic synchronous position mode (0x6060).
pub const MODE_CSP: i8 = 8;

/// Which objects carry the torque limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TorqueLimits {
    /// 0x60E0 / 0x60E1: one limit per direction.
    PerDirection,
    /// 0x6072 only: the larger of the two limits for both directions.
    MaxTorque,
}

const MAX_ENTRIES: usize = 12;

/// The layout of one drive's process data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PdoLayout {
    rx: [PdoEntry; MAX_ENTRIES],
    rx_len: usize,
    tx: [PdoEntry; MAX_ENTRIES],
    tx_len: usize,
    pub torque: TorqueLimits,
    pub mode_in_pdo: bool,
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

/// What the drive reports each cycle (TxPDO values).
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
}

impl PdoLayout {
    /// The layout this backend uses.
    pub fn new(torque: TorqueLimits, mode_in_pdo: bool) -> PdoLayout {
        let mut rx = [CONTROLWORD; MAX_ENTRIES];
        let mut n = 0;
        let mut push = |e: PdoEntry| {
            rx[n] = e;
            n += 1;
        };
        push(CONTROLWORD);
        push(TARGET_POSITION);
        push(TOUCH_PROBE_FUNCTION);
        match torque {
            TorqueLimits::PerDirection => {
                push(POSITIVE_TORQUE_LIMIT);
                push(NEGATIVE_TORQUE_LIMIT);
            }
            TorqueLimits::MaxTorque => push(MAX_TORQUE),
        }
        if mode_in_pdo {
            push(MODES_OF_OPERATION);
        }
        let rx_len = n;
        let tx_list = [
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
        let mut tx = [CONTROLWORD; MAX_ENTRIES];
        tx[..tx_list.len()].copy_from_slice(&tx_list);
        PdoLayout {
            rx,
            rx_len,
            tx,
            tx_len: tx_list.len(),
            torque,
            mode_in_pdo,
        }
    }

    /// RxPDO entries (0x1600), in order.
    pub fn rx_entries(&self) -> &[PdoEntry] {
        &self.rx[..self.rx_len]
    }

    /// TxPDO entries (0x1A00), in order.
    pub fn tx_entries(&self) -> &[PdoEntry] {
        &self.tx[..self.tx_len]
    }

    /// Output (RxPDO) bytes.
    pub fn rx_bytes(&self) -> usize {
        self.rx_entries().iter().map(PdoEntry::bytes).sum()
    }

    /// Input (TxPDO) bytes.
    pub fn tx_bytes(&self) -> usize {
        self.tx_entries().iter().map(PdoEntry::bytes).sum()
    }

    /// Every object the drive must have: the mapped ones and the mode
    /// objects, for the start-up check (in the order they are checked).
    pub fn required_objects(&self) -> impl Iterator<Item = PdoEntry> + '_ {
        let mode = (!self.mode_in_pdo).then_some(MODES_OF_OPERATION);
        self.rx_entries()
            .iter()
            .chain(self.tx_entries())
            .copied()
            .chain(mode)
            .chain([MODES_OF_OPERATION_DISPLAY])
    }

    /// Packs `out` into `buf` (the drive's output slice). A short buffer
    /// leaves the rest unwritten: never panics.
    pub fn pack_outputs(&self, out: &DriveOutputs, buf: &mut [u8]) {
        let mut at = 0;
        for e in self.rx_entries() {
            let v: u32 = match e.index {
                0x6040 => u32::from(out.controlword),
                0x607A => out.target_position as u32,
                0x60B8 => u32::from(out.touch_probe_function),
                0x60E0 => u32::from(out.torque_limit_positive),
                0x60E1 => u32::from(out.torque_limit_negative),
                0x6072 => u32::from(out.torque_limit_positive.max(out.torque_limit_negative)),
                0x6060 => out.mode as u8 as u32,
                _ => 0,
            };
            put(buf, at, e.bytes(), v);
            at += e.bytes();
        }
    }

    /// Unpacks the drive's input slice. Missing bytes read as 0.
    pub fn unpack_inputs(&self, buf: &[u8]) -> DriveInputs {
        let mut d = DriveInputs::default();
        let mut at = 0;
        for e in self.tx_entries() {
            let v = get(buf, at, e.bytes());
            at += e.bytes();
            match e.index {
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
                _ => {}
            }
        }
        d
    }
}

fn put(buf: &mut [u8], at: usize, len: usize, v: u32) {
    let bytes = v.to_le_bytes();
    if let Some(dst) = buf.get_mut(at..at + len) {
        dst.copy_from_slice(&bytes[..len]);
    }
}

fn get(buf: &[u8], at: usize, len: usize) -> u32 {
    let mut b = [0u8; 4];
    if let Some(src) = buf.get(at..at + len) {
        b[..len].copy_from_slice(src);
    }
    u32::from_le_bytes(b)
}

/// Name of a CiA 402 / 301 object this backend uses, for messages.
pub fn object_name(index: u16) -> &'static str {
    let all = [
        CONTROLWORD,
        STATUSWORD,
        MODES_OF_OPERATION,
        MODES_OF_OPERATION_DISPLAY,
        TARGET_POSITION,
        POSITION_ACTUAL,
        VELOCITY_ACTUAL,
        TORQUE_ACTUAL,
        DIGITAL_INPUTS,
        ERROR_CODE,
        TOUCH_PROBE_FUNCTION,
        TOUCH_PROBE_STATUS,
        TOUCH_PROBE_1_POSITIVE,
        TOUCH_PROBE_1_NEGATIVE,
        TOUCH_PROBE_2_POSITIVE,
        TOUCH_PROBE_2_NEGATIVE,
        POSITIVE_TORQUE_LIMIT,
        NEGATIVE_TORQUE_LIMIT,
        MAX_TORQUE,
        FOLLOWING_ERROR_WINDOW,
    ];
    match index {
        0x1600 => "RxPDO mapping",
        0x1A00 => "TxPDO mapping",
        0x1C12 => "RxPDO assignment",
        0x1C13 => "TxPDO assignment",
        0x1C32 => "output sync manager parameters",
        0x1C33 => "input sync manager parameters",
        _ => all
            .iter()
            .find(|e| e.index == index)
            .map_or("object", |e| e.name),
    }
}

/// Digital inputs 0x60FD bits (CiA 402).
pub mod di {
    pub const NEGATIVE_LIMIT_SWITCH: u32 = 1 << 0;
    pub const POSITIVE_LIMIT_SWITCH: u32 = 1 << 1;
    pub const HOME_SWITCH: u32 = 1 << 2;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_values() {
        assert_eq!(CONTROLWORD.mapping_value(), 0x6040_0010);
        assert_eq!(TARGET_POSITION.mapping_value(), 0x607A_0020);
        assert_eq!(MODES_OF_OPERATION.mapping_value(), 0x6060_0008);
        let e = PdoEntry::from_mapping_value(0x60B9_0010);
        assert_eq!((e.index, e.sub, e.bits), (0x60B9, 0, 16));
    }

    #[test]
    fn sizes_and_order() {
        let l = PdoLayout::new(TorqueLimits::PerDirection, false);
        let rx: Vec<u16> = l.rx_entries().iter().map(|e| e.index).collect();
        assert_eq!(rx, [0x6040, 0x607A, 0x60B8, 0x60E0, 0x60E1]);
        assert_eq!(l.rx_bytes(), 12);
        let tx: Vec<u16> = l.tx_entries().iter().map(|e| e.index).collect();
        assert_eq!(
            tx,
            [
                0x6041, 0x6064, 0x606C, 0x6077, 0x60FD, 0x60B9, 0x60BA, 0x60BB, 0x60BC, 0x60BD,
                0x603F
            ]
        );
        assert_eq!(l.tx_bytes(), 2 + 4 + 4 + 2 + 4 + 2 + 16 + 2);

        let m = PdoLayout::new(TorqueLimits::MaxTorque, true);
        let rx: Vec<u16> = m.rx_entries().iter().map(|e| e.index).collect();
        assert_eq!(rx, [0x6040, 0x607A, 0x60B8, 0x6072, 0x6060]);
        assert_eq!(m.rx_bytes(), 11);

        let req: Vec<u16> = l.required_objects().map(|e| e.index).collect();
        assert_eq!(req.iter().filter(|&&i| i == 0x6060).count(), 1);
        assert!(req.contains(&0x6061) && req.contains(&0x60B8));
        let req: Vec<u16> = m.required_objects().map(|e| e.index).collect();
        assert_eq!(req.iter().filter(|&&i| i == 0x6060).count(), 1);
    }

    #[test]
    fn pack_unpack() {
        let l = PdoLayout::new(TorqueLimits::PerDirection, false);
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

        let m = PdoLayout::new(TorqueLimits::MaxTorque, true);
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
    fn names() {
        assert_eq!(object_name(0x60B8), "touch probe function");
        assert_eq!(object_name(0x1C12), "RxPDO assignment");
        assert_eq!(object_name(0x1234), "object");
    }
}
