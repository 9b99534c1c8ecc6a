//! The EtherCAT veth rig: a veth pair whose one end sits in a network
//! namespace of its own with `ecat-emu`'s emulated CiA 402 drives on it
//! (one per axis, each over the plant of the axis' `[axis.sim]`), the
//! other end in the root namespace for `motion-io --backend ethercat`.
//! Root only (raw sockets, `ip netns`): without, [`EcatRig::new`] says why
//! and the caller skips (a test prints `SKIPPED: …` and passes).
//!
//! Used by the EtherCAT end-to-end tests and by `jitter --ethercat`, where
//! the emulator plays the hardware: its thread is pinned to the I/O CPU
//! (where `motion-io` and its bus thread run, not the cycle's CPU) at a
//! SCHED_FIFO priority the caller chooses (the jitter bench: below
//! motion-io, whose answers the supervisor's round trip measures).

use ecat_emu::{DriveConfig, Emulator, EmulatorConfig, SubDeviceView, VethPair};
use motion_config::{AxisEntry, EthercatDrive, MachineConfig};

use crate::machines::{checked, Machine, TempConfig};

/// The pair and, once started, the emulator; both go away on drop
/// (emulator first: it leaves the namespace before it is deleted).
pub struct EcatRig {
    emu: Option<Emulator>,
    pair: VethPair,
    pub drives: usize,
}

impl EcatRig {
    /// The veth pair (unique names), no drives yet; `Err`: why there can be
    /// none here (`SKIPPED: needs root and ip netns (…)`).
    pub fn new() -> Result<EcatRig, String> {
        let pair = VethPair::new().map_err(|s| s.to_string())?;
        Ok(EcatRig {
            emu: None,
            pair,
            drives: 0,
        })
    }

    /// The pair with one emulated drive per axis of `machine` (config order
    /// = bus position), the emulator's thread pinned to `cpu` at SCHED_FIFO
    /// `priority`.
    pub fn start(machine: &MachineConfig, cpu: usize, priority: i32) -> Result<EcatRig, String> {
        let mut rig = EcatRig::new()?;
        let cycle_us = machine.supervisor.cycle_us;
        let drives = (machine.axes.iter().enumerate())
            .map(|(k, a)| emulated_drive(a, k as u16, cycle_us))
            .collect();
        rig.start_drives(drives, Some(cpu), priority)?;
        Ok(rig)
    }

    /// Starts the emulator with `drives` (bus positions in order), its
    /// thread pinned to `cpu` if given, at SCHED_FIFO `priority`.
    pub fn start_drives(
        &mut self,
        drives: Vec<DriveConfig>,
        cpu: Option<usize>,
        priority: i32,
    ) -> Result<(), String> {
        let n = drives.len();
        let cfg = EmulatorConfig {
            interface: self.pair.subdevice.clone(),
            netns: Some(self.pair.netns.clone()),
            drives,
            priority: Some(priority),
        };
        // the emulator's thread inherits the affinity of the thread that
        // starts it
        let emu = std::thread::spawn(move || {
            if let Some(cpu) = cpu {
                crate::placement::enter(Some(cpu), None);
            }
            Emulator::start(cfg)
        })
        .join()
        .map_err(|_| "the emulator's start-up thread panicked".to_string())?
        .map_err(|e| format!("emulator: {e}"))?;
        self.emu = Some(emu);
        self.drives = n;
        Ok(())
    }

    /// The master's end of the pair (root namespace): `motion-io --interface`.
    pub fn interface(&self) -> &str {
        &self.pair.master
    }

    /// The running emulator (panics before [`start_drives`](Self::start_drives)).
    pub fn emulator(&self) -> &Emulator {
        self.emu.as_ref().expect("the emulator was started")
    }

    /// The SubDevice at bus `position`.
    pub fn drive(&self, position: usize) -> SubDeviceView {
        self.emulator().view(position).expect("SubDevice")
    }

    /// Process-data cycles the emulated drives have run (all drives).
    pub fn drive_cycles(&self) -> u64 {
        let Some(emu) = &self.emu else { return 0 };
        (0..self.drives)
            .filter_map(|k| emu.view(k))
            .map(|v| v.drive.cycles)
            .sum()
    }
}

impl Drop for EcatRig {
    fn drop(&mut self) {
        // the emulator leaves the namespace before it is deleted
        drop(self.emu.take());
    }
}

