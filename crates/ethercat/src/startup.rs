//! Bus start-up, INIT → OP: ethercrab discovers the SubDevices and brings
//! them to PRE-OP; then, per mapped SubDevice, over CoE
//! ([`crate::drive_setup`]): its dictionary checked against what its axis
//! needs, the PDO mapping settled (written, predefined or fixed), 0x6060 =
//! 8 (CSP) with 0x6061 awaited, the drive's own homing parameters, DC SYNC0
//! or free run. **Every drive is checked before any is refused**: the
//! start-up error lists, per drive, every missing or unsupported object.
//!
//! Then the SM watchdog (0x0400 divider = 100 µs, 0x0420 = `sm_watchdog_ms`,
//! the SM2 watchdog enable bit checked); ethercrab reads the mapping back to
//! size SM2/SM3 and the FMMUs (PRE-OP with PDI), DC SYNC0 is configured,
//! SAFE-OP — where a drive that did not show its mode at PRE-OP gets
//! another bound to show it — and OP is requested; the bus thread cycles
//! process data until every SubDevice reports OP. Each drive's report
//! carries the lines of its set-up for the log (mapping in force, sync
//! mode and cycle, SM watchdog, stop, brake, homing, unavailable objects).

use std::time::Duration;

use ethercrab::error::Error;
use ethercrab::subdevice_group::{DcConfiguration, NoDc, Op, PreOp, PreOpPdi};
use ethercrab::{DcSync, MainDevice};
use motion_config::{EthercatBus, EthercatDrive};

use crate::capacity::{MAX_PDI, MAX_SUBDEVICES};
use crate::drive_setup::{await_mode, configure_drive, MODE_SAFEOP_WAIT};
use crate::group::{Group, OpGroup};
use crate::objects::MODE_CSP;
use crate::pdo::PdoLayout;
use crate::report::{Sd, StartupError, SubDeviceReport, SyncMode};

/// Per axis, what the bus thread needs.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct AxisPlan {
    /// Index in the group (= bus position).
    pub sd: usize,
    pub layout: PdoLayout,
    pub has_window: bool,
    /// The drive's own homing, if its axis's drive homes.
    pub homing: Option<motion_config::ethercat::DriveHomingPlan>,
    /// 0x6061 has not yet shown mode 8 (awaited in SAFE-OP).
    pub mode_pending: bool,
}

/// What start-up hands the bus thread: the group with OP requested, the
/// plan of each axis, the report of each SubDevice and each axis' sync mode.
pub(crate) struct Started {
    pub group: OpGroup,
    pub plans: Vec<AxisPlan>,
    pub reports: Vec<SubDeviceReport>,
    pub syncs: Vec<SyncMode>,
}

