//! Backend `ethercat`: CiA 402 drives on an EtherCAT bus, through
//! [`motion_ethercat::EthercatBackend`] (ethercrab on its own real-time bus
//! thread, cycling at the supervisor's cycle; see `crates/ethercat/README.md`).
//!
//! [`EthercatIo`] is the thin adapter to motion-io's [`Backend`] trait: the
//! eight methods are forwarded. The one thing it adds is the virtual axes of
//! the I/O process: they have no drive, so they are left out of the bus and
//! answered here (the engine never reads a virtual axis' feedback; the
//! command is echoed). With no virtual axis the frames go through as they
//! are; otherwise they are repacked into preallocated frames (no allocation
//! per cycle).

use std::cell::RefCell;
use std::time::Duration;

use motion_config::{
    EthercatDc, EthercatDrive, EthercatIo as IoKeys, IoBackend, IoConfig, MachineConfig,
};
use motion_ethercat::{
    AxisMapping, DcMode, EthercatBackend, EthercatConfig, StartupReport, SubDeviceSelector,
};
use motion_frames::{
    AxisCommand, AxisFeedback, CommandFrame, FeedbackFrame, CW_ENABLE, SW_ENABLED,
};

use crate::backend::{Backend, ExchangeError};

/// Why the backend could not start, and the exit code it calls for.
#[derive(Debug)]
pub struct StartError {
    /// 2: a configuration / command-line mistake; 1: the bus refused.
    pub code: i32,
    pub message: String,
}

/// Where the bus thread runs (motion-io's `--cpu` / `--priority`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Placement {
    pub cpu: Option<usize>,
    pub priority: Option<i32>,
}

/// Default SCHED_FIFO priority of the bus thread without `--priority`.
pub const DEFAULT_BUS_PRIORITY: i32 = 70;

/// The backend configuration for I/O process `io` of `machine` (whose axes
/// are only that I/O process's, in frame order): the drives of its axes,
/// and `frame index → bus index` (`None` for a virtual axis).
pub fn bus_config(
    machine: &MachineConfig,
    io: &IoConfig,
    interface: Option<&str>,
    at: Placement,
) -> Result<(EthercatConfig, Vec<Option<usize>>), StartError> {
    let mistake = |message: String| StartError { code: 2, message };
    let keys = io.ethercat.clone().unwrap_or_default();
    let interface = match interface {
        Some(i) => i.to_string(),
        None if !keys.interface.is_empty() => keys.interface.clone(),
        None => {
            return Err(mistake(format!(
                "I/O process {}: no EtherCAT interface: give --interface IF, or backend = \
                 \"ethercat\" and interface = \"IF\" in its [[io]] section",
                io.name
            )))
        }
    };
    let mut axes = Vec::new();
    let mut map = Vec::new();
    for a in &machine.axes {
        match &a.ethercat {
            Some(e) => {
                map.push(Some(axes.len()));
                axes.push(AxisMapping {
                    name: a.name.clone(),
                    subdevice: match &e.drive {
                        EthercatDrive::Position(p) => SubDeviceSelector::Position(*p),
                        EthercatDrive::Name(n) => SubDeviceSelector::Name(n.clone()),
                    },
                    counts_per_unit: a.engine.counts_per_unit,
                    index_pulse_bit: e.index_pulse_bit,
                });
            }
            None if a.engine.configuration == motion_homing::AxisConfiguration::Virtual => {
                map.push(None);
            }
            None => {
                let why = if io.backend == IoBackend::Ethercat {
                    String::new()
                } else {
                    format!(
                        " (its I/O process {} has backend = \"{}\" in the config: set backend = \
                         \"ethercat\" there and name each axis' drive)",
                        io.name,
                        io.backend.name()
                    )
                };
                return Err(mistake(format!(
                    "axis {}: ethercat_position: the axis names no drive (ethercat_position or \
                     ethercat_name){why}",
                    a.name
                )));
            }
        }
    }
    if axes.is_empty() {
        return Err(mistake(format!(
            "I/O process {}: no axis with a drive on the bus",
            io.name
        )));
    }
    let mut cfg = EthercatConfig::new(
        &interface,
        Duration::from_nanos(machine.supervisor.cycle_ns()),
        axes,
    );
    apply_keys(&mut cfg, &keys);
    cfg.cpu = at.cpu;
    cfg.priority = at.priority.unwrap_or(DEFAULT_BUS_PRIORITY);
    cfg.lock_memory = machine.supervisor.lock_memory;
    let problems = cfg.problems();
    if !problems.is_empty() {
        return Err(mistake(format!(
            "I/O process {}: {}",
            io.name,
            problems.join("; ")
        )));
    }
    Ok((cfg, map))
}