/// The emulated drive of axis `a` at bus `position`: `EMU-<name>`, the
/// axis' counts per unit and plant, serial number position + 1.
pub fn emulated_drive(a: &AxisEntry, position: u16, cycle_us: u32) -> DriveConfig {
    let mut d = DriveConfig::new(&format!("EMU-{}", a.name));
    d.counts_per_unit = a.engine.counts_per_unit;
    d.plant = a.sim;
    d.serial = u32::from(position) + 1;
    d.cycle_ns = cycle_us * 1000;
    d
}

/// One emulated drive per axis of `machine` that is on the bus (by its
/// `ethercat_position`), in bus order.
pub fn drives_on_the_bus(machine: &MachineConfig) -> Vec<DriveConfig> {
    let mut drives: Vec<(u16, DriveConfig)> = (machine.axes.iter())
        .filter_map(|a| match a.ethercat.as_ref()?.drive {
            EthercatDrive::Position(p) => {
                Some((p, emulated_drive(a, p, machine.supervisor.cycle_us)))
            }
            _ => None,
        })
        .collect();
    drives.sort_by_key(|(p, _)| *p);
    drives.into_iter().map(|(_, d)| d).collect()
}

/// `toml` (a machine without `[[io]]`) with its axes on an EtherCAT I/O
/// process on `interface`: `[[io]] bus0`, spawned by the supervisor,
/// `backend = "ethercat"`, the k-th axis with hardware (not virtual) on the
/// drive at bus position k.
pub fn on_ethercat(toml: &str, interface: &str) -> Result<(String, MachineConfig), String> {
    let first = toml.find("[[axis]]").ok_or("the machine has no [[axis]]")?;
    let mut text = format!(
        "{}[[io]]\nname = \"bus0\"\nspawn = \"supervisor\"\nbackend = \"ethercat\"\n\
         interface = \"{interface}\"\n\n",
        &toml[..first]
    );
    let mut k = 0;
    for block in toml[first..].split("[[axis]]\n").skip(1) {
        if block.contains("configuration = \"virtual\"") {
            text += &format!("[[axis]]\n{block}");
        } else {
            text += &format!("[[axis]]\nethercat_position = {k}\n{block}");
            k += 1;
        }
    }
    checked(text)
}

/// A test's bus: the rig with its drives running, and the config that puts
/// the machine's axes on it.
pub struct Bus {
    pub rig: EcatRig,
    pub cfg: TempConfig,
}

impl Bus {
    /// `machine` on a new rig, one drive per axis with hardware (built from
    /// its `[axis.sim]`, then changed by `tweak`), the emulator at SCHED_FIFO
    /// 60. `None` (the reason printed) where there can be no rig.
    pub fn start(
        tag: &str,
        machine: &Machine,
        tweak: impl FnOnce(&mut [DriveConfig]),
    ) -> Option<Bus> {
        let mut rig = match EcatRig::new() {
            Ok(r) => r,
            Err(skip) => {
                eprintln!("{skip}");
                return None;
            }
        };
        let mut parsed = None;
        let cfg = machine.write_mapped(tag, |text| {
            let (text, m) = on_ethercat(&text, rig.interface()).unwrap_or_else(|e| panic!("{e}"));
            parsed = Some(m);
            text
        });
        let mut drives = drives_on_the_bus(&parsed.expect("parsed"));
        tweak(&mut drives);
        rig.start_drives(drives, None, 60).expect("emulator");
        Some(Bus { rig, cfg })
    }

    /// The SubDevice at bus `position`.
    pub fn drive(&self, position: usize) -> SubDeviceView {
        self.rig.drive(position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_on_ethercat() {
        let (text, m) = on_ethercat(motion_config::DEMO_TOML, "veth7").unwrap();
        assert_eq!(m.ios.len(), 1);
        assert_eq!(m.ios[0].backend, motion_config::IoBackend::Ethercat);
        for (k, a) in m.axes.iter().enumerate() {
            assert_eq!(
                a.ethercat.as_ref().unwrap().drive,
                motion_config::EthercatDrive::Position(k as u16),
                "{text}"
            );
        }
        let demo = motion_config::parse(motion_config::DEMO_TOML).unwrap();
        assert_eq!(m.axes.len(), demo.axes.len());
        assert_eq!(m.axes[1].sim, demo.axes[1].sim);
    }
}
