//! A small CoE object dictionary: entries by (index, sub-index) with their
//! size, access and PDO mappability, values stored little endian.

use std::collections::BTreeMap;

/// SDO abort codes (ETG.1000.6 Table 41 / CiA 301).
pub mod abort {
    pub const TOGGLE_BIT: u32 = 0x0503_0000;
    pub const INVALID_COMMAND: u32 = 0x0504_0001;
    pub const UNSUPPORTED_ACCESS: u32 = 0x0601_0000;
    pub const WRITE_ONLY: u32 = 0x0601_0001;
    pub const READ_ONLY: u32 = 0x0601_0002;
    pub const SUBINDEX0_MUST_BE_ZERO: u32 = 0x0601_0003;
    pub const NO_COMPLETE_ACCESS: u32 = 0x0601_0004;
    pub const OBJECT_NOT_FOUND: u32 = 0x0602_0000;
    pub const CANNOT_MAP: u32 = 0x0604_0041;
    pub const PDO_TOO_LONG: u32 = 0x0604_0042;
    pub const LENGTH_MISMATCH: u32 = 0x0607_0010;
    pub const SUBINDEX_NOT_FOUND: u32 = 0x0609_0011;
    pub const VALUE_RANGE: u32 = 0x0609_0030;
    pub const GENERAL: u32 = 0x0800_0000;
    pub const STATE: u32 = 0x0800_0022;
}

/// SDO access of an entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Ro,
    Rw,
    Wo,
}

/// Where an entry may be mapped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mappable {
    No,
    /// RxPDO (master → drive).
    Rx,
    /// TxPDO (drive → master).
    Tx,
}

/// One (index, sub-index) entry.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    pub bits: u16,
    pub access: Access,
    pub map: Mappable,
    /// Visible string: variable length up to `bits / 8`.
    pub string: bool,
    pub data: Vec<u8>,
}

impl Entry {
    /// A numeric entry holding `value` (little endian, `bits / 8` bytes).
    fn number(bits: u16, access: Access, map: Mappable, value: u64) -> Entry {
        Entry {
            bits,
            access,
            map,
            string: false,
            data: value.to_le_bytes()[..usize::from(bits / 8)].to_vec(),
        }
    }
}

/// The dictionary.
#[derive(Clone, Debug, Default)]
pub struct Od {
    entries: BTreeMap<(u16, u8), Entry>,
    names: BTreeMap<u16, &'static str>,
}

impl Od {
    pub fn new() -> Od {
        Od::default()
    }

    /// A single-value object (sub-index 0).
    pub fn var(
        &mut self,
        index: u16,
        name: &'static str,
        bits: u16,
        access: Access,
        map: Mappable,
        value: u64,
    ) {
        self.names.insert(index, name);
        self.entries
            .insert((index, 0), Entry::number(bits, access, map, value));
    }

    /// A visible-string object (sub-index 0), read only.
    pub fn string(&mut self, index: u16, name: &'static str, value: &str) {
        self.string_with(index, name, value, Access::Ro);
    }

    /// A visible-string object with the given access; its size is the
    /// initial value's length (writes may be shorter).
    pub fn string_with(&mut self, index: u16, name: &'static str, value: &str, access: Access) {
        self.names.insert(index, name);
        self.entries.insert(
            (index, 0),
            Entry {
                bits: (value.len() * 8) as u16,
                access,
                map: Mappable::No,
                string: true,
                data: value.as_bytes().to_vec(),
            },
        );
    }

    /// A record / array: sub-index 0 holds the number of entries (u8, `sub0`
    /// access), then `subs` = (bits, access, map, value) for 1..=n.
    pub fn record(
        &mut self,
        index: u16,
        name: &'static str,
        sub0: Access,
        subs: &[(u16, Access, Mappable, u64)],
    ) {
        self.names.insert(index, name);
        let count = Entry::number(8, sub0, Mappable::No, subs.len() as u64);
        self.entries.insert((index, 0), count);
        for (i, &(bits, access, map, value)) in subs.iter().enumerate() {
            self.entries.insert(
                (index, i as u8 + 1),
                Entry::number(bits, access, map, value),
            );
        }
    }

    /// Drops a whole object (drive variants without it).
    pub fn remove(&mut self, index: u16) {
        self.names.remove(&index);
        self.entries.retain(|&(i, _), _| i != index);
    }

    pub fn has_object(&self, index: u16) -> bool {
        self.names.contains_key(&index)
    }