fn apply_keys(cfg: &mut EthercatConfig, k: &IoKeys) {
    cfg.dc = match k.dc {
        EthercatDc::Auto => DcMode::Auto,
        EthercatDc::On => DcMode::On,
        EthercatDc::Off => DcMode::Off,
    };
    cfg.sm_watchdog = Duration::from_millis(u64::from(k.sm_watchdog_ms));
    cfg.reply_timeout = k
        .reply_timeout_us
        .map(|us| Duration::from_micros(u64::from(us)));
    cfg.startup_timeout = Duration::from_secs(u64::from(k.startup_timeout_s));
    cfg.mode_in_pdo = k.mode_in_pdo;
    cfg.dc_static_sync_iterations = k.dc_static_sync_iterations;
}

/// The start-up report in lines for the log: one summary, one line per
/// SubDevice (name, position, the axis it drives, DC or free run), warnings.
pub fn report_lines(interface: &str, r: &StartupReport) -> Vec<String> {
    let dc = r
        .axes
        .iter()
        .filter(|(_, s)| *s == motion_ethercat::SyncMode::Dc)
        .count();
    let mut out = vec![format!(
        "EtherCAT on {interface}: {} SubDevice(s) in OP after {} ms; {} of {} axes on \
         distributed clocks (SYNC0), {} free run; bus thread: {}",
        r.subdevices.len(),
        r.duration.as_millis(),
        dc,
        r.axes.len(),
        r.axes.len() - dc,
        r.rt.lines().next().unwrap_or_default()
    )];
    for s in &r.subdevices {
        let sync = match (&s.axis, s.sync) {
            (Some(axis), Some(sync)) => format!("axis {axis}, {sync}"),
            _ => "no axis".to_string(),
        };
        out.push(format!(
            "  SubDevice {} {:?}: {sync} (DC {}capable)",
            s.position,
            s.name,
            if s.dc_capable { "" } else { "not " }
        ));
    }
    for w in &r.warnings {
        out.push(format!("  warning: {w}"));
    }
    out
}

/// Copies the bus feedback `bus` into `fb` in frame order (`map`: frame →
/// bus index); virtual axes echo their last command.
fn unpack(
    map: &[Option<usize>],
    last: &[AxisCommand],
    bus: &FeedbackFrame,
    fb: &mut FeedbackFrame,
) {
    for (i, m) in map.iter().enumerate() {
        fb.axes[i] = match m {
            Some(k) => bus.axes[*k],
            None => {
                let c = &last[i];
                AxisFeedback {
                    position: c.target_position,
                    velocity: c.target_velocity,
                    status_word: if c.control_word & CW_ENABLE != 0 {
                        SW_ENABLED
                    } else {
                        0
                    },
                    ..AxisFeedback::ZERO
                }
            }
        };
    }
    fb.header.axis_count = map.len() as u32;
}

/// motion-io's [`Backend`] over [`EthercatBackend`].
pub struct EthercatIo {
    inner: EthercatBackend,
    names: Vec<String>,
    /// Frame index → bus index; `None`: a virtual axis.
    map: Vec<Option<usize>>,
    /// Every axis on the bus, in frame order: frames pass through.
    direct: bool,
    bus_cmd: Box<CommandFrame>,
    bus_fb: RefCell<Box<FeedbackFrame>>,
    /// Last command of each frame axis (the virtual ones are echoed).
    last: Vec<AxisCommand>,
    interface: String,
}

