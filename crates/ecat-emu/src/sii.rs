//! The SII EEPROM image of an emulated SubDevice (ETG.1000.6 / ETG.2010):
//! fixed header (PDI, alias, checksum, identity, mailbox), then the
//! categories strings, general, FMMU, sync managers, TxPDO, RxPDO, end.

/// Mailbox and process-data layout of the emulated ESC.
pub mod layout {
    pub const MBX_OUT_START: u16 = 0x1000;
    pub const MBX_IN_START: u16 = 0x1080;
    pub const MBX_SIZE: u16 = 128;
    pub const PD_OUT_START: u16 = 0x1100;
    pub const PD_IN_START: u16 = 0x1200;
    /// SM control bytes: mailbox write, mailbox read, buffered write with
    /// the SM watchdog enabled, buffered read.
    pub const SM0_CONTROL: u8 = 0x26;
    pub const SM1_CONTROL: u8 = 0x22;
    pub const SM2_CONTROL: u8 = 0x64;
    pub const SM3_CONTROL: u8 = 0x20;
}

/// What goes into the image.
#[derive(Clone, Debug)]
pub struct SiiInfo {
    pub name: String,
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision: u32,
    pub serial: u32,
    pub alias: u16,
    /// Default PDO sizes for the SM2 / SM3 entries (bytes).
    pub default_rx_bytes: u16,
    pub default_tx_bytes: u16,
}

fn crc8(bytes: &[u8]) -> u8 {
    let mut crc = 0xFFu8;
    for &b in bytes {
        crc ^= b;
        for _ in 0..8 {
            crc = if crc & 0x80 != 0 {
                (crc << 1) ^ 0x07
            } else {
                crc << 1
            };
        }
    }
    crc
}

fn category(out: &mut Vec<u8>, kind: u16, mut data: Vec<u8>) {
    if data.len() % 2 == 1 {
        data.push(0);
    }
    out.extend_from_slice(&kind.to_le_bytes());
    out.extend_from_slice(&((data.len() / 2) as u16).to_le_bytes());
    out.extend_from_slice(&data);
}

