//! What a drive's object dictionary holds, read once over CoE at PRE-OP
//! before anything is written: which of the objects the backend may use
//! exist ([`Dictionary::has`]), the homing methods it lists (0x60E3), its
//! supported drive modes (0x6502) and quick stop option code (0x605A).
//! The start-up check ([`crate::wants`]) and the bus scan read this.

use std::ops::Deref;

use ethercrab::error::{Error, MailboxError};
use ethercrab::{SubDevice, SubDeviceRef};

use crate::objects::*;

/// Every object the backend may use, probed at start-up (and by the scan).
pub const PROBED: [PdoEntry; 28] = USED;

/// The SDO abort code of a mailbox error, if it is one.
pub fn abort_code(e: &Error) -> Option<u32> {
    match e {
        Error::Mailbox(MailboxError::Aborted { code, .. }) => Some(u32::from(*code)),
        _ => None,
    }
}

/// One (index, sub-index) entry read with the width its bit length says.
pub async fn read_entry<S>(sd: &SubDeviceRef<'_, S>, e: &PdoEntry) -> Result<u32, Error>
where
    S: Deref<Target = SubDevice>,
{
    Ok(match e.bits {
        8 => u32::from(sd.sdo_read::<u8>(e.index, e.sub).await?),
        16 => u32::from(sd.sdo_read::<u16>(e.index, e.sub).await?),
        _ => sd.sdo_read::<u32>(e.index, e.sub).await?,
    })
}

/// What the dictionary of one drive holds.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Dictionary {
    /// Objects of [`PROBED`] that answered an upload, with their value.
    pub present: Vec<(PdoEntry, u32)>,
    /// Objects of [`PROBED`] that did not, with the SDO abort code.
    pub absent: Vec<(PdoEntry, u32)>,
    /// 0x60E3, if the drive has it.
    pub homing_methods: Option<Vec<i8>>,
}

impl Dictionary {
    /// The object `index` (sub-index as probed) exists.
    pub fn has(&self, index: u16) -> bool {
        self.present.iter().any(|(e, _)| e.index == index)
    }

    /// The value read at start-up, if the object exists.
    pub fn value(&self, index: u16) -> Option<u32> {
        self.present
            .iter()
            .find(|(e, _)| e.index == index)
            .map(|&(_, v)| v)
    }

    /// The SDO abort code an absent object answered with.
    pub fn abort(&self, index: u16) -> Option<u32> {
        self.absent
            .iter()
            .find(|(e, _)| e.index == index)
            .map(|&(_, c)| c)
    }

    /// CiA 402 objects present (0x6000..0x6FFF), ascending, as `0xNNNN`.
    pub fn cia402_objects(&self) -> Vec<String> {
        let mut v: Vec<u16> = self
            .present
            .iter()
            .map(|(e, _)| e.index)
            .filter(|i| (0x6000..0x7000).contains(i))
            .collect();
        v.sort_unstable();
        v.dedup();
        v.iter().map(|i| format!("{i:#06X}")).collect()
    }

    /// The drive supports mode `mode` per 0x6502 (`None`: no 0x6502).
    pub fn supports_mode(&self, mode: i8) -> Option<bool> {
        let bit = match mode {
            MODE_CSP => 7,
            MODE_HOMING => 5,
            _ => return None,
        };
        self.value(0x6502).map(|m| m & (1 << bit) != 0)
    }
}

/// Reads every object of [`PROBED`] once. An object that answers with an
/// SDO abort is absent; any other failure (no mailbox answer) is an error:
/// the drive cannot be judged.
pub async fn probe<S>(sd: &SubDeviceRef<'_, S>) -> Result<Dictionary, Error>
where
    S: Deref<Target = SubDevice>,
{
    let mut d = Dictionary::default();
    for e in PROBED {
        match read_entry(sd, &e).await {
            Ok(v) => d.present.push((e, v)),
            Err(err) => match abort_code(&err) {
                Some(code) => d.absent.push((e, code)),
                None => return Err(err),
            },
        }
    }
    if let Some(n) = d.value(0x60E3) {
        d.homing_methods = Some(homing_methods(sd, n.min(64) as u8).await);
    }
    Ok(d)
}

/// The `n` entries of 0x60E3 (signed bytes; drives that store them as 16
/// bit are read that way). An entry that cannot be read is left out.
async fn homing_methods<S>(sd: &SubDeviceRef<'_, S>, n: u8) -> Vec<i8>
where
    S: Deref<Target = SubDevice>,
{
    let mut out = Vec::new();
    for k in 1..=n {
        match sd.sdo_read::<u8>(0x60E3, k).await {
            Ok(m) => out.push(m as i8),
            Err(_) => {
                if let Ok(m) = sd.sdo_read::<u16>(0x60E3, k).await {
                    out.push(m as i16 as i8);
                }
            }
        }
    }
    out
}
