//! Bus start-up, INIT → OP: ethercrab discovers the SubDevices and brings
//! them to PRE-OP; then, per mapped SubDevice, over CoE:
//!
//! 1. every object the layout needs is read once — an SDO abort is a
//!    start-up error naming the SubDevice and the object ("SubDevice 1
//!    (name): object 0x60B8 touch probe function not supported (SDO abort
//!    0x06020000)"); the torque limits fall back from 0x60E0/0x60E1 to
//!    0x6072;
//! 2. PDO assignment 0x1C12/0x1C13 cleared, mappings 0x1600/0x1A00 written
//!    (sub-index 0 = 0, entries, count), assignment written;
//! 3. 0x6060 = 8 (CSP), checked in 0x6061;
//! 4. synchronisation: DC SYNC0 where the drive and `dc` allow it (0x1C32:01
//!    = 2, SYNC0 = the bus cycle), free run otherwise (0x1C32:01 = 0);
//!    0x1C32:02 = the cycle;
//! 5. the SM watchdog (0x0400 divider = 100 µs, 0x0420 = `sm_watchdog`),
//!    and the SM2 watchdog enable bit checked.
//!
//! ethercrab then reads the mapping back to size SM2/SM3 and the FMMUs
//! (PRE-OP with PDI), DC SYNC0 is configured, SAFE-OP, and OP is requested;
//! the bus thread cycles process data until every SubDevice reports OP.

use std::fmt;
use std::ops::Deref;
use std::time::Duration;

use ethercrab::error::{Error, MailboxError};
use ethercrab::subdevice_group::{DcConfiguration, HasDc, NoDc, Op};
use ethercrab::{
    DcSync, DefaultLock, EtherCrabWireWrite, MainDevice, SubDevice, SubDeviceGroup, SubDeviceRef,
};

use crate::bus::{MAX_PDI, MAX_SUBDEVICES};
use crate::config::{DcMode, EthercatConfig, SubDeviceSelector};
use crate::pdo::{
    object_name, PdoEntry, PdoLayout, TorqueLimits, FOLLOWING_ERROR_WINDOW, MAX_TORQUE, MODE_CSP,
    NEGATIVE_TORQUE_LIMIT, POSITIVE_TORQUE_LIMIT, RXPDO_ASSIGN, RXPDO_INDEX, TXPDO_ASSIGN,
    TXPDO_INDEX,
};

/// A group in OP, with or without distributed clocks.
pub(crate) type Group<S, DC> = SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, DefaultLock, S, DC>;

/// The group the bus thread cycles.
pub(crate) enum OpGroup {
    FreeRun(Group<Op, NoDc>),
    Dc(Group<Op, HasDc>),
}

/// A start-up failure, in words for the operator.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StartupError(pub String);

impl fmt::Display for StartupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for StartupError {}

/// How a SubDevice is synchronised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SyncMode {
    /// Distributed clocks, SYNC0 = the bus cycle.
    Dc,
    /// Free run (frame-triggered).
    FreeRun,
}

impl fmt::Display for SyncMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SyncMode::Dc => "dc",
            SyncMode::FreeRun => "free-run",
        })
    }
}

/// One SubDevice found on the bus.
#[derive(Clone, Debug, PartialEq)]
pub struct SubDeviceReport {
    /// Position in the bus (0-based).
    pub position: usize,
    pub name: String,
    /// Configured station address.
    pub address: u16,
    pub vendor_id: u32,
    pub product_id: u32,
    pub revision: u32,
    pub serial: u32,
    /// Supports distributed clocks (SYNC0).
    pub dc_capable: bool,
    /// Name of the axis driven through it.
    pub axis: Option<String>,
    /// `Some` for mapped SubDevices.
    pub sync: Option<SyncMode>,
    /// 0x1008 as read over CoE (normal / segmented upload), if present.
    pub device_name: Option<String>,
    /// Output / input bytes of its process data.
    pub output_bytes: usize,
    pub input_bytes: usize,
}

impl fmt::Display for SubDeviceReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "SubDevice {} ({}) at {:#06x}: vendor {:#010x} product {:#010x} rev {} serial {}, \
             {} B out / {} B in",
            self.position,
            self.name,
            self.address,
            self.vendor_id,
            self.product_id,
            self.revision,
            self.serial,
            self.output_bytes,
            self.input_bytes
        )?;
        if let (Some(axis), Some(sync)) = (&self.axis, self.sync) {
            write!(f, ", axis {axis}, {sync}")?;
        }
        Ok(())
    }
}

