//! Re-configuring a SubDevice that lost its configuration (power-cycled,
//! or found in INIT / PRE-OP) while the rest of the bus runs on: without
//! restarting motion-io.
//!
//! At start-up, once every SubDevice is in OP, the registers ethercrab and
//! start-up set are copied ([`Snapshot`]: sync managers 0–3, FMMUs 0–3,
//! SM watchdog). A power-cycled SubDevice is then brought back in the order
//! of a start-up:
//!
//! 1. its station address, written at its bus position (APWR 0x0010);
//! 2. INIT (error acknowledged), the mailbox sync managers, PRE-OP;
//! 3. the drive over CoE exactly as at start-up ([`configure_drive`]: the
//!    dictionary checked, the mapping settled — it must come out as the one
//!    the cycle packs — CSP, homing parameters); in **free run**: its
//!    distributed clock restarted with the power and is not re-synchronised
//!    to the others' (with `dc = "on"` that is refused: restart motion-io);
//! 4. the process-data sync managers, FMMUs and SM watchdog as they were,
//!    SAFE-OP, the mode display awaited, and OP requested (the cycle sees
//!    it arrive).
//!
//! Its axes were faulted by the loss (`AxisLogic::lost`): nothing is enabled
//! until the supervisor asks again. A failure is reported once (the log
//! says to restart motion-io) and not retried.

use std::ops::Deref;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

use ethercrab::{Command, MainDevice, SubDevice, SubDeviceRef};
use motion_config::{EthercatBus, EthercatDc};
use motion_rt::now_ns;

use crate::drive_setup::{await_mode, configure_drive, MODE_SAFEOP_WAIT};
use crate::group::{OpGroup, Pdi};
use crate::objects::MODE_CSP;
use crate::report::{Sd, SyncMode};
use crate::startup::AxisPlan;
use crate::status::{Health, Shared};

/// Sync managers 0–3 (8 bytes each) and FMMUs 0–3 (16 bytes each) as
/// 64-bit words, the SM watchdog divider and time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Snapshot {
    sm: [u64; 4],
    fmmu: [u64; 8],
    wd_divider: u16,
    wd_time: u16,
}

/// What re-configuring needs, kept from start-up.
pub(crate) struct Recovery {
    pub cfg: EthercatBus,
    pub plans: Vec<AxisPlan>,
    pub syncs: Vec<SyncMode>,
    /// Per bus position: its name and register snapshot.
    pub names: Vec<String>,
    pub snapshots: Vec<Option<Snapshot>>,
    pub shared: Arc<Shared>,
}

impl Recovery {
    /// Notes why re-configuring SubDevice `i` failed (never blocks the bus
    /// thread: the note is dropped if the log's reader holds the list).
    pub fn failed(&self, i: usize, why: String) {
        if let Ok(mut f) = self.shared.failures.try_lock() {
            f.retain(|(k, _)| *k != i);
            f.push((i, why));
        }
        self.shared.sd[i].set_health(Health::Failed);
        self.shared.health_events.fetch_add(1, Ordering::Release);
    }
}

/// The registers of every mapped SubDevice (once in OP).
pub(crate) async fn snapshot(
    group: &OpGroup,
    md: &MainDevice<'_>,
    mapped: &[usize],
) -> Vec<Option<Snapshot>> {
    let mut out = vec![None; group.len()];
    for &i in mapped {
        if let Ok(sd) = group.subdevice(md, i) {
            out[i] = read_snapshot(&sd).await.ok();
        }
    }
    out
}

