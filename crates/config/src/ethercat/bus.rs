//! [`EthercatBus`]: what the EtherCAT bus of one I/O process runs with, as
//! `motion-ethercat` takes it — the I/O process's keys (with
//! `motion-io --interface` in force), the cycle, its axes that have a drive,
//! and where the bus thread runs.

use std::time::Duration;

use motion_homing::AxisConfiguration;

use super::{AxisEthercat, AxisNeeds, EthercatIo};
use crate::{IoBackend, MachineConfig};

/// SCHED_FIFO priority of the bus thread without `motion-io --priority`.
pub const DEFAULT_BUS_PRIORITY: i32 = 70;
/// [`EthercatBus::new`]'s `watchdog_cycles`: `io_watchdog_cycles`'s default
/// at a 1 ms cycle.
pub const DEFAULT_WATCHDOG_CYCLES: u32 = 50;
/// [`EthercatBus::new`]'s `feedback_timeout_ms`: the supervisor's default.
pub const DEFAULT_FEEDBACK_TIMEOUT_MS: f64 = 10.0;

/// One axis on the bus, in the bus's order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BusAxis {
    /// The axis name (messages).
    pub name: String,
    pub ethercat: AxisEthercat,
    /// What its configuration needs of the drive (checked at start-up).
    pub needs: AxisNeeds,
}

impl BusAxis {
    /// Axis `name` on the drive at bus position `position`, needing nothing
    /// but the cyclic position objects (tests, tools).
    pub fn at(name: &str, position: u16) -> BusAxis {
        BusAxis {
            name: name.to_string(),
            ethercat: AxisEthercat {
                drive: super::EthercatDrive::Position(position),
                index_pulse_bit: None,
                home_switch_bit: None,
                brake_delay_ms: 0,
                drive_homing_method: None,
            },
            needs: AxisNeeds::default(),
        }
    }
}

/// Everything the EtherCAT backend needs. Built from a parsed (so checked)
/// [`MachineConfig`] by [`EthercatBus::for_io`]; the backend does not check
/// it again.
///
/// Positions, velocities and latches pass through in counts: the drive's
/// counts are taken to be the frames' counts, so the bus needs no
/// conversion constant.
#[derive(Clone, Debug, PartialEq)]
pub struct EthercatBus {
    /// The `[[io]]` keys; `interface` is the one in force.
    pub keys: EthercatIo,
    /// The bus cycle = the supervisor's `cycle_us`.
    pub cycle_us: u32,
    /// The axes with a drive, in frame order (virtual axes left out).
    pub axes: Vec<BusAxis>,
    /// CPU to pin the bus thread to.
    pub cpu: Option<usize>,
    /// SCHED_FIFO priority of the bus thread.
    pub priority: i32,
    /// Lock memory (`mlockall`) from the bus thread.
    pub lock_memory: bool,
    /// `io_watchdog_cycles` of the supervisor: motion-io's watchdog. The
    /// bus thread has its own, of twice as many cycles (see
    /// `motion_ethercat::cycle`).
    pub watchdog_cycles: u32,
    /// `feedback_timeout_ms` of the supervisor: how long its engines go on
    /// through missing feedback before they abort the motion. A drive
    /// whose data was lost longer is not sent after a command that ran on
    /// (see `motion_ethercat::axis`).
    pub feedback_timeout_ms: f64,
}

impl EthercatBus {
    /// A bus on `interface` with the default keys, FIFO
    /// [`DEFAULT_BUS_PRIORITY`], memory locked, any CPU.
    pub fn new(interface: &str, cycle_us: u32, axes: Vec<BusAxis>) -> EthercatBus {
        EthercatBus {
            keys: EthercatIo {
                interface: interface.to_string(),
                ..EthercatIo::default()
            },
            cycle_us,
            axes,
            cpu: None,
            priority: DEFAULT_BUS_PRIORITY,
            lock_memory: true,
            watchdog_cycles: DEFAULT_WATCHDOG_CYCLES,
            feedback_timeout_ms: DEFAULT_FEEDBACK_TIMEOUT_MS,
        }
    }

    /// The bus of I/O process `io` of `machine`, and its frame's axes on it
    /// (`frame index → bus index`; `None` for a virtual axis, which has no
    /// drive). `interface`: `motion-io --interface`, in force over the key;
    /// `cpu` / `priority`: motion-io's `--cpu` / `--priority`, which the bus
    /// thread takes. The error is the message for the operator.
    pub fn for_io(
        machine: &MachineConfig,
        io: usize,
        interface: Option<&str>,
        cpu: Option<usize>,
        priority: Option<i32>,
    ) -> Result<(EthercatBus, Vec<Option<usize>>), String> {
        let cfg = &machine.ios[io];
        let mut keys = cfg.ethercat.clone().unwrap_or_default();
        match interface {
            Some(i) => keys.interface = i.to_string(),
            None if !keys.interface.is_empty() => {}
            None => {
                return Err(format!(
                    "I/O process {}: no EtherCAT interface: give --interface IF, or backend = \
                     \"ethercat\" and interface = \"IF\" in its [[io]] section",
                    cfg.name
                ))
            }
        }
        let mut axes = Vec::new();
        let mut map = Vec::new();
        for a in machine.axes.iter().filter(|a| a.io == io) {
            match &a.ethercat {
                Some(e) => {
                    map.push(Some(axes.len()));
                    axes.push(BusAxis {
                        name: a.name.clone(),
                        ethercat: e.clone(),
                        needs: AxisNeeds::of(&a.engine, e),
                    });
                }
                None if a.engine.configuration == AxisConfiguration::Virtual => map.push(None),
                None => {
                    let why = if cfg.backend == IoBackend::Ethercat {
                        String::new()
                    } else {
                        format!(
                            " (its I/O process {} has backend = \"{}\" in the config: set \
                             backend = \"ethercat\" there and name each axis' drive)",
                            cfg.name,
                            cfg.backend.name()
                        )
                    };
                    return Err(format!(
                        "axis {}: ethercat_position: the axis names no drive (ethercat_position \
                         or ethercat_name){why}",
                        a.name
                    ));
                }
            }
        }
        if axes.is_empty() {
            return Err(format!(
                "I/O process {}: no axis with a drive on the bus",
                cfg.name
            ));
        }
        let bus = EthercatBus {
            keys,
            cycle_us: machine.supervisor.cycle_us,
            axes,
            cpu,
            priority: priority.unwrap_or(DEFAULT_BUS_PRIORITY),
            lock_memory: machine.supervisor.lock_memory,
            watchdog_cycles: machine.supervisor.io_watchdog_cycles,
            feedback_timeout_ms: machine.supervisor.feedback_timeout_ms,
        };
        Ok((bus, map))
    }