    pub fn name(&self, index: u16) -> Option<&'static str> {
        self.names.get(&index).copied()
    }

    pub fn entry(&self, index: u16, sub: u8) -> Result<&Entry, u32> {
        match self.entries.get(&(index, sub)) {
            Some(e) => Ok(e),
            None if self.has_object(index) => Err(abort::SUBINDEX_NOT_FOUND),
            None => Err(abort::OBJECT_NOT_FOUND),
        }
    }

    /// Raw bytes for an SDO upload (access checked).
    pub fn upload(&self, index: u16, sub: u8) -> Result<Vec<u8>, u32> {
        let e = self.entry(index, sub)?;
        if e.access == Access::Wo {
            return Err(abort::WRITE_ONLY);
        }
        Ok(e.data.clone())
    }

    /// Checks an SDO download against access and size (the value is not
    /// stored; see [`set_bytes`](Self::set_bytes)).
    pub fn check_download(&self, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        let e = self.entry(index, sub)?;
        if e.access == Access::Ro {
            return Err(abort::READ_ONLY);
        }
        let size = usize::from(e.bits / 8);
        if e.string {
            if data.len() > size {
                return Err(abort::LENGTH_MISMATCH);
            }
        } else if data.len() != size {
            return Err(abort::LENGTH_MISMATCH);
        }
        Ok(())
    }

    /// Stores bytes without any check (the device's own updates).
    pub fn set_bytes(&mut self, index: u16, sub: u8, data: &[u8]) {
        if let Some(e) = self.entries.get_mut(&(index, sub)) {
            if e.string {
                e.data = data.to_vec();
            } else {
                let n = e.data.len().min(data.len());
                e.data[..n].copy_from_slice(&data[..n]);
            }
        }
    }

    /// Unsigned value (0 if absent).
    pub fn get(&self, index: u16, sub: u8) -> u64 {
        let mut b = [0u8; 8];
        if let Some(e) = self.entries.get(&(index, sub)) {
            let n = e.data.len().min(8);
            b[..n].copy_from_slice(&e.data[..n]);
        }
        u64::from_le_bytes(b)
    }

    /// Sign-extended value (0 if absent).
    pub fn get_signed(&self, index: u16, sub: u8) -> i64 {
        let Some(e) = self.entries.get(&(index, sub)) else {
            return 0;
        };
        let bits = (e.data.len().min(8) * 8) as u32;
        let v = self.get(index, sub);
        if bits == 0 || bits >= 64 {
            v as i64
        } else {
            let shift = 64 - bits;
            ((v << shift) as i64) >> shift
        }
    }

    /// Stores a value (truncated to the entry's size; no-op if absent).
    pub fn put(&mut self, index: u16, sub: u8, value: u64) {
        if let Some(e) = self.entries.get_mut(&(index, sub)) {
            let n = e.data.len().min(8);
            e.data[..n].copy_from_slice(&value.to_le_bytes()[..n]);
        }
    }

    /// Entry size in bits (0 if absent).
    pub fn bits(&self, index: u16, sub: u8) -> u16 {
        self.entries.get(&(index, sub)).map_or(0, |e| e.bits)
    }

    /// Object indices, ascending.
    pub fn indices(&self) -> impl Iterator<Item = u16> + '_ {
        self.names.keys().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_access_and_aborts() {
        let mut od = Od::new();
        od.var(
            0x6064,
            "pos",
            32,
            Access::Ro,
            Mappable::Tx,
            (-5i32) as u32 as u64,
        );
        od.var(0x6040, "cw", 16, Access::Rw, Mappable::Rx, 0);
        od.record(
            0x1018,
            "identity",
            Access::Ro,
            &[(32, Access::Ro, Mappable::No, 0x1234)],
        );
        od.string(0x1008, "name", "EMU");
        assert_eq!(od.get_signed(0x6064, 0), -5);
        assert_eq!(od.upload(0x1018, 0).unwrap(), [1]);
        assert_eq!(od.upload(0x1018, 1).unwrap(), [0x34, 0x12, 0, 0]);
        assert_eq!(od.upload(0x1018, 2), Err(abort::SUBINDEX_NOT_FOUND));
        assert_eq!(od.upload(0x60B8, 0), Err(abort::OBJECT_NOT_FOUND));
        assert_eq!(od.check_download(0x6064, 0, &[0; 4]), Err(abort::READ_ONLY));
        assert_eq!(
            od.check_download(0x6040, 0, &[0; 4]),
            Err(abort::LENGTH_MISMATCH)
        );
        assert_eq!(od.check_download(0x6040, 0, &[1, 0]), Ok(()));
        od.put(0x6040, 0, 0x1_000F);
        assert_eq!(od.get(0x6040, 0), 0x000F);
        assert_eq!(od.upload(0x1008, 0).unwrap(), b"EMU");
        od.remove(0x1018);
        assert_eq!(od.upload(0x1018, 1), Err(abort::OBJECT_NOT_FOUND));
        assert_eq!(od.indices().collect::<Vec<_>>(), [0x1008, 0x6040, 0x6064]);
    }
}
