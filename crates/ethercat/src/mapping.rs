//! The PDO mapping of one drive, as drives have them (at PRE-OP, over CoE):
//!
//! 1. the mapping in force is read (0x1C12 / 0x1C13 assignment, each
//!    assigned PDO's entries);
//! 2. **writable**: the backend writes its own mapping (every object it
//!    wants, [`crate::wants`]) into the first assigned PDO of each
//!    direction (0x1600 / 0x1A00 when none is) and assigns it; a drive that
//!    refuses the length gets the required objects only;
//! 3. **fixed mapping, assignable**: where the mapping objects cannot be
//!    written, the predefined PDOs (0x1600..0x1607, 0x1700..0x1707 and the
//!    0x1Axx / 0x1Bxx ones) are read and the smallest one per direction
//!    that carries every required object is assigned;
//! 4. **fixed assignment**: the mapping in force is used if it carries
//!    every required object.
//!
//! Only when none does is the drive refused, with what each candidate
//! lacks. The result is the layout in force ([`PdoLayout`]) and how it
//! came about ([`Source`]).

use std::fmt;
use std::ops::Deref;

use ethercrab::error::Error;
use ethercrab::{SubDevice, SubDeviceRef};

use crate::dictionary::abort_code;
use crate::objects::*;
use crate::pdo::{PdoLayout, MAX_PDOS};
use crate::report::{Sd, StartupError};
use crate::wants::Wants;

/// How the layout in force came about.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// The backend's own mapping, written.
    Written,
    /// The drive's mapping is fixed; predefined PDOs assigned.
    Predefined,
    /// Mapping and assignment are fixed: the drive's own, as it was.
    Fixed,
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Source::Written => "written by the backend",
            Source::Predefined => "predefined PDOs assigned (the mapping objects are fixed)",
            Source::Fixed => "fixed (mapping and assignment as the drive has them)",
        })
    }
}

/// One PDO object and its entries.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Pdo {
    pub index: u16,
    pub entries: Vec<PdoEntry>,
}

impl Pdo {
    fn bytes(&self) -> usize {
        self.entries
            .iter()
            .map(|e| usize::from(e.bits))
            .sum::<usize>()
            / 8
    }

    fn describe(&self) -> String {
        let e: Vec<String> = self
            .entries
            .iter()
            .map(|e| format!("{:#06X}", e.index))
            .collect();
        format!("{:#06X} [{}]", self.index, e.join(", "))
    }
}