    /// The bus cycle.
    pub fn cycle(&self) -> Duration {
        Duration::from_micros(u64::from(self.cycle_us))
    }

    /// An answer later than this counts as a lost frame (default: 90 % of
    /// the cycle).
    pub fn reply_timeout(&self) -> Duration {
        match self.keys.reply_timeout_us {
            Some(us) => Duration::from_micros(u64::from(us)),
            None => self.cycle() * 9 / 10,
        }
    }

    /// SyncManager watchdog of the drives (0x0400 / 0x0420).
    pub fn sm_watchdog(&self) -> Duration {
        Duration::from_millis(u64::from(self.keys.sm_watchdog_ms))
    }

    /// INIT → OP limit.
    pub fn startup_timeout(&self) -> Duration {
        Duration::from_secs(u64::from(self.keys.startup_timeout_s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EthercatDc, EthercatDrive};

    fn machine(text: &str) -> MachineConfig {
        crate::parse(text).unwrap_or_else(|p| panic!("{p:#?}"))
    }

    const BUS: &str = "[supervisor]\ncycle_us = 500\n[[io]]\nname = \"bus0\"\n\
                       backend = \"ethercat\"\ninterface = \"eth7\"\ndc = \"on\"\n\
                       sm_watchdog_ms = 20\nreply_timeout_us = 300\n";

    #[test]
    fn config_keys_reach_the_bus() {
        let m = machine(&format!(
            "{BUS}[[axis]]\nname = \"X\"\ncounts_per_unit = 100.0\nethercat_position = 2\n\
             [[axis]]\nname = \"V\"\nconfiguration = \"virtual\"\n\
             [[axis]]\nname = \"Y\"\nethercat_name = \"DRV\"\nethercat_index_pulse_bit = 20\n"
        ));
        let (bus, map) = EthercatBus::for_io(&m, 0, None, Some(0), Some(60)).unwrap();
        assert_eq!(bus.keys.interface, "eth7");
        assert_eq!(bus.cycle(), Duration::from_micros(500));
        assert_eq!(bus.keys.dc, EthercatDc::On);
        assert_eq!(bus.sm_watchdog(), Duration::from_millis(20));
        assert_eq!(bus.reply_timeout(), Duration::from_micros(300));
        assert_eq!((bus.cpu, bus.priority), (Some(0), 60));
        assert_eq!(map, [Some(0), None, Some(1)]);
        assert_eq!(bus.axes[0].name, "X");
        assert_eq!(bus.axes[0].ethercat.drive, EthercatDrive::Position(2));
        assert_eq!(
            bus.axes[1].ethercat.drive,
            EthercatDrive::Name("DRV".into())
        );
        assert_eq!(bus.axes[1].ethercat.index_pulse_bit, Some(20));
        // --interface wins; the bus thread defaults to FIFO 70; the reply
        // deadline to 90 % of the cycle
        let (mut bus, _) = EthercatBus::for_io(&m, 0, Some("veth0"), None, None).unwrap();
        assert_eq!((bus.keys.interface.as_str(), bus.priority), ("veth0", 70));
        bus.keys.reply_timeout_us = None;
        assert_eq!(bus.reply_timeout(), Duration::from_micros(450));
    }

    #[test]
    fn mistakes_are_named() {
        // --backend ethercat on an I/O process configured for the sim
        let m = machine("[[axis]]\nname = \"X\"\n");
        let e = EthercatBus::for_io(&m, 0, Some("eth0"), None, None).unwrap_err();
        assert!(
            e.starts_with("axis X: ethercat_position: the axis names no drive")
                && e.contains("backend = \"sim\""),
            "{e}"
        );
        let e = EthercatBus::for_io(&m, 0, None, None, None).unwrap_err();
        assert!(e.contains("no EtherCAT interface"), "{e}");
        // only virtual axes: nothing on the bus
        let m = machine(&format!(
            "{BUS}[[axis]]\nname = \"V\"\nconfiguration = \"virtual\"\n"
        ));
        let e = EthercatBus::for_io(&m, 0, None, None, None).unwrap_err();
        assert!(e.contains("no axis with a drive"), "{e}");
    }
}
