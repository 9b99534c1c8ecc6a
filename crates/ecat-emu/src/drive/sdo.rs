//! The rules of an SDO download to an emulated drive: mapping and
//! assignment objects only in PRE-OP, sub-index 0 = 0 before entries
//! change, only mappable objects of the right direction, cyclic synchronous
//! position only, the sync types the drive supports.

use super::dictionary::{MAP_SUBS, MAX_PDO_BYTES};
use super::Drive;
use crate::od::{abort, Mappable};

impl Drive {
    /// An SDO download, with the rules of the mapping, assignment, mode and
    /// sync objects. `preop`: the ESC is in PRE-OP (mapping changes allowed).
    pub fn sdo_download(
        &mut self,
        index: u16,
        sub: u8,
        data: &[u8],
        preop: bool,
    ) -> Result<(), u32> {
        self.od.check_download(index, sub, data)?;
        let mut v = [0u8; 8];
        let n = data.len().min(8);
        v[..n].copy_from_slice(&data[..n]);
        let value = u64::from_le_bytes(v);
        match index {
            0x1600..=0x17FF | 0x1A00..=0x1BFF if !preop => return Err(abort::STATE),
            0x1C12 | 0x1C13 if !preop => return Err(abort::STATE),
            0x1600..=0x17FF | 0x1A00..=0x1BFF => self.check_mapping_write(index, sub, value)?,
            0x1C12 | 0x1C13 => self.check_assign_write(index, sub, value)?,
            // cyclic synchronous position, homing where it has methods
            // (0 = no mode)
            0x6060 => {
                let m = value as u8 as i8;
                let homing = m == 6 && !self.cfg.homing_methods.is_empty();
                if m != 8 && m != 0 && !homing {
                    return Err(abort::VALUE_RANGE);
                }
            }
            0x6098 if !self.cfg.homing_methods.contains(&(value as u8 as i8)) => {
                return Err(abort::VALUE_RANGE)
            }
            0x1C32 | 0x1C33 if sub == 1 => {
                let ok = match value {
                    0 | 1 => true,
                    2 => self.cfg.dc,
                    _ => false,
                };
                if !ok {
                    return Err(abort::VALUE_RANGE);
                }
            }
            _ => {}
        }
        self.od.set_bytes(index, sub, data);
        if index == 0x6060 {
            self.show_mode();
        }
        Ok(())
    }

    /// A mapping object (0x1600.. RxPDO, 0x1A00.. TxPDO): entries change
    /// only while sub-index 0 is 0; the count is checked against the
    /// entries (mappable, at most [`MAP_SUBS`], at most [`MAX_PDO_BYTES`]).
    fn check_mapping_write(&self, index: u16, sub: u8, value: u64) -> Result<(), u32> {
        let want = if index < 0x1A00 {
            Mappable::Rx
        } else {
            Mappable::Tx
        };
        if sub != 0 {
            if self.od.get(index, 0) != 0 {
                return Err(abort::SUBINDEX0_MUST_BE_ZERO);
            }
            return self.check_mappable(value as u32, want);
        }
        let count = value as usize;
        if count > MAP_SUBS {
            return Err(abort::VALUE_RANGE);
        }
        let mut bytes = 0;
        for j in 1..=count as u8 {
            let m = self.od.get(index, j) as u32;
            self.check_mappable(m, want)?;
            bytes += (m & 0xFF) as usize / 8;
        }
        if bytes > MAX_PDO_BYTES {
            return Err(abort::PDO_TOO_LONG);
        }
        Ok(())
    }

    /// An assignment object (0x1C12 RxPDOs, 0x1C13 TxPDOs): entries change
    /// only while sub-index 0 is 0, and name existing PDOs of its kind.
    fn check_assign_write(&self, index: u16, sub: u8, value: u64) -> Result<(), u32> {
        let range = if index == 0x1C12 {
            0x1600..=0x17FF
        } else {
            0x1A00..=0x1BFF
        };
        let pdo_ok = |pdo: u16| range.contains(&pdo) && self.od.has_object(pdo);
        if sub != 0 {
            if self.od.get(index, 0) != 0 {
                return Err(abort::SUBINDEX0_MUST_BE_ZERO);
            }
            return if pdo_ok(value as u16) {
                Ok(())
            } else {
                Err(abort::VALUE_RANGE)
            };
        }
        for j in 1..=value as u8 {
            if !pdo_ok(self.od.get(index, j) as u16) {
                return Err(abort::VALUE_RANGE);
            }
        }
        Ok(())
    }

    fn check_mappable(&self, m: u32, want: Mappable) -> Result<(), u32> {
        if m == 0 {
            return Err(abort::CANNOT_MAP);
        }
        let (index, sub, bits) = ((m >> 16) as u16, (m >> 8) as u8, (m & 0xFF) as u16);
        match self.od.entry(index, sub) {
            Ok(e) if e.map == want && e.bits == bits => Ok(()),
            Ok(_) => Err(abort::CANNOT_MAP),
            // the object is not there at all: say so
            Err(code) => Err(code),
        }
    }
}
