//! The CiA 402 / 301 objects this backend knows, each once: index,
//! sub-index, bit length and name ([`PdoEntry`]), and what the backend uses
//! it for ([`purpose`]) — every message names an object as `0xNNNN` with
//! its name and purpose.

/// One object entry (CiA 301: index, sub-index, bit length), as mapped into
/// a PDO or read over SDO.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PdoEntry {
    pub index: u16,
    pub sub: u8,
    pub bits: u8,
    /// Name for messages ("touch probe function"); empty if unknown.
    pub name: &'static str,
}

impl PdoEntry {
    /// The 32-bit value written to a mapping object's sub-index:
    /// index << 16 | sub-index << 8 | bit length.
    pub const fn mapping_value(&self) -> u32 {
        ((self.index as u32) << 16) | ((self.sub as u32) << 8) | self.bits as u32
    }

    /// Inverse of [`mapping_value`](Self::mapping_value), with the name
    /// when the object is one of ours.
    pub fn from_mapping_value(v: u32) -> PdoEntry {
        let index = (v >> 16) as u16;
        PdoEntry {
            index,
            sub: (v >> 8) as u8,
            bits: v as u8,
            name: known_name(index),
        }
    }

    /// Whole bytes (a bit-sized entry rounds down: its bits are counted in
    /// the layout, see `pdo`).
    pub const fn bytes(&self) -> usize {
        self.bits as usize / 8
    }

    /// `0x6041 statusword` (`0x6099:01 …` for a sub-index other than 0).
    pub fn label(&self) -> String {
        let name = if self.name.is_empty() {
            object_name(self.index)
        } else {
            self.name
        };
        if self.sub == 0 {
            format!("{:#06X} {name}", self.index)
        } else {
            format!("{:#06X}:{:02X} {name}", self.index, self.sub)
        }
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

const fn sub(index: u16, sub: u8, bits: u8, name: &'static str) -> PdoEntry {
    PdoEntry {
        index,
        sub,
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
pub const QUICK_STOP_OPTION_CODE: PdoEntry = entry(0x605A, 16, "quick stop option code");
pub const HOME_OFFSET: PdoEntry = entry(0x607C, 32, "home offset");
pub const HOMING_METHOD: PdoEntry = entry(0x6098, 8, "homing method");
pub const HOMING_SPEED_SWITCH: PdoEntry = sub(0x6099, 1, 32, "homing speed (switch search)");
pub const HOMING_SPEED_ZERO: PdoEntry = sub(0x6099, 2, 32, "homing speed (zero search)");
pub const HOMING_ACCELERATION: PdoEntry = entry(0x609A, 32, "homing acceleration");
/// A record: sub 0 = count, subs 1.. = the methods (signed bytes).
pub const SUPPORTED_HOMING_METHODS: PdoEntry = entry(0x60E3, 8, "supported homing methods");
pub const SUPPORTED_DRIVE_MODES: PdoEntry = entry(0x6502, 32, "supported drive modes");

/// RxPDO mapping objects (0x1600 is the first).
pub const RXPDO_INDEX: u16 = 0x1600;
/// TxPDO mapping objects (0x1A00 is the first).
pub const TXPDO_INDEX: u16 = 0x1A00;
/// SM2 (outputs) PDO assignment.
pub const RXPDO_ASSIGN: u16 = 0x1C12;
/// SM3 (inputs) PDO assignment.
pub const TXPDO_ASSIGN: u16 = 0x1C13;
/// Cyclic synchronous position mode (0x6060).
pub const MODE_CSP: i8 = 8;
/// Homing mode (0x6060).
pub const MODE_HOMING: i8 = 6;

/// Every object the backend may use (probed in a drive's dictionary at
/// start-up and by the scan).
pub const USED: [PdoEntry; 28] = [
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
    QUICK_STOP_OPTION_CODE,
    HOME_OFFSET,
    HOMING_METHOD,
    HOMING_SPEED_SWITCH,
    HOMING_SPEED_ZERO,
    HOMING_ACCELERATION,
    SUPPORTED_HOMING_METHODS,
    SUPPORTED_DRIVE_MODES,
];

/// Objects of fixed mappings the backend does not use, for names.
const FOREIGN: [PdoEntry; 3] = [
    entry(0x6062, 32, "position demand value"),
    entry(0x60F4, 32, "following error actual value"),
    entry(0x60FF, 32, "target velocity"),
];

fn known_name(index: u16) -> &'static str {
    USED.iter()
        .chain(&FOREIGN)
        .find(|e| e.index == index)
        .map_or("", |e| e.name)
}

/// Name of an object, for messages ("object" if unknown).
pub fn object_name(index: u16) -> &'static str {
    match index {
        0x1600..=0x17FF => "RxPDO mapping",
        0x1A00..=0x1BFF => "TxPDO mapping",
        0x1C12 => "RxPDO assignment",
        0x1C13 => "TxPDO assignment",
        0x1C32 => "output sync manager parameters",
        0x1C33 => "input sync manager parameters",
        0x1008 => "manufacturer device name",
        0x0000 => "padding",
        _ => match known_name(index) {
            "" => "object",
            n => n,
        },
    }
}

/// What the backend uses an object for (messages of the start-up check).
pub fn purpose(index: u16) -> &'static str {
    match index {
        0x6040 => "drives the CiA 402 state machine",
        0x6041 => "reports the drive state",
        0x6060 => "selects cyclic synchronous position (and homing) mode",
        0x6061 => "confirms the mode in force",
        0x607A => "carries the position set-point",
        0x6064 => "reports the position",
        0x606C => "reports the velocity",
        0x6077 => "reports the torque (hard-stop detection)",
        0x60FD => "reports the home switch, limit switch and index inputs",
        0x603F => "names the drive's fault",
        0x60B8 => "arms the touch probes",
        0x60B9 => "reports the touch probe latches",
        0x60BA | 0x60BB => "holds the latched marker position (touch probe 1)",
        0x60BC | 0x60BD => "holds the latched switch position (touch probe 2)",
        0x60E0 | 0x60E1 | 0x6072 => "limits the torque",
        0x6065 => "applies the position error tolerance",
        0x6098 => "selects the drive's homing method",
        0x6099 => "sets the drive's homing speeds",
        0x609A => "sets the drive's homing acceleration",
        0x607C => "sets the drive's home offset (written 0)",
        0x60E3 => "lists the homing methods the drive supports",
        0x1C12 | 0x1C13 => "assigns the PDOs",
        _ => "",
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
    fn mapping_values_and_names() {
        assert_eq!(CONTROLWORD.mapping_value(), 0x6040_0010);
        assert_eq!(TARGET_POSITION.mapping_value(), 0x607A_0020);
        assert_eq!(MODES_OF_OPERATION.mapping_value(), 0x6060_0008);
        let e = PdoEntry::from_mapping_value(0x60B9_0010);
        assert_eq!((e.index, e.sub, e.bits), (0x60B9, 0, 16));
        assert_eq!(e.name, "touch probe status");
        assert_eq!(object_name(0x60B8), "touch probe function");
        assert_eq!(object_name(0x1C12), "RxPDO assignment");
        assert_eq!(object_name(0x1601), "RxPDO mapping");
        assert_eq!(object_name(0x1234), "object");
        assert_eq!(
            HOMING_SPEED_ZERO.label(),
            "0x6099:02 homing speed (zero search)"
        );
        assert_eq!(STATUSWORD.label(), "0x6041 statusword");
    }
}