impl EthercatIo {
    /// Starts the bus (blocking until every SubDevice is in OP or start-up
    /// failed; errors name the SubDevice and the object or state).
    pub fn start(
        cfg: EthercatConfig,
        map: Vec<Option<usize>>,
        names: Vec<String>,
    ) -> Result<EthercatIo, StartError> {
        let interface = cfg.interface.clone();
        let inner = EthercatBackend::new(cfg).map_err(|e| StartError {
            code: 1,
            message: format!("EtherCAT start-up on {interface} failed: {e}"),
        })?;
        let direct = map.iter().enumerate().all(|(i, m)| *m == Some(i));
        Ok(EthercatIo {
            inner,
            last: vec![AxisCommand::ZERO; names.len()],
            names,
            map,
            direct,
            bus_cmd: Box::new(CommandFrame::ZERO),
            bus_fb: RefCell::new(Box::new(FeedbackFrame::ZERO)),
            interface,
        })
    }

    pub fn report_lines(&self) -> Vec<String> {
        report_lines(&self.interface, self.inner.report())
    }

    /// Runs `f` on the bus feedback, then fills `fb` from it.
    fn via_bus<R>(
        &mut self,
        fb: &mut FeedbackFrame,
        f: impl FnOnce(&mut EthercatBackend, &mut FeedbackFrame) -> R,
    ) -> R {
        if self.direct {
            return f(&mut self.inner, fb);
        }
        let bus = self.bus_fb.get_mut();
        let r = f(&mut self.inner, bus);
        unpack(&self.map, &self.last, bus, fb);
        r
    }

    /// A summary of the bus counters and its round trip, for the log at exit.
    pub fn summary(&self) -> String {
        let st = self.inner.bus_status();
        format!(
            "EtherCAT on {}: {} bus cycles, {} lost frame(s), {} late, {} working-counter \
             error(s), {} overrun(s), {} recovery(ies), {} SubDevice(s) needing a restart; \
             bus round trip (frame out → inputs back): {}",
            self.interface,
            st.cycles,
            st.lost_frames,
            st.late_frames,
            st.wkc_errors,
            st.overruns,
            st.recoveries,
            st.needs_restart,
            st.roundtrip
        )
    }
}

impl Backend for EthercatIo {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn axis_count(&self) -> usize {
        self.names.len()
    }

    fn axis_names(&self) -> Vec<String> {
        self.names.clone()
    }

    fn apply(&mut self, cmd: &CommandFrame, fb: &mut FeedbackFrame) -> Result<(), ExchangeError> {
        let n = self.names.len();
        let r = if self.direct {
            self.inner.exchange(cmd, fb)
        } else {
            self.last.copy_from_slice(&cmd.axes[..n]);
            let mut bus_n = 0;
            for (i, m) in self.map.iter().enumerate() {
                if let Some(k) = m {
                    self.bus_cmd.axes[*k] = cmd.axes[i];
                    bus_n += 1;
                }
            }
            self.bus_cmd.header = cmd.header;
            self.bus_cmd.header.axis_count = bus_n as u32;
            let bus = self.bus_fb.get_mut();
            let r = self.inner.exchange(&self.bus_cmd, bus);
            unpack(&self.map, &self.last, bus, fb);
            r
        };
        r.map_err(|e| match e {
            motion_ethercat::ExchangeError::AxisCountMismatch { frame, ours } => {
                ExchangeError::AxisCountMismatch { frame, ours }
            }
        })
    }

    fn watchdog_stop(&mut self, dt_s: f64, fb: &mut FeedbackFrame) -> bool {
        // the virtual axes stop with their commands: nothing to do
        self.via_bus(fb, |b, f| b.watchdog_stop(dt_s, f))
    }

    fn status(&self, fb: &mut FeedbackFrame) {
        if self.direct {
            return self.inner.status(fb);
        }
        let mut bus = self.bus_fb.borrow_mut();
        self.inner.status(&mut bus);
        unpack(&self.map, &self.last, &bus, fb);
    }

    fn emergency_stop(&mut self, fb: &mut FeedbackFrame) {
        self.via_bus(fb, |b, f| b.emergency_stop(f));
    }

    fn shutdown(&mut self, dt_s: f64, fb: &mut FeedbackFrame) -> bool {
        // paced by the bus cycle, bounded (motion_ethercat::backend::MAX_SHUTDOWN)
        self.via_bus(fb, |b, f| b.shutdown(dt_s, f))
    }

