//! The EtherCAT half of the jitter bench (`jitter --ethercat`): the demo
//! machine's axes on `motion-io --backend ethercat`, over a veth pair to
//! `ecat-emu`'s emulated CiA 402 drives (one per axis, each over the plant
//! of the axis' `[axis.sim]`). Root only (raw sockets, `ip netns`).
//!
//! The emulator plays the hardware: its thread is pinned to the I/O CPU
//! (where `motion-io` and its bus thread run, not the cycle's CPU) at a
//! SCHED_FIFO priority the caller chooses (the jitter bench: below
//! motion-io, whose answers the supervisor's round trip measures).

use ecat_emu::{DriveConfig, Emulator, EmulatorConfig, VethPair};
use motion_config::MachineConfig;

/// Pair and emulator; both go away on drop (emulator first).
pub struct EcatRig {
    emu: Option<Emulator>,
    pair: VethPair,
    pub drives: usize,
}

impl EcatRig {
    /// Sets up the veth pair and starts one emulated drive per axis of
    /// `machine` (config order = bus position), its thread pinned to `cpu`
    /// at SCHED_FIFO `priority`.
    pub fn start(machine: &MachineConfig, cpu: usize, priority: i32) -> Result<EcatRig, String> {
        let pair = VethPair::new().map_err(|s| s.to_string())?;
        let drives: Vec<DriveConfig> = machine
            .axes
            .iter()
            .enumerate()
            .map(|(k, a)| {
                let mut d = DriveConfig::new(&format!("EMU-{}", a.name));
                d.counts_per_unit = a.engine.counts_per_unit;
                d.plant = a.sim;
                d.serial = k as u32 + 1;
                d.cycle_ns = machine.supervisor.cycle_us * 1000;
                d
            })
            .collect();
        let n = drives.len();
        let cfg = EmulatorConfig {
            interface: pair.subdevice.clone(),
            netns: Some(pair.netns.clone()),
            drives,
            priority: Some(priority),
        };
        // the emulator's thread inherits the affinity of the thread that
        // starts it
        let emu = std::thread::spawn(move || {
            crate::host::enter_rt(Some(cpu), None);
            Emulator::start(cfg)
        })
        .join()
        .map_err(|_| "the emulator's start-up thread panicked".to_string())?
        .map_err(|e| format!("emulator: {e}"))?;
        Ok(EcatRig {
            emu: Some(emu),
            pair,
            drives: n,
        })
    }

    /// The master's end of the pair (root namespace): `motion-io --interface`.
    pub fn interface(&self) -> &str {
        &self.pair.master
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

/// `toml` (a machine without `[[io]]`) with its axes on an EtherCAT I/O
/// process on `interface`: `[[io]] bus0`, spawned by the supervisor,
/// `backend = "ethercat"`, axis k on the drive at bus position k.
pub fn on_ethercat(toml: &str, interface: &str) -> Result<(String, MachineConfig), String> {
    let first = toml.find("[[axis]]").ok_or("the machine has no [[axis]]")?;
    let mut text = format!(
        "{}[[io]]\nname = \"bus0\"\nspawn = \"supervisor\"\nbackend = \"ethercat\"\n\
         interface = \"{interface}\"\n\n",
        &toml[..first]
    );
    for (k, block) in toml[first..].split("[[axis]]\n").skip(1).enumerate() {
        text += &format!("[[axis]]\nethercat_position = {k}\n{block}");
    }
    match motion_config::parse(&text) {
        Ok(m) => Ok((text, m)),
        Err(problems) => Err(problems
            .iter()
            .map(|p| p.to_string())
            .collect::<Vec<_>>()
            .join("; ")),
    }
}

/// motion-io's bus round trip of one run, from the summary it logs at exit
/// (`… bus round trip (frame out → inputs back): N cycles: min a / p50 b /
/// p99 c / p99.9 d / max e us`), and its lost frames.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BusRun {
    pub cycles: u64,
    pub min: f64,
    pub p50: f64,
    pub p99: f64,
    pub p999: f64,
    pub max: f64,
    pub lost: u64,
}

/// Finds the bus summary in `stderr`.
pub fn bus_run(stderr: &str) -> Option<BusRun> {
    let line = stderr
        .lines()
        .rev()
        .find(|l| l.contains("bus round trip (frame out"))?;
    let rt = &line[line.find("inputs back):")?..];
    let after = |key: &str| -> Option<f64> {
        let at = rt.find(key)? + key.len();
        rt[at..].trim_start().split([' ', ',']).next()?.parse().ok()
    };
    let cycles = rt
        .trim_start_matches("inputs back):")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let lost = line
        .split(", ")
        .find(|p| p.ends_with("lost frame(s)"))
        .and_then(|p| p.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    Some(BusRun {
        cycles,
        min: after("min ")?,
        p50: after("p50 ")?,
        p99: after("p99 ")?,
        p999: after("p99.9 ")?,
        max: after("max ")?,
        lost,
    })
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

    #[test]
    fn reads_the_bus_summary() {
        let s = "motion-supervisor: x\nmotion-io: EtherCAT on ecm1: 5000 bus cycles, 3 lost \
                 frame(s), 3 late, 0 working-counter error(s), 1 overrun(s), 0 recovery(ies), \
                 0 SubDevice(s) needing a restart; bus round trip (frame out → inputs back): \
                 4997 cycles: min 40.1 / p50 55.5 / p99 90.5 / p99.9 150.5 / max 900.2 us\n";
        let b = bus_run(s).unwrap();
        assert_eq!(
            b,
            BusRun {
                cycles: 4997,
                min: 40.1,
                p50: 55.5,
                p99: 90.5,
                p999: 150.5,
                max: 900.2,
                lost: 3
            }
        );
        assert_eq!(bus_run("nothing"), None);
    }
}
