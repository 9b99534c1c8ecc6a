//! One mapped SubDevice's set-up over CoE at PRE-OP: the objects the layout
//! needs (an SDO abort names the SubDevice and the object), the PDO mapping
//! and assignment, cyclic synchronous position, and its synchronisation (DC
//! SYNC0 or free run).

use std::ops::Deref;

use ethercrab::error::{Error, MailboxError};
use ethercrab::{EtherCrabWireWrite, SubDevice, SubDeviceRef};
use motion_config::{EthercatBus, EthercatDc};

use crate::pdo::{
    object_name, PdoEntry, PdoLayout, TorqueLimits, FOLLOWING_ERROR_WINDOW, MAX_TORQUE, MODE_CSP,
    NEGATIVE_TORQUE_LIMIT, POSITIVE_TORQUE_LIMIT, RXPDO_ASSIGN, RXPDO_INDEX, TXPDO_ASSIGN,
    TXPDO_INDEX,
};
use crate::report::StartupError;

/// What [`configure_drive`] set up.
pub(crate) struct DriveSetup {
    pub layout: PdoLayout,
    /// The drive has 0x6065 following error window.
    pub has_window: bool,
    /// It runs on DC SYNC0 (else free run).
    pub dc: bool,
}

fn abort_code(e: &Error) -> Option<u32> {
    match e {
        Error::Mailbox(MailboxError::Aborted { code, .. }) => Some(u32::from(*code)),
        _ => None,
    }
}

/// A SubDevice as messages name it.
pub(crate) struct Sd<'a> {
    pub position: usize,
    pub name: &'a str,
}

impl Sd<'_> {
    pub fn err(&self, what: String) -> StartupError {
        StartupError(format!(
            "SubDevice {} ({}): {what}",
            self.position, self.name
        ))
    }

    fn missing(&self, e: &PdoEntry, err: &Error) -> StartupError {
        match abort_code(err) {
            Some(code) => self.err(format!(
                "object {:#06X} {} not supported (SDO abort {code:#010X})",
                e.index,
                if e.name.is_empty() {
                    object_name(e.index)
                } else {
                    e.name
                }
            )),
            None => self.err(format!(
                "reading object {:#06X} {} failed: {err}",
                e.index,
                object_name(e.index)
            )),
        }
    }

    /// A warning about this SubDevice.
    fn warning(&self, what: &str) -> String {
        format!("SubDevice {} ({}): {what}", self.position, self.name)
    }
}

async fn read_entry<S>(sd: &SubDeviceRef<'_, S>, e: &PdoEntry) -> Result<u32, Error>
where
    S: Deref<Target = SubDevice>,
{
    Ok(match e.bits {
        8 => u32::from(sd.sdo_read::<u8>(e.index, e.sub).await?),
        16 => u32::from(sd.sdo_read::<u16>(e.index, e.sub).await?),
        _ => sd.sdo_read::<u32>(e.index, e.sub).await?,
    })
}

async fn write<S, T>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    index: u16,
    sub: u8,
    value: T,
) -> Result<(), StartupError>
where
    S: Deref<Target = SubDevice>,
    T: EtherCrabWireWrite,
{
    sd.sdo_write(index, sub, value).await.map_err(|e| {
        let why = match abort_code(&e) {
            Some(code) => format!("SDO abort {code:#010X}"),
            None => e.to_string(),
        };
        who.err(format!(
            "writing {index:#06X}:{sub:02X} ({}) failed: {why}",
            object_name(index)
        ))
    })
}

/// Per mapped SubDevice: objects, mapping, mode, sync.
pub(crate) async fn configure_drive<S>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    cfg: &EthercatBus,
    warnings: &mut Vec<String>,
) -> Result<DriveSetup, StartupError>
where
    S: Deref<Target = SubDevice>,
{
    let torque = torque_limits(sd, who, warnings).await?;
    let layout = PdoLayout::new(torque, cfg.keys.mode_in_pdo);
    for e in layout.required_objects() {
        if let Err(err) = read_entry(sd, &e).await {
            return Err(who.missing(&e, &err));
        }
    }
    let has_window = match read_entry(sd, &FOLLOWING_ERROR_WINDOW).await {
        Ok(_) => true,
        Err(_) => {
            warnings.push(who.warning(
                "no 0x6065 following error window, the position error tolerance is not applied",
            ));
            false
        }
    };
    map_pdos(sd, who, &layout).await?;
    set_csp(sd, who).await?;
    if has_window {
        write(sd, who, FOLLOWING_ERROR_WINDOW.index, 0, u32::MAX).await?;
    }
    let dc = synchronisation(sd, who, cfg, warnings).await?;
    Ok(DriveSetup {
        layout,
        has_window,
        dc,
    })
}