async fn read_snapshot<S>(sd: &SubDeviceRef<'_, S>) -> Result<Snapshot, ethercrab::error::Error>
where
    S: Deref<Target = SubDevice>,
{
    let mut s = Snapshot::default();
    for (k, w) in s.sm.iter_mut().enumerate() {
        *w = sd.register_read(0x0800u16 + 8 * k as u16).await?;
    }
    for (k, w) in s.fmmu.iter_mut().enumerate() {
        *w = sd.register_read(0x0600u16 + 8 * k as u16).await?;
    }
    s.wd_divider = sd.register_read(0x0400u16).await?;
    s.wd_time = sd.register_read(0x0420u16).await?;
    Ok(s)
}

/// Waits up to a second for AL state `state` (0x0130 low nibble).
async fn wait_state(sd: &Pdi<'_>, state: u16) -> Result<(), String> {
    let until = now_ns() + 1_000_000_000;
    loop {
        let st: u16 = sd
            .register_read(0x0130u16)
            .await
            .map_err(|e| format!("reading its AL status failed: {e}"))?;
        if st & 0x0F == state && st & 0x10 == 0 {
            return Ok(());
        }
        if st & 0x10 != 0 {
            let code: u16 = sd.register_read(0x0134u16).await.unwrap_or(0);
            return Err(format!(
                "it refused AL state {state:#x}: AL status {st:#06x}, code {code:#06x}"
            ));
        }
        if now_ns() > until {
            return Err(format!(
                "not in AL state {state:#x} after 1 s (AL status {st:#06x})"
            ));
        }
        crate::io::Until(now_ns() + 1_000_000).await;
    }
}

async fn request(sd: &Pdi<'_>, state: u16) -> Result<(), String> {
    sd.register_write(0x0120u16, state)
        .await
        .map_err(|e| format!("requesting AL state {state:#x} failed: {e}"))?;
    Ok(())
}

/// Re-configures SubDevice `i` (see the module docs).
pub(crate) async fn run(
    i: usize,
    rec: &Recovery,
    group: &OpGroup,
    md: &MainDevice<'_>,
) -> Result<(), String> {
    let k = rec
        .plans
        .iter()
        .position(|p| p.sd == i)
        .ok_or("it drives no axis")?;
    let snap = rec.snapshots[i].ok_or("its registers were not read at start-up")?;
    let mut cfg = rec.cfg.clone();
    if rec.syncs[k] == SyncMode::Dc {
        if cfg.keys.dc == EthercatDc::On {
            return Err(
                "it ran on distributed clocks and dc = \"on\": its clock restarted with the \
                 power, restart motion-io to synchronise it again"
                    .into(),
            );
        }
        cfg.keys.dc = EthercatDc::Off;
    }
    let sd = group.subdevice(md, i).map_err(|e| e.to_string())?;
    let at = u16::try_from(i).unwrap_or(u16::MAX);
    Command::apwr(at, 0x0010)
        .send(md, sd.configured_address())
        .await
        .map_err(|e| format!("writing its station address failed: {e}"))?;
    request(&sd, 0x0011).await?;
    wait_state(&sd, 0x01).await?;
    let regs = |e: ethercrab::error::Error| format!("restoring its registers failed: {e}");
    for (k, w) in snap.sm.iter().enumerate().take(2) {
        sd.register_write(0x0800u16 + 8 * k as u16, *w)
            .await
            .map_err(regs)?;
    }
    request(&sd, 0x02).await?;
    wait_state(&sd, 0x02).await?;
    let who = Sd {
        position: i,
        name: &rec.names[i],
    };
    let setup = configure_drive(&sd, &who, &cfg.axes[k], &cfg)
        .await
        .map_err(|e| e.0)?;
    if setup.layout != rec.plans[k].layout {
        return Err(format!(
            "its PDO mapping came out different from start-up's ({}): restart motion-io",
            setup.layout.describe().join("; ")
        ));
    }
    for (k, w) in snap.sm.iter().enumerate().skip(2) {
        sd.register_write(0x0800u16 + 8 * k as u16, *w)
            .await
            .map_err(regs)?;
    }
    for (k, w) in snap.fmmu.iter().enumerate() {
        sd.register_write(0x0600u16 + 8 * k as u16, *w)
            .await
            .map_err(regs)?;
    }
    sd.register_write(0x0400u16, snap.wd_divider)
        .await
        .map_err(regs)?;
    sd.register_write(0x0420u16, snap.wd_time)
        .await
        .map_err(regs)?;
    request(&sd, 0x04).await?;
    wait_state(&sd, 0x04).await?;
    if !await_mode(&sd, MODE_CSP, MODE_SAFEOP_WAIT).await {
        return Err("0x6061 does not show cyclic synchronous position in SAFE-OP".into());
    }
    request(&sd, 0x08).await?;
    // the cycle sees OP when it comes (the drive needs valid outputs first)
    crate::io::Until(now_ns() + Duration::from_millis(1).as_nanos() as u64).await;
    Ok(())
}