    fn summary(&self) -> Option<String> {
        Some(EthercatIo::summary(self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn machine(text: &str) -> (MachineConfig, IoConfig) {
        let m = motion_config::parse(text).unwrap_or_else(|p| panic!("{p:#?}"));
        let io = m.ios[0].clone();
        (m.only_io(0), io)
    }

    const BUS: &str =
        "[supervisor]\ncycle_us = 500\n[[io]]\nname = \"bus0\"\nbackend = \"ethercat\"\n\
                       interface = \"eth7\"\ndc = \"on\"\nsm_watchdog_ms = 20\n\
                       reply_timeout_us = 300\n";

    #[test]
    fn config_keys_reach_the_backend() {
        let (m, io) = machine(&format!(
            "{BUS}[[axis]]\nname = \"X\"\ncounts_per_unit = 100.0\nethercat_position = 2\n\
             [[axis]]\nname = \"V\"\nconfiguration = \"virtual\"\n\
             [[axis]]\nname = \"Y\"\nethercat_name = \"DRV\"\nethercat_index_pulse_bit = 20\n"
        ));
        let at = Placement {
            cpu: Some(0),
            priority: Some(60),
        };
        let (cfg, map) = bus_config(&m, &io, None, at).unwrap();
        assert_eq!(cfg.interface, "eth7");
        assert_eq!(cfg.cycle, Duration::from_micros(500));
        assert_eq!(cfg.dc, DcMode::On);
        assert_eq!(cfg.sm_watchdog, Duration::from_millis(20));
        assert_eq!(cfg.reply_timeout, Some(Duration::from_micros(300)));
        assert_eq!((cfg.cpu, cfg.priority), (Some(0), 60));
        assert_eq!(map, [Some(0), None, Some(1)]);
        assert_eq!(cfg.axes[0].subdevice, SubDeviceSelector::Position(2));
        assert_eq!(cfg.axes[0].counts_per_unit, 100.0);
        assert_eq!(cfg.axes[1].subdevice, SubDeviceSelector::Name("DRV".into()));
        assert_eq!(cfg.axes[1].index_pulse_bit, Some(20));
        // --interface wins; the bus thread defaults to FIFO 70
        let (cfg, _) = bus_config(&m, &io, Some("veth0"), Placement::default()).unwrap();
        assert_eq!((cfg.interface.as_str(), cfg.priority), ("veth0", 70));
    }

    #[test]
    fn virtual_axes_echo_their_command_between_the_bus_axes() {
        let mut bus = FeedbackFrame::ZERO;
        bus.axes[0].position = 111;
        bus.axes[1].position = 222;
        let mut last = vec![AxisCommand::ZERO; 3];
        last[1].target_position = 5_000;
        last[1].target_velocity = 20.0;
        last[1].control_word = CW_ENABLE;
        let mut fb = FeedbackFrame::ZERO;
        unpack(&[Some(0), None, Some(1)], &last, &bus, &mut fb);
        assert_eq!(fb.header.axis_count, 3);
        assert_eq!(
            (
                fb.axes[0].position,
                fb.axes[1].position,
                fb.axes[2].position
            ),
            (111, 5_000, 222)
        );
        assert_eq!(
            (fb.axes[1].velocity, fb.axes[1].status_word),
            (20.0, SW_ENABLED)
        );
    }

    #[test]
    fn mistakes_are_named() {
        // --backend ethercat on an I/O process configured for the sim
        let (m, io) = machine("[[axis]]\nname = \"X\"\n");
        let e = bus_config(&m, &io, Some("eth0"), Placement::default()).unwrap_err();
        assert_eq!(e.code, 2);
        assert!(
            e.message
                .starts_with("axis X: ethercat_position: the axis names no drive")
                && e.message.contains("backend = \"sim\""),
            "{}",
            e.message
        );
        let e = bus_config(&m, &io, None, Placement::default()).unwrap_err();
        assert!(e.message.contains("no EtherCAT interface"), "{}", e.message);
        // only virtual axes: nothing on the bus
        let (m, io) = machine(&format!(
            "{BUS}[[axis]]\nname = \"V\"\nconfiguration = \"virtual\"\n"
        ));
        let e = bus_config(&m, &io, None, Placement::default()).unwrap_err();
        assert!(e.message.contains("no axis with a drive"), "{}", e.message);
    }
}