/// The entries of PDO object `index`; `None` if it does not exist.
async fn read_pdo<S>(sd: &SubDeviceRef<'_, S>, index: u16) -> Result<Option<Pdo>, Error>
where
    S: Deref<Target = SubDevice>,
{
    let n = match sd.sdo_read::<u8>(index, 0).await {
        Ok(n) => n,
        Err(e) if abort_code(&e).is_some() => return Ok(None),
        Err(e) => return Err(e),
    };
    let mut entries = Vec::new();
    for k in 1..=n.min(64) {
        let v = sd.sdo_read::<u32>(index, k).await?;
        entries.push(PdoEntry::from_mapping_value(v));
    }
    Ok(Some(Pdo { index, entries }))
}

/// The PDOs assigned in `assign` (0x1C12 / 0x1C13), with their entries.
pub(crate) async fn assigned<S>(sd: &SubDeviceRef<'_, S>, assign: u16) -> Result<Vec<Pdo>, Error>
where
    S: Deref<Target = SubDevice>,
{
    let n = sd.sdo_read::<u8>(assign, 0).await?;
    let mut out = Vec::new();
    for k in 1..=n.min(MAX_PDOS as u8) {
        let index = sd.sdo_read::<u16>(assign, k).await?;
        if let Some(p) = read_pdo(sd, index).await? {
            out.push(p);
        }
    }
    Ok(out)
}

/// The PDO objects a drive may predefine in one direction.
fn predefined(rx: bool) -> impl Iterator<Item = u16> {
    let base: u16 = if rx { 0x1600 } else { 0x1A00 };
    (base..base + 8).chain(base + 0x100..base + 0x108)
}

/// SDO write; the abort code (or 0 for another failure) on refusal.
async fn write<S, T>(
    sd: &SubDeviceRef<'_, S>,
    index: u16,
    sub: u8,
    v: T,
) -> Result<(), (u16, u8, u32)>
where
    S: Deref<Target = SubDevice>,
    T: ethercrab::EtherCrabWireWrite,
{
    sd.sdo_write(index, sub, v)
        .await
        .map_err(|e| (index, sub, abort_code(&e).unwrap_or(0)))
}

/// Writes `entries` into mapping object `pdo` (sub-index 0 = 0, entries,
/// count).
async fn write_pdo<S>(
    sd: &SubDeviceRef<'_, S>,
    pdo: u16,
    entries: &[PdoEntry],
) -> Result<(), (u16, u8, u32)>
where
    S: Deref<Target = SubDevice>,
{
    write(sd, pdo, 0, 0u8).await?;
    for (i, e) in entries.iter().enumerate() {
        write(sd, pdo, i as u8 + 1, e.mapping_value()).await?;
    }
    write(sd, pdo, 0, entries.len() as u8).await
}

/// Assigns `pdos` in `assign` (sub-index 0 = 0, entries, count).
async fn write_assign<S>(
    sd: &SubDeviceRef<'_, S>,
    assign: u16,
    pdos: &[u16],
) -> Result<(), (u16, u8, u32)>
where
    S: Deref<Target = SubDevice>,
{
    write(sd, assign, 0, 0u8).await?;
    for (i, p) in pdos.iter().enumerate() {
        write(sd, assign, i as u8 + 1, *p).await?;
    }
    write(sd, assign, 0, pdos.len() as u8).await
}

fn refusal((index, sub, code): (u16, u8, u32)) -> String {
    format!(
        "{index:#06X}:{sub:02X} {} not writable (SDO abort {code:#010X})",
        object_name(index)
    )
}

/// Settles the mapping of one drive (see the module docs).
pub(crate) async fn settle<S>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    wants: &Wants,
) -> Result<(PdoLayout, Source), StartupError>
where
    S: Deref<Target = SubDevice>,
{
    let comm = |e: Error| who.err(format!("reading the PDO mapping failed: {e}"));
    let rx_now = assigned(sd, RXPDO_ASSIGN).await.map_err(comm)?;
    let tx_now = assigned(sd, TXPDO_ASSIGN).await.map_err(comm)?;
    let rx_pdo = rx_now.first().map_or(RXPDO_INDEX, |p| p.index);
    let tx_pdo = tx_now.first().map_or(TXPDO_INDEX, |p| p.index);
    // 2. our own mapping: everything wanted, else the required objects
    let mut why_not = None;
    for all in [true, false] {
        let rx = wants.entries(true, all);
        let tx = wants.entries(false, all);
        let wrote = async {
            write_assign(sd, RXPDO_ASSIGN, &[]).await?;
            write_assign(sd, TXPDO_ASSIGN, &[]).await?;
            write_pdo(sd, rx_pdo, &rx).await?;
            write_pdo(sd, tx_pdo, &tx).await?;
            write_assign(sd, RXPDO_ASSIGN, &[rx_pdo]).await?;
            write_assign(sd, TXPDO_ASSIGN, &[tx_pdo]).await
        }
        .await;
        match wrote {
            Ok(()) => {
                let layout = PdoLayout::from_entries(&rx, &tx, &[rx_pdo], &[tx_pdo])
                    .map_err(|_| who.err("the mapping has too many entries".into()))?;
                return Ok((layout, Source::Written));
            }
            // the assignment itself is fixed: only the mapping in force
            Err(e @ (RXPDO_ASSIGN | TXPDO_ASSIGN, _, _)) => {
                why_not = Some(refusal(e));
                return in_force(who, wants, &rx_now, &tx_now, why_not.as_deref());
            }
            Err(e) => why_not = Some(refusal(e)),
        }
    }
    // 3. fixed mappings: the predefined PDOs
    let mut candidates = (Vec::new(), Vec::new());
    for rx in [true, false] {
        let list = if rx {
            &mut candidates.0
        } else {
            &mut candidates.1
        };
        for index in predefined(rx) {
            if let Some(p) = read_pdo(sd, index).await.map_err(comm)? {
                if !p.entries.is_empty() {
                    list.push(p);
                }
            }
        }
    }
    let pick = |rx: bool, list: &[Pdo]| -> Option<Pdo> {
        list.iter()
            .filter(|p| wants.lacks(rx, &p.entries).is_empty())
            .min_by_key(|p| p.bytes())
            .cloned()
    };
    match (pick(true, &candidates.0), pick(false, &candidates.1)) {
        (Some(r), Some(t)) => {
            let assign = async {
                write_assign(sd, RXPDO_ASSIGN, &[r.index]).await?;
                write_assign(sd, TXPDO_ASSIGN, &[t.index]).await
            }
            .await;
            assign.map_err(|e| {
                who.err(format!(
                    "assigning {:#06X}/{:#06X}: {}",
                    r.index,
                    t.index,
                    refusal(e)
                ))
            })?;
            let layout = PdoLayout::from_entries(&r.entries, &t.entries, &[r.index], &[t.index])
                .map_err(|_| who.err("the mapping has too many entries".into()))?;
            Ok((layout, Source::Predefined))
        }
        _ => Err(none_fits(
            who,
            wants,
            &candidates.0,
            &candidates.1,
            why_not.as_deref(),
        )),
    }
}

/// 4. the mapping in force, if it carries every required object.
fn in_force(
    who: &Sd<'_>,
    wants: &Wants,
    rx: &[Pdo],
    tx: &[Pdo],
    why_not: Option<&str>,
) -> Result<(PdoLayout, Source), StartupError> {
    let flat = |l: &[Pdo]| -> Vec<PdoEntry> { l.iter().flat_map(|p| p.entries.clone()).collect() };
    let (r, t) = (flat(rx), flat(tx));
    let lacks: Vec<String> = wants
        .lacks(true, &r)
        .into_iter()
        .chain(wants.lacks(false, &t))
        .collect();
    if !lacks.is_empty() {
        let desc: Vec<String> = rx.iter().chain(tx).map(Pdo::describe).collect();
        return Err(who.err(format!(
            "the PDO mapping in force ({}) cannot be changed ({}) and lacks: {}",
            desc.join(", "),
            why_not.unwrap_or("fixed"),
            lacks.join("; ")
        )));
    }
    let idx = |l: &[Pdo]| -> Vec<u16> { l.iter().map(|p| p.index).collect() };
    let layout = PdoLayout::from_entries(&r, &t, &idx(rx), &idx(tx))
        .map_err(|_| who.err("the mapping in force has too many entries".into()))?;
    Ok((layout, Source::Fixed))
}

/// The refusal when no predefined PDO carries what the axis needs.
fn none_fits(
    who: &Sd<'_>,
    wants: &Wants,
    rx: &[Pdo],
    tx: &[Pdo],
    why_not: Option<&str>,
) -> StartupError {
    let mut lines = vec![format!(
        "no PDO mapping carries what the axis needs: the mapping objects cannot be written ({})",
        why_not.unwrap_or("fixed")
    )];
    for (dir, list, is_rx) in [("RxPDO", rx, true), ("TxPDO", tx, false)] {
        if list.is_empty() {
            lines.push(format!("  no {dir} is predefined"));
        }
        for p in list {
            let lacks = wants.lacks(is_rx, &p.entries);
            let verdict = if lacks.is_empty() {
                "has every required object".to_string()
            } else {
                format!("lacks {}", lacks.join("; "))
            };
            lines.push(format!("  {dir} {}: {verdict}", p.describe()));
        }
    }
    who.err(lines.join("\n"))
}
