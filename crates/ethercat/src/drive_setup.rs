//! One mapped SubDevice's set-up over CoE at PRE-OP:
//!
//! 1. its dictionary is read ([`crate::dictionary`]) and checked against
//!    what its axis needs ([`crate::wants`]): every missing object at once;
//! 2. the PDO mapping is settled ([`crate::mapping`]: written, predefined
//!    or fixed);
//! 3. 0x6060 = 8 (cyclic synchronous position), 0x6061 awaited for
//!    [`MODE_PREOP_WAIT`] — a drive that shows its mode only later is
//!    checked again in SAFE-OP ([`await_mode`], by `startup`);
//! 4. the following error window off, the drive's own homing parameters
//!    (0x6098 method, 0x6099 speeds, 0x609A acceleration, 0x607C = 0);
//! 5. its synchronisation: DC SYNC0 where the drive and `dc` allow it
//!    (0x1C32:01 = 2), free run otherwise (0); 0x1C32:02 = the cycle.
//!
//! What was set up is kept as lines for the start-up log
//! ([`DriveSetup::lines`]): the mapping in force (objects, offsets, bits),
//! the sync mode and cycle, the stop, the brake, the homing, and what is
//! unavailable.

use std::ops::Deref;
use std::time::Duration;

use ethercrab::{EtherCrabWireWrite, SubDevice, SubDeviceRef};
use motion_config::ethercat::{BusAxis, DriveHomingPlan};
use motion_config::{EthercatBus, EthercatDc};
use motion_rt::now_ns;

use crate::dictionary::{abort_code, probe, Dictionary};
use crate::io::Until;
use crate::mapping;
use crate::objects::*;
use crate::pdo::PdoLayout;
use crate::report::{Sd, StartupError};
use crate::wants::{unavailable, Wants};

/// How long 0x6061 is awaited at PRE-OP before the check moves to SAFE-OP.
pub const MODE_PREOP_WAIT: Duration = Duration::from_millis(200);
/// How long 0x6061 is awaited in SAFE-OP (a drive that updates its mode
/// display only there).
pub const MODE_SAFEOP_WAIT: Duration = Duration::from_secs(2);

/// What [`configure_drive`] set up.
pub(crate) struct DriveSetup {
    pub layout: PdoLayout,
    /// The drive has 0x6065 following error window.
    pub has_window: bool,
    /// It runs on DC SYNC0 (else free run).
    pub dc: bool,
    /// 0x6061 showed cyclic synchronous position at PRE-OP (else it is
    /// awaited again in SAFE-OP).
    pub mode_shown: bool,
    /// The drive's own homing, if its axis's drive homes.
    pub homing: Option<DriveHomingPlan>,
    /// For the start-up log.
    pub lines: Vec<String>,
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

/// Per mapped SubDevice: dictionary, needs, mapping, mode, homing, sync.
pub(crate) async fn configure_drive<S>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    axis: &BusAxis,
    cfg: &EthercatBus,
) -> Result<DriveSetup, StartupError>
where
    S: Deref<Target = SubDevice>,
{
    let dict = probe(sd)
        .await
        .map_err(|e| who.err(format!("reading its object dictionary failed: {e}")))?;
    let wants = Wants::of(&axis.name, &axis.needs, &dict, cfg.keys.mode_in_pdo);
    if !wants.missing.is_empty() {
        return Err(who.err(format!(
            "{} problem(s) for axis {}:\n    {}",
            wants.missing.len(),
            axis.name,
            wants.missing.join("\n    ")
        )));
    }
    let (layout, source) = mapping::settle(sd, who, &wants).await?;
    write(sd, who, 0x6060, 0, MODE_CSP as u8).await?;
    let mode_shown = await_mode(sd, MODE_CSP, MODE_PREOP_WAIT).await;
    let has_window = dict.has(0x6065);
    if has_window {
        write(sd, who, FOLLOWING_ERROR_WINDOW.index, 0, u32::MAX).await?;
    }
    if let Some(h) = &wants.drive_homing {
        write(sd, who, 0x6098, 0, h.method as u8).await?;
        write(sd, who, 0x6099, 1, h.speed_switch).await?;
        write(sd, who, 0x6099, 2, h.speed_zero).await?;
        write(sd, who, 0x609A, 0, h.acceleration).await?;
        write(sd, who, 0x607C, 0, 0u32).await?;
    }
    let mut lines = vec![format!("mapping {source}")];
    lines.extend(layout.describe());
    let (dc, sync) = synchronisation(sd, who, cfg).await?;
    lines.push(sync);
    lines.extend(stop_lines(&dict, axis, cfg));
    if let Some(h) = &wants.drive_homing {
        lines.push(format!(
            "drive homing: method {} ({}), 0x6099 speeds {} / {} counts/s, 0x609A {} \
             counts/s², 0x607C home offset 0; 0x6060/0x6061 in the process data",
            h.method,
            motion_config::ethercat::homing::method_name(h.method),
            h.speed_switch,
            h.speed_zero,
            h.acceleration
        ));
    }
    if !mode_shown {
        lines.push(format!(
            "0x6061 did not show mode 8 within {} ms at PRE-OP: awaited again in SAFE-OP",
            MODE_PREOP_WAIT.as_millis()
        ));
    }
    lines.extend(unavailable(&layout, &dict));
    Ok(DriveSetup {
        layout,
        has_window,
        dc,
        mode_shown,
        homing: wants.drive_homing,
        lines,
    })
}