/// Torque limits per direction (0x60E0 / 0x60E1), else through 0x6072 max
/// torque.
async fn torque_limits<S>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    warnings: &mut Vec<String>,
) -> Result<TorqueLimits, StartupError>
where
    S: Deref<Target = SubDevice>,
{
    match read_entry(sd, &POSITIVE_TORQUE_LIMIT).await {
        Ok(_) => match read_entry(sd, &NEGATIVE_TORQUE_LIMIT).await {
            Ok(_) => Ok(TorqueLimits::PerDirection),
            Err(e) => Err(who.missing(&NEGATIVE_TORQUE_LIMIT, &e)),
        },
        Err(e1) if abort_code(&e1).is_some() => match read_entry(sd, &MAX_TORQUE).await {
            Ok(_) => {
                warnings.push(who.warning(
                    "no 0x60E0/0x60E1, torque limits through 0x6072 max torque (the larger \
                     limit for both directions)",
                ));
                Ok(TorqueLimits::MaxTorque)
            }
            Err(_) => Err(who.missing(&POSITIVE_TORQUE_LIMIT, &e1)),
        },
        Err(e) => Err(who.missing(&POSITIVE_TORQUE_LIMIT, &e)),
    }
}

/// PDO assignment 0x1C12/0x1C13 cleared, mappings 0x1600/0x1A00 written
/// (sub-index 0 = 0, entries, count), assignment written.
async fn map_pdos<S>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    layout: &PdoLayout,
) -> Result<(), StartupError>
where
    S: Deref<Target = SubDevice>,
{
    write(sd, who, RXPDO_ASSIGN, 0, 0u8).await?;
    write(sd, who, TXPDO_ASSIGN, 0, 0u8).await?;
    for (pdo, entries) in [
        (RXPDO_INDEX, layout.rx_entries()),
        (TXPDO_INDEX, layout.tx_entries()),
    ] {
        write(sd, who, pdo, 0, 0u8).await?;
        for (i, e) in entries.iter().enumerate() {
            write(sd, who, pdo, i as u8 + 1, e.mapping_value()).await?;
        }
        write(sd, who, pdo, 0, entries.len() as u8).await?;
    }
    write(sd, who, RXPDO_ASSIGN, 1, RXPDO_INDEX).await?;
    write(sd, who, RXPDO_ASSIGN, 0, 1u8).await?;
    write(sd, who, TXPDO_ASSIGN, 1, TXPDO_INDEX).await?;
    write(sd, who, TXPDO_ASSIGN, 0, 1u8).await
}

/// 0x6060 = 8 (cyclic synchronous position), checked in 0x6061.
async fn set_csp<S>(sd: &SubDeviceRef<'_, S>, who: &Sd<'_>) -> Result<(), StartupError>
where
    S: Deref<Target = SubDevice>,
{
    write(sd, who, 0x6060, 0, MODE_CSP as u8).await?;
    let shown = sd.sdo_read::<u8>(0x6061, 0).await.map_err(|e| {
        who.err(format!(
            "reading 0x6061 modes of operation display failed: {e}"
        ))
    })?;
    if shown as i8 != MODE_CSP {
        return Err(who.err(format!(
            "0x6061 shows mode {} after 0x6060 = 8 (cyclic synchronous position)",
            shown as i8
        )));
    }
    Ok(())
}

/// DC SYNC0 where the drive and `dc` allow it (0x1C32:01 = 2), free run
/// otherwise (0); 0x1C32:02 = the cycle. Returns whether it runs on DC.
async fn synchronisation<S>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    cfg: &EthercatBus,
    warnings: &mut Vec<String>,
) -> Result<bool, StartupError>
where
    S: Deref<Target = SubDevice>,
{
    let supported = sd.sdo_read::<u16>(0x1C32, 4).await.ok();
    let drive_dc = supported.is_some_and(|s| s & 0x0004 != 0);
    let esc_dc = sd.dc_support().enhanced();
    let dc = match cfg.keys.dc {
        EthercatDc::Off => false,
        EthercatDc::Auto => drive_dc && esc_dc,
        EthercatDc::On => {
            if !(drive_dc && esc_dc) {
                return Err(who.err(format!(
                    "dc = \"on\" but the SubDevice does not support DC SYNC0 (ESC: {:?}, \
                     0x1C32:04 supported sync types: {})",
                    sd.dc_support(),
                    supported.map_or("absent".to_string(), |s| format!("{s:#06x}"))
                )));
            }
            true
        }
    };
    if supported.is_some() {
        let mode: u16 = if dc { 2 } else { 0 };
        write(sd, who, 0x1C32, 1, mode).await?;
        // the inputs follow the outputs' mode; not every drive lets it be set
        let _ = sd.sdo_write(0x1C33, 1, mode).await;
        let ns = u32::try_from(cfg.cycle().as_nanos()).unwrap_or(u32::MAX);
        if sd.sdo_write(0x1C32, 2, ns).await.is_err() {
            warnings.push(who.warning("0x1C32:02 cycle time not writable"));
        }
    }
    Ok(dc)
}