/// Builds the image (bytes, word-addressed by the ESC).
pub fn image(info: &SiiInfo) -> Vec<u8> {
    use layout::*;
    let mut e = vec![0u8; 0x80];
    let w = |e: &mut Vec<u8>, word: usize, v: u16| {
        e[word * 2..word * 2 + 2].copy_from_slice(&v.to_le_bytes())
    };
    let d = |e: &mut Vec<u8>, word: usize, v: u32| {
        e[word * 2..word * 2 + 4].copy_from_slice(&v.to_le_bytes())
    };
    w(&mut e, 0x0000, 0x0C08); // PDI control: 32-bit µC, EEPROM emulation off
    w(&mut e, 0x0004, info.alias);
    let crc = crc8(&e[..14]);
    w(&mut e, 0x0007, u16::from(crc));
    d(&mut e, 0x0008, info.vendor_id);
    d(&mut e, 0x000A, info.product_code);
    d(&mut e, 0x000C, info.revision);
    d(&mut e, 0x000E, info.serial);
    w(&mut e, 0x0018, MBX_OUT_START);
    w(&mut e, 0x0019, MBX_SIZE);
    w(&mut e, 0x001A, MBX_IN_START);
    w(&mut e, 0x001B, MBX_SIZE);
    w(&mut e, 0x001C, 0x0004); // CoE
    w(&mut e, 0x003E, 0x000F); // 2 KiB
    w(&mut e, 0x003F, 0x0001);

    // strings: 1 = name (order / device name), 2 = group, 3 = PDO names
    let strings = [info.name.as_str(), "Drives", "Outputs", "Inputs"];
    let mut s = vec![strings.len() as u8];
    for t in strings {
        s.push(t.len() as u8);
        s.extend_from_slice(t.as_bytes());
    }
    category(&mut e, 10, s);

    // general (32 bytes)
    let mut g = vec![0u8; 32];
    g[0] = 2; // group
    g[1] = 0; // image
    g[2] = 1; // order → name
    g[3] = 1; // name
    g[5] = 0x0D; // CoE: SDO, PDO assign, PDO config (no SDO info, no complete access)
    g[12] = 0; // flags
    g[13..15].copy_from_slice(&0i16.to_le_bytes()); // current
    g[16..18].copy_from_slice(&0x0011u16.to_le_bytes()); // ports 0,1: MII
    category(&mut e, 30, g);

    // FMMU usage: outputs, inputs, SM status
    category(&mut e, 40, vec![0x01, 0x02, 0x03, 0xFF]);

    // sync managers
    let mut sm = Vec::new();
    for (start, len, control, kind) in [
        (MBX_OUT_START, MBX_SIZE, SM0_CONTROL, 1u8),
        (MBX_IN_START, MBX_SIZE, SM1_CONTROL, 2),
        (PD_OUT_START, info.default_rx_bytes, SM2_CONTROL, 3),
        (PD_IN_START, info.default_tx_bytes, SM3_CONTROL, 4),
    ] {
        sm.extend_from_slice(&start.to_le_bytes());
        sm.extend_from_slice(&len.to_le_bytes());
        sm.extend_from_slice(&[control, 0, 0x01, kind]);
    }
    category(&mut e, 41, sm);

    // default PDOs (informational: the CoE objects rule)
    let pdo = |index: u16, sm: u8, name: u8, entries: &[(u16, u8)]| {
        let mut v = Vec::new();
        v.extend_from_slice(&index.to_le_bytes());
        v.extend_from_slice(&[entries.len() as u8, sm, 0, name]);
        v.extend_from_slice(&0u16.to_le_bytes());
        for &(idx, bits) in entries {
            v.extend_from_slice(&idx.to_le_bytes());
            v.extend_from_slice(&[0, 0, if bits == 16 { 6 } else { 4 }, bits]);
            v.extend_from_slice(&0u16.to_le_bytes());
        }
        v
    };
    category(&mut e, 50, pdo(0x1A00, 3, 4, &[(0x6041, 16), (0x6064, 32)]));
    category(&mut e, 51, pdo(0x1600, 2, 3, &[(0x6040, 16), (0x607A, 32)]));
    e.extend_from_slice(&0xFFFFu16.to_le_bytes());
    e.extend_from_slice(&0u16.to_le_bytes());
    // pad to the declared size with 0xFF
    e.resize(2048, 0xFF);
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info() -> SiiInfo {
        SiiInfo {
            name: "EMU-402".into(),
            vendor_id: 0xEC7,
            product_code: 0x0402_0001,
            revision: 3,
            serial: 42,
            alias: 0,
            default_rx_bytes: 6,
            default_tx_bytes: 6,
        }
    }

    #[test]
    fn header_and_categories() {
        let e = image(&info());
        assert_eq!(u32::from_le_bytes(e[16..20].try_into().unwrap()), 0xEC7);
        assert_eq!(u32::from_le_bytes(e[28..32].try_into().unwrap()), 42);
        assert_eq!(crc8(&e[..14]), e[14]);
        // the SII checksum: CRC-8, polynomial 0x07, init 0xFF, not reflected
        // (ethercrab's STATION_ALIAS_CRC parameters)
        assert_eq!(crc8(b"123456789"), 0xFB);
        // walk the categories
        let mut at = 0x80;
        let mut kinds = Vec::new();
        loop {
            let kind = u16::from_le_bytes([e[at], e[at + 1]]);
            let len = u16::from_le_bytes([e[at + 2], e[at + 3]]) as usize;
            kinds.push(kind);
            if kind == 0xFFFF {
                break;
            }
            at += 4 + len * 2;
        }
        assert_eq!(kinds, [10, 30, 40, 41, 50, 51, 0xFFFF]);
        // string 1 is the name
        assert_eq!(e[0x84], 4);
        assert_eq!(&e[0x86..0x86 + 7], b"EMU-402");
    }
}