/// The stop as this drive does it: quick stop option code, the bound,
/// the brake.
fn stop_lines(dict: &Dictionary, axis: &BusAxis, cfg: &EthercatBus) -> Vec<String> {
    let qs = match dict.value(0x605A) {
        Some(v) => format!("0x605A quick stop option code {}", v as u16 as i16),
        None => "no 0x605A quick stop option code".into(),
    };
    let mut out = vec![format!(
        "stop: quick stop ({qs}), then disable voltage once at rest or after {} ms",
        cfg.keys.quick_stop_timeout_ms
    )];
    if axis.needs.brake_delay_ms > 0 {
        out.push(format!(
            "brake: every stop ends with disable operation (the drive closes its brake, \
             0x605C), {} ms with the power stage on, then disable voltage",
            axis.needs.brake_delay_ms
        ));
    }
    out
}

/// Waits up to `bound` for 0x6061 to show `mode` (read over SDO every
/// 10 ms); true once it does.
pub(crate) async fn await_mode<S>(sd: &SubDeviceRef<'_, S>, mode: i8, bound: Duration) -> bool
where
    S: Deref<Target = SubDevice>,
{
    let until = now_ns() + bound.as_nanos() as u64;
    loop {
        if let Ok(shown) = sd.sdo_read::<u8>(0x6061, 0).await {
            if shown as i8 == mode {
                return true;
            }
        }
        if now_ns() >= until {
            return false;
        }
        Until(now_ns() + 10_000_000).await;
    }
}

/// DC SYNC0 where the drive and `dc` allow it (0x1C32:01 = 2), free run
/// otherwise (0); 0x1C32:02 = the cycle. Returns whether it runs on DC and
/// the line for the log.
async fn synchronisation<S>(
    sd: &SubDeviceRef<'_, S>,
    who: &Sd<'_>,
    cfg: &EthercatBus,
) -> Result<(bool, String), StartupError>
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
    let cycle_us = cfg.cycle().as_micros();
    let mut line = if dc {
        format!("sync: DC SYNC0, cycle {cycle_us} µs (0x1C32:01 = 2), shift half a cycle")
    } else {
        format!("sync: free run, cycle {cycle_us} µs (0x1C32:01 = 0)")
    };
    if supported.is_some() {
        let mode: u16 = if dc { 2 } else { 0 };
        write(sd, who, 0x1C32, 1, mode).await?;
        // the inputs follow the outputs' mode; not every drive lets it be set
        let _ = sd.sdo_write(0x1C33, 1, mode).await;
        let ns = u32::try_from(cfg.cycle().as_nanos()).unwrap_or(u32::MAX);
        if sd.sdo_write(0x1C32, 2, ns).await.is_err() {
            line.push_str("; 0x1C32:02 cycle time not writable");
        }
    } else {
        line.push_str("; no 0x1C32 sync manager parameters");
    }
    Ok((dc, line))
}