/// Selects the SubDevice of each axis.
fn map_axes(cfg: &EthercatBus, names: &[String]) -> Result<Vec<usize>, StartupError> {
    let mut out = Vec::new();
    for a in &cfg.axes {
        let idx = match &a.ethercat.drive {
            EthercatDrive::Position(p) => {
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
            EthercatDrive::Name(n) => {
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
    cfg: &EthercatBus,
    warnings: &mut Vec<String>,
) -> Result<Started, StartupError> {
    let interface = &cfg.keys.interface;
    let mut group = md
        .init_single_group::<MAX_SUBDEVICES, MAX_PDI>(ethercrab::std::ethercat_now)
        .await
        .map_err(|e| StartupError(format!("bus initialisation on {interface} failed: {e}")))?;
    if group.is_empty() {
        return Err(StartupError(format!(
            "no SubDevice answers on {interface} (cable, interface, link up?)"
        )));
    }
    let mut reports = discovered(&group, md);
    let names: Vec<String> = reports.iter().map(|r| r.name.clone()).collect();
    let map = map_axes(cfg, &names)?;
    let (plans, syncs) = configure_axes(&group, md, cfg, &map, &mut reports).await?;
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
    check_process_data(&group, md, cfg, &plans, &mut reports, warnings).await?;
    let group = into_op(group, md, cfg, any_dc, &plans, &reports).await?;
    Ok(Started {
        group,
        plans,
        reports,
        syncs,
    })
}

/// The report of every SubDevice ethercrab found, before any set-up.
fn discovered(group: &Group<PreOp, NoDc>, md: &MainDevice<'_>) -> Vec<SubDeviceReport> {
    group
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
                lines: Vec::new(),
            }
        })
        .collect()
}

/// Sets up the drive of every axis (`map`: its SubDevice) over CoE and
/// notes in its report which axis it drives, how it is synchronised and
/// the lines of its set-up. Every drive is set up (or found wanting)
/// before an error is returned: the error lists every drive's problems.
async fn configure_axes(
    group: &Group<PreOp, NoDc>,
    md: &MainDevice<'_>,
    cfg: &EthercatBus,
    map: &[usize],
    reports: &mut [SubDeviceReport],
) -> Result<(Vec<AxisPlan>, Vec<SyncMode>), StartupError> {
    let mut plans = Vec::new();
    let mut syncs = Vec::new();
    let mut errors = Vec::new();
    for (axis, &sdi) in cfg.axes.iter().zip(map) {
        let sd = group
            .subdevice(md, sdi)
            .map_err(|e| StartupError(format!("SubDevice {sdi}: {e}")))?;
        let name = reports[sdi].name.clone();
        let who = Sd {
            position: sdi,
            name: &name,
        };
        let setup = match configure_drive(&sd, &who, axis, cfg).await {
            Ok(s) => s,
            Err(e) => {
                errors.push(e.0);
                continue;
            }
        };
        // 0x1008 through a normal (or segmented) upload, for the report
        reports[sdi].device_name = sd
            .sdo_read::<heapless::String<96>>(0x1008, 0)
            .await
            .ok()
            .map(|s| s.as_str().to_string());
        reports[sdi].axis = Some(axis.name.clone());
        let sync = if setup.dc {
            SyncMode::Dc
        } else {
            SyncMode::FreeRun
        };
        reports[sdi].sync = Some(sync);
        reports[sdi].lines = setup.lines;
        syncs.push(sync);
        plans.push(AxisPlan {
            sd: sdi,
            layout: setup.layout,
            has_window: setup.has_window,
            homing: setup.homing,
            mode_pending: !setup.mode_shown,
        });
    }
    if !errors.is_empty() {
        return Err(StartupError(format!(
            "{} of {} drive(s) cannot run their axes; nothing was started:\n  {}",
            errors.len(),
            map.len(),
            errors.join("\n  ")
        )));
    }
    Ok((plans, syncs))
}

/// Process-data sizes as the drives report them vs the layout written; the
/// SM watchdog (0x0400 divider = 100 µs, 0x0420 = `sm_watchdog_ms`) and its
/// enable bit.
async fn check_process_data(
    group: &Group<PreOpPdi, NoDc>,
    md: &MainDevice<'_>,
    cfg: &EthercatBus,
    plans: &[AxisPlan],
    reports: &mut [SubDeviceReport],
    warnings: &mut Vec<String>,
) -> Result<(), StartupError> {
    let wd_ms = cfg.sm_watchdog().as_millis();
    let wd_units = u16::try_from((cfg.sm_watchdog().as_micros() / 100).max(1)).unwrap_or(u16::MAX);
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
            name: &reports[i].name,
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
        let mut line = format!(
            "SM watchdog: {wd_ms} ms (0x0400 = 2498: 100 µs units, 0x0420 = {wd_units}), SM2 \
             watchdog on: the drive stops this long after the last process data"
        );
        if control & 0x40 == 0 {
            line.push_str(" (switched on: its EEPROM had it off)");
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
                reports[i].name
            ));
        }
        reports[i].lines.push(line);
    }
    Ok(())
}