/// What start-up found and did.
#[derive(Clone, Debug, PartialEq)]
pub struct StartupReport {
    pub subdevices: Vec<SubDeviceReport>,
    /// Per axis (frame order): the SubDevice position and its sync mode.
    pub axes: Vec<(usize, SyncMode)>,
    /// Real-time set-up of the bus thread, as applied.
    pub rt: String,
    /// Things that work but are worth saying (not-permitted RT settings, a
    /// missing optional object).
    pub warnings: Vec<String>,
    /// INIT → OP.
    pub duration: Duration,
}

/// Per axis, what the bus thread needs.
#[derive(Clone, Debug)]
pub(crate) struct AxisPlan {
    /// Index in the group (= bus position).
    pub sd: usize,
    pub layout: PdoLayout,
    pub has_window: bool,
}

fn abort_code(e: &Error) -> Option<u32> {
    match e {
        Error::Mailbox(MailboxError::Aborted { code, .. }) => Some(u32::from(*code)),
        _ => None,
    }
}

struct Sd<'a> {
    position: usize,
    name: &'a str,
}

impl Sd<'_> {
    fn err(&self, what: String) -> StartupError {
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

/// Per mapped SubDevice: objects, mapping, mode, sync. Returns the plan
/// and whether it runs on DC.
async fn configure_drive<S>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    cfg: &EthercatConfig,
    warnings: &mut Vec<String>,
) -> Result<(PdoLayout, bool, bool), StartupError>
where
    S: Deref<Target = SubDevice>,
{
    // torque limits: per direction, else max torque
    let torque = match read_entry(sd, &POSITIVE_TORQUE_LIMIT).await {
        Ok(_) => match read_entry(sd, &NEGATIVE_TORQUE_LIMIT).await {
            Ok(_) => TorqueLimits::PerDirection,
            Err(e) => return Err(who.missing(&NEGATIVE_TORQUE_LIMIT, &e)),
        },
        Err(e1) if abort_code(&e1).is_some() => match read_entry(sd, &MAX_TORQUE).await {
            Ok(_) => {
                warnings.push(format!(
                    "SubDevice {} ({}): no 0x60E0/0x60E1, torque limits through 0x6072 \
                     max torque (the larger limit for both directions)",
                    who.position, who.name
                ));
                TorqueLimits::MaxTorque
            }
            Err(_) => return Err(who.missing(&POSITIVE_TORQUE_LIMIT, &e1)),
        },
        Err(e) => return Err(who.missing(&POSITIVE_TORQUE_LIMIT, &e)),
    };
    let layout = PdoLayout::new(torque, cfg.mode_in_pdo);
    for e in layout.required_objects() {
        if let Err(err) = read_entry(sd, &e).await {
            return Err(who.missing(&e, &err));
        }
    }
    let has_window = match read_entry(sd, &FOLLOWING_ERROR_WINDOW).await {
        Ok(_) => true,
        Err(_) => {
            warnings.push(format!(
                "SubDevice {} ({}): no 0x6065 following error window, the position \
                 error tolerance is not applied",
                who.position, who.name
            ));
            false
        }
    };

    // mapping
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
    write(sd, who, TXPDO_ASSIGN, 0, 1u8).await?;

    // mode
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
    if has_window {
        write(sd, who, FOLLOWING_ERROR_WINDOW.index, 0, u32::MAX).await?;
    }

    // synchronisation
    let supported = sd.sdo_read::<u16>(0x1C32, 4).await.ok();
    let drive_dc = supported.is_some_and(|s| s & 0x0004 != 0);
    let esc_dc = sd.dc_support().enhanced();
    let dc = match cfg.dc {
        DcMode::Off => false,
        DcMode::Auto => drive_dc && esc_dc,
        DcMode::On => {
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
        let ns = u32::try_from(cfg.cycle.as_nanos()).unwrap_or(u32::MAX);
        if sd.sdo_write(0x1C32, 2, ns).await.is_err() {
            warnings.push(format!(
                "SubDevice {} ({}): 0x1C32:02 cycle time not writable",
                who.position, who.name
            ));
        }
    }
    Ok((layout, has_window, dc))
}

/// Selects the SubDevice of each axis.
fn map_axes(cfg: &EthercatConfig, names: &[String]) -> Result<Vec<usize>, StartupError> {
    let mut out = Vec::new();
    for a in &cfg.axes {
        let idx = match &a.subdevice {
            SubDeviceSelector::Position(p) => {
                let p = usize::from(*p);
                if p >= names.len() {
                    return Err(StartupError(format!(
                        "axis {}: no SubDevice at position {p} ({} found: {})",
                        a.name,
                        names.len(),
                        names.join(", ")
                    )));
                }
                p
            }
            SubDeviceSelector::Name(n) => {
                let hits: Vec<usize> = (0..names.len()).filter(|&i| &names[i] == n).collect();
                match hits.as_slice() {
                    [one] => *one,
                    [] => {
                        return Err(StartupError(format!(
                            "axis {}: no SubDevice named {n:?} (found: {})",
                            a.name,
                            names.join(", ")
                        )))
                    }
                    many => {
                        return Err(StartupError(format!(
                            "axis {}: {} SubDevices named {n:?} (positions {:?}): map it by \
                             position",
                            a.name,
                            many.len(),
                            many
                        )))
                    }
                }
            }
        };
        if out.contains(&idx) {
            return Err(StartupError(format!(
                "axis {}: SubDevice {idx} is already used by another axis",
                a.name
            )));
        }
        out.push(idx);
    }
    Ok(out)
}

/// INIT → SAFE-OP → OP requested. The caller cycles process data until all
/// SubDevices are in OP.
pub(crate) async fn startup(
    md: &MainDevice<'_>,
    cfg: &EthercatConfig,
    warnings: &mut Vec<String>,
) -> Result<(OpGroup, Vec<AxisPlan>, Vec<SubDeviceReport>, Vec<SyncMode>), StartupError> {
    let mut group = md
        .init_single_group::<MAX_SUBDEVICES, MAX_PDI>(ethercrab::std::ethercat_now)
        .await
        .map_err(|e| {
            StartupError(format!(
                "bus initialisation on {} failed: {e}",
                cfg.interface
            ))
        })?;
    if group.is_empty() {
        return Err(StartupError(format!(
            "no SubDevice answers on {} (cable, interface, link up?)",
            cfg.interface
        )));
    }
    let mut reports: Vec<SubDeviceReport> = group
        .iter(md)
        .enumerate()
        .map(|(i, sd)| {
            let id = sd.identity();
            SubDeviceReport {
                position: i,
                name: sd.name().to_string(),
                address: sd.configured_address(),
                vendor_id: id.vendor_id,
                product_id: id.product_id,
                revision: id.revision,
                serial: id.serial,
                dc_capable: sd.dc_support().enhanced(),
                axis: None,
                sync: None,
                device_name: None,
                output_bytes: 0,
                input_bytes: 0,
            }
        })
        .collect();
    let names: Vec<String> = reports.iter().map(|r| r.name.clone()).collect();
    let map = map_axes(cfg, &names)?;

    let mut plans = Vec::new();
    let mut syncs = Vec::new();
    for (axis, &sdi) in cfg.axes.iter().zip(&map) {
        let sd = group
            .subdevice(md, sdi)
            .map_err(|e| StartupError(format!("SubDevice {sdi}: {e}")))?;
        let who = Sd {
            position: sdi,
            name: &names[sdi],
        };
        let (layout, has_window, dc) = configure_drive(&sd, &who, cfg, warnings).await?;
        // 0x1008 through a normal (or segmented) upload, for the report
        reports[sdi].device_name = sd
            .sdo_read::<heapless::String<96>>(0x1008, 0)
            .await
            .ok()
            .map(|s| s.as_str().to_string());
        reports[sdi].axis = Some(axis.name.clone());
        let sync = if dc { SyncMode::Dc } else { SyncMode::FreeRun };
        reports[sdi].sync = Some(sync);
        syncs.push(sync);
        plans.push(AxisPlan {
            sd: sdi,
            layout,
            has_window,
        });
    }
    let any_dc = syncs.contains(&SyncMode::Dc);
    if any_dc {
        for (i, mut sd) in group.iter_mut(md).enumerate() {
            if plans.iter().any(|p| p.sd == i) && reports[i].sync == Some(SyncMode::Dc) {
                sd.set_dc_sync(DcSync::Sync0);
            }
        }
    }

    let group = group
        .into_pre_op_pdi(md)
        .await
        .map_err(|e| StartupError(format!("process data configuration failed: {e}")))?;

    // sizes as the drives report them vs the layout; SM watchdog
    let wd_units = u16::try_from((cfg.sm_watchdog.as_micros() / 100).max(1)).unwrap_or(u16::MAX);
    for (i, sd) in group.iter(md).enumerate() {
        let (inp, out) = {
            let io = sd.io_raw();
            (io.inputs().len(), io.outputs().len())
        };
        reports[i].input_bytes = inp;
        reports[i].output_bytes = out;
        let Some(plan) = plans.iter().find(|p| p.sd == i) else {
            continue;
        };
        let who = Sd {
            position: i,
            name: &names[i],
        };
        if inp != plan.layout.tx_bytes() || out != plan.layout.rx_bytes() {
            return Err(who.err(format!(
                "process data is {out} B out / {inp} B in, the mapping written is {} / {}",
                plan.layout.rx_bytes(),
                plan.layout.tx_bytes()
            )));
        }
        let reg = |e: Error| who.err(format!("SM watchdog set-up failed: {e}"));
        // divider 2498 → (2498 + 2) × 40 ns = 100 µs per watchdog unit
        sd.register_write(0x0400u16, 2498u16).await.map_err(reg)?;
        sd.register_write(0x0420u16, wd_units).await.map_err(reg)?;
        let control: u8 = sd.register_read(0x0814u16).await.map_err(reg)?;
        if control & 0x40 == 0 {
            // the EEPROM left the SM2 watchdog off: switch it on (SM off,
            // control, SM on)
            let enable: u8 = sd.register_read(0x0816u16).await.map_err(reg)?;
            sd.register_write(0x0816u16, enable & !1)
                .await
                .map_err(reg)?;
            sd.register_write(0x0814u16, control | 0x40)
                .await
                .map_err(reg)?;
            sd.register_write(0x0816u16, enable).await.map_err(reg)?;
            warnings.push(format!(
                "SubDevice {i} ({}): SM2 watchdog was disabled in its EEPROM; enabled",
                names[i]
            ));
        }
    }

    let transition = |e: Error, to: &str| {
        StartupError(format!(
            "transition to {to} failed: {e} ({})",
            reports
                .iter()
                .map(|r| r.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ))
    };
    let op = if any_dc {
        let g = group
            .configure_dc_sync(
                md,
                DcConfiguration {
                    start_delay: Duration::from_millis(100),
                    sync0_period: cfg.cycle,
                    sync0_shift: cfg.cycle / 2,
                },
            )
            .await
            .map_err(|e| StartupError(format!("DC SYNC0 configuration failed: {e}")))?;
        let g = g
            .into_safe_op(md)
            .await
            .map_err(|e| transition(e, "SAFE-OP"))?;
        OpGroup::Dc(
            g.request_into_op(md)
                .await
                .map_err(|e| transition(e, "OP"))?,
        )
    } else {
        let g = group
            .into_safe_op(md)
            .await
            .map_err(|e| transition(e, "SAFE-OP"))?;
        OpGroup::FreeRun(
            g.request_into_op(md)
                .await
                .map_err(|e| transition(e, "OP"))?,
        )
    };
    Ok((op, plans, reports, syncs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::AxisMapping;

    fn cfg(sel: &[SubDeviceSelector]) -> EthercatConfig {
        EthercatConfig::new(
            "x",
            Duration::from_millis(1),
            sel.iter()
                .enumerate()
                .map(|(i, s)| AxisMapping {
                    name: format!("A{i}"),
                    subdevice: s.clone(),
                    counts_per_unit: 1.0,
                    index_pulse_bit: None,
                })
                .collect(),
        )
    }

    #[test]
    fn axes_map_by_position_and_unique_name() {
        let names: Vec<String> = ["EK1100", "Servo", "Servo", "Spindle"]
            .map(String::from)
            .to_vec();
        let c = cfg(&[
            SubDeviceSelector::Position(2),
            SubDeviceSelector::Name("Spindle".into()),
        ]);
        assert_eq!(map_axes(&c, &names).unwrap(), [2, 3]);
        let e = map_axes(&cfg(&[SubDeviceSelector::Name("Servo".into())]), &names).unwrap_err();
        assert!(e.0.contains("2 SubDevices named \"Servo\""), "{e}");
        let e = map_axes(&cfg(&[SubDeviceSelector::Position(4)]), &names).unwrap_err();
        assert!(e.0.contains("no SubDevice at position 4 (4 found"), "{e}");
        let e = map_axes(&cfg(&[SubDeviceSelector::Name("X".into())]), &names).unwrap_err();
        assert!(e.0.contains("no SubDevice named \"X\""), "{e}");
        let e = map_axes(
            &cfg(&[
                SubDeviceSelector::Position(3),
                SubDeviceSelector::Name("Spindle".into()),
            ]),
            &names,
        )
        .unwrap_err();
        assert!(e.0.contains("already used"), "{e}");
    }
}