/// DC SYNC0 configured (if any SubDevice runs on DC), SAFE-OP, OP requested.
async fn into_op(
    group: Group<PreOpPdi, NoDc>,
    md: &MainDevice<'_>,
    cfg: &EthercatBus,
    any_dc: bool,
    plans: &[AxisPlan],
    reports: &[SubDeviceReport],
) -> Result<OpGroup, StartupError> {
    if !any_dc {
        return Ok(OpGroup::FreeRun(
            request_op(group, md, plans, reports).await?,
        ));
    }
    let g = group
        .configure_dc_sync(
            md,
            DcConfiguration {
                start_delay: Duration::from_millis(100),
                sync0_period: cfg.cycle(),
                sync0_shift: cfg.cycle() / 2,
            },
        )
        .await
        .map_err(|e| StartupError(format!("DC SYNC0 configuration failed: {e}")))?;
    Ok(OpGroup::Dc(request_op(g, md, plans, reports).await?))
}

/// SAFE-OP — where the mode display of a drive that did not show it at
/// PRE-OP is awaited again, with a bound — then OP requested (the bus
/// thread cycles process data until every SubDevice has reached it).
async fn request_op<DC>(
    group: Group<PreOpPdi, DC>,
    md: &MainDevice<'_>,
    plans: &[AxisPlan],
    reports: &[SubDeviceReport],
) -> Result<Group<Op, DC>, StartupError> {
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
    let g = group
        .into_safe_op(md)
        .await
        .map_err(|e| transition(e, "SAFE-OP"))?;
    for p in plans.iter().filter(|p| p.mode_pending) {
        let sd = g
            .subdevice(md, p.sd)
            .map_err(|e| StartupError(format!("SubDevice {}: {e}", p.sd)))?;
        if !await_mode(&sd, MODE_CSP, MODE_SAFEOP_WAIT).await {
            let shown = sd.sdo_read::<u8>(0x6061, 0).await.map(|m| m as i8);
            return Err(Sd {
                position: p.sd,
                name: &reports[p.sd].name,
            }
            .err(format!(
                "0x6061 modes of operation display shows {} after 0x6060 = 8 (cyclic \
                 synchronous position), still {} ms into SAFE-OP",
                shown.map_or("nothing readable".into(), |m| m.to_string()),
                MODE_SAFEOP_WAIT.as_millis()
            )));
        }
    }
    g.request_into_op(md).await.map_err(|e| transition(e, "OP"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_config::ethercat::BusAxis;

    fn cfg(sel: &[EthercatDrive]) -> EthercatBus {
        EthercatBus::new(
            "x",
            1000,
            sel.iter()
                .enumerate()
                .map(|(i, s)| {
                    let mut a = BusAxis::at(&format!("A{i}"), 0);
                    a.ethercat.drive = s.clone();
                    a
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
            EthercatDrive::Position(2),
            EthercatDrive::Name("Spindle".into()),
        ]);
        assert_eq!(map_axes(&c, &names).unwrap(), [2, 3]);
        let e = map_axes(&cfg(&[EthercatDrive::Name("Servo".into())]), &names).unwrap_err();
        assert!(e.0.contains("2 SubDevices named \"Servo\""), "{e}");
        let e = map_axes(&cfg(&[EthercatDrive::Position(4)]), &names).unwrap_err();
        assert!(e.0.contains("no SubDevice at position 4 (4 found"), "{e}");
        let e = map_axes(&cfg(&[EthercatDrive::Name("X".into())]), &names).unwrap_err();
        assert!(e.0.contains("no SubDevice named \"X\""), "{e}");
        let e = map_axes(
            &cfg(&[
                EthercatDrive::Position(3),
                EthercatDrive::Name("Spindle".into()),
            ]),
            &names,
        )
        .unwrap_err();
        assert!(e.0.contains("already used"), "{e}");
    }
}
