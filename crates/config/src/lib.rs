//! The machine configuration: TOML in, typed config out, or *every* problem
//! at once, each naming the axis and the key.
//!
//! Parsing walks the TOML table by hand instead of deriving serde types: a
//! derive stops at the first wrong key, while a commissioning engineer fixing
//! a config wants the whole list in one go. Engine-level rules (the CIP codes)
//! come from [`motion_homing::validate`], so they are written only once; the
//! physical ranges every number must lie in are one table ([`limits`]).
//!
//! Every key is declared once, in the key table ([`keytable`]): the parser
//! reads keys only through it, and `docs/configuration.md` and the man page
//! `motion-machine.toml(5)` are written from it.

pub mod args;
mod axis;
#[cfg(feature = "cli-fuzz")]
pub mod cli_fuzz;
pub mod ethercat;
pub mod file;
mod gantry;
mod io;
mod keys;
pub mod keytable;
mod limit_switches;
pub mod limits;
pub mod names;
pub mod opcua;
mod operations;
mod problem;
mod supervisor;

pub use ethercat::{AxisEthercat, EthercatBus, EthercatDc, EthercatDrive, EthercatIo};
pub use gantry::{GantryConfig, MAX_SIDES};
use keys::Reader;
pub use problem::Problem;

use motion_homing::AxisConfig;
use motion_plant::PlantConfig;
use std::path::{Path, PathBuf};

/// The built-in default machine (`deploy/demo.toml`).
pub const DEMO_TOML: &str = include_str!("../../../deploy/demo.toml");
/// The shipped gantry example (`deploy/gantry.toml`): home order, a racked
/// gantry, an absolute axis.
pub const GANTRY_TOML: &str = include_str!("../../../deploy/gantry.toml");

/// Most axes one supervisor drives (the frame layout's fixed capacity).
pub const MAX_AXES: usize = 64;
/// Most I/O processes one supervisor serves.
pub const MAX_IOS: usize = 16;

/// Name of the one I/O process of a config without `[[io]]` sections.
pub const DEFAULT_IO_NAME: &str = "io";

/// Who starts an I/O process.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IoMode {
    /// The supervisor spawns `motion-io --backend BACKEND --io NAME`
    /// (`spawn = "sim"`, also spelled `spawn = "supervisor"`).
    Sim,
    /// An I/O process is started by someone else (a systemd unit); the
    /// supervisor waits for it to attach.
    External,
}

// `[supervisor] io`; `[[io]] spawn` also reads "supervisor" for `Sim`.
motion_homing::spellings!(IoMode {
    Sim => "sim",
    External => "external",
});

/// `[[io]] spawn`: "sim" means "the supervisor starts it", whatever its
/// backend (the name the interface fixed); "supervisor" says so.
pub const SPAWN_NAMES: &[(&str, IoMode)] = &[
    ("sim", IoMode::Sim),
    ("supervisor", IoMode::Sim),
    ("external", IoMode::External),
];

/// The drive backend of an I/O process (`[[io]] backend`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IoBackend {
    /// One simulated plant per axis (`[axis.sim]`).
    #[default]
    Sim,
    /// CiA 402 drives on an EtherCAT bus (`motion-ethercat`).
    Ethercat,
}

// The config and command-line spelling (`motion-io --backend NAME`).
motion_homing::spellings!(IoBackend {
    Sim => "sim",
    Ethercat => "ethercat",
});

/// One drive-I/O process (`[[io]]`, or the implicit one named `io`).
#[derive(Clone, Debug, PartialEq)]
pub struct IoConfig {
    pub name: String,
    pub spawn: IoMode,
    /// CPU of a spawned one (`None`: another CPU than the cycle's).
    pub cpu: Option<usize>,
    /// SCHED_FIFO priority of a spawned one (0: normal scheduling).
    pub priority: i32,
    /// What drives its axes (default `sim`).
    pub backend: IoBackend,
    /// `Some` exactly when `backend` is `Ethercat`.
    pub ethercat: Option<EthercatIo>,
}

/// `[supervisor]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SupervisorConfig {
    pub cycle_us: u32,
    pub cpu: usize,
    pub priority: i32,
    /// `io = "sim" | "external"`: the implicit I/O process of a config
    /// without `[[io]]`.
    pub io: IoMode,
    pub service_prefix: String,
    /// Feedback-loss rule: the leaky bucket trips at this many ms of missing
    /// feedback (see the engine's docs).
    pub feedback_timeout_ms: f64,
    /// Share of the elapsed time a fresh cycle drains from the bucket.
    pub feedback_loss_drain: f64,
    /// Missing-command cycles after which `motion-io` stops every axis.
    pub io_watchdog_cycles: u32,
    /// `mlockall` the process (default true).
    pub lock_memory: bool,
    /// SCHED_FIFO priority of a spawned `motion-io` (0: normal scheduling).
    /// Default: 10 below the cycle, still above the kernel's IRQ threads (50).
    pub io_priority: i32,
    /// CPU a spawned `motion-io` is pinned to; `None`: the cycle's CPU (it
    /// answers while the cycle sleeps; see `motion_supervisor::session`).
    pub io_cpu: Option<usize>,
    /// Hold `/dev/cpu_dma_latency` at this many µs while running (default 0,
    /// as cyclictest does); negative: leave the idle states alone.
    pub cpu_dma_latency_us: i32,
    /// Where the supervisor publishes how to reach it (its session file) and
    /// keeps iceoryx2's files; `None`: the default (`/run/motion` for root).
    pub runtime_dir: Option<PathBuf>,
    /// Where the homing references of absolute axes and the homing record
    /// live (`/var/lib/motion` for root, else `$HOME/.local/state/motion`).
    pub state_dir: PathBuf,
}

impl SupervisorConfig {
    pub fn cycle_ns(&self) -> u64 {
        u64::from(self.cycle_us) * 1000
    }

    /// The feedback-loss time bound in ns.
    pub fn feedback_timeout_ns(&self) -> u64 {
        (self.feedback_timeout_ms * 1e6) as u64
    }
}

/// One `[[axis]]`: its engine config and the simulated plant behind it.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisEntry {
    pub name: String,
    /// Index into [`MachineConfig::ios`] of the I/O process driving it.
    pub io: usize,
    /// `home_order`: home-all homes order 0, then 1, ...; equal orders in
    /// parallel. `None`: config order, one at a time, when no axis has one;
    /// homed only when named when some have one.
    pub home_order: Option<u32>,
    /// Warn when a home event lands further than this (units) from the
    /// median of the axis's recent events (switch wear, coupling slip);
    /// 0 = off.
    pub drift_limit: f64,
    pub engine: AxisConfig,
    pub sim: PlantConfig,
    /// Its drive, on an EtherCAT I/O process (`None` elsewhere and for a
    /// virtual axis, which has no drive).
    pub ethercat: Option<AxisEthercat>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct MachineConfig {
    pub supervisor: SupervisorConfig,
    /// Every I/O process; at least one.
    pub ios: Vec<IoConfig>,
    pub axes: Vec<AxisEntry>,
    /// Axes homed as one machine axis.
    pub gantries: Vec<GantryConfig>,
    /// Things that are accepted but probably not meant (printed at start).
    pub warnings: Vec<String>,
}

impl MachineConfig {
    /// The gantry axis `i` is a side of, if any.
    pub fn gantry_of(&self, i: usize) -> Option<usize> {
        self.gantries.iter().position(|g| g.axes.contains(&i))
    }

    /// Index of the axis called `name`.
    pub fn axis_index(&self, name: &str) -> Option<usize> {
        self.axes.iter().position(|a| a.name == name)
    }

    /// Index of the I/O process called `name`.
    pub fn io_index(&self, name: &str) -> Option<usize> {
        self.ios.iter().position(|i| i.name == name)
    }

    /// Indices of the axes I/O process `io` drives, in config order: axis
    /// `k` of its frames is `axes_of(io)[k]`.
    pub fn axes_of(&self, io: usize) -> Vec<usize> {
        (0..self.axes.len())
            .filter(|&i| self.axes[i].io == io)
            .collect()
    }

    /// Only the axes of I/O process `io` (what `motion-io --io NAME` serves).
    pub fn only_io(&self, io: usize) -> MachineConfig {
        let mut m = self.clone();
        m.axes.retain(|a| a.io == io);
        m
    }
}

/// Parses and validates a machine configuration.
pub fn parse(text: &str) -> Result<MachineConfig, Vec<Problem>> {
    let table: toml::Table = match text.parse() {
        Ok(t) => t,
        Err(e) => return Err(vec![Problem::syntax(text, &e)]),
    };
    let mut problems = Vec::new();
    let mut warnings = Vec::new();
    let mut top = Reader::new(&table, None, keytable::Section::Top, &mut problems);
    let sup_table = top.table(&keytable::top::SUPERVISOR);
    let io_tables = top.array_of_tables(&keytable::top::IO);
    let axis_tables = top.array_of_tables(&keytable::top::AXIS);
    let gantry_tables = top.array_of_tables(&keytable::top::GANTRY);
    let opcua_table = top.table(&keytable::top::OPCUA);
    top.finish();

    let supervisor = supervisor::parse(sup_table.as_ref(), &mut problems, &mut warnings);
    let ios = io::parse(&io_tables, &supervisor, &mut problems, &mut warnings);
    let mut axes = Vec::new();
    for (i, t) in axis_tables.iter().enumerate() {
        if let Some(a) = axis::parse(i, t, &supervisor, &ios, &mut problems) {
            axes.push(a);
        }
    }
    if axis_tables.is_empty() {
        problems.push(Problem::new(None, "axis", "no [[axis]] configured"));
    }
    if axis_tables.len() > MAX_AXES {
        problems.push(Problem::new(
            None,
            "axis",
            format!("{} axes configured, at most {MAX_AXES}", axis_tables.len()),
        ));
    }
    for (i, a) in axes.iter().enumerate() {
        if axes[..i].iter().any(|b| b.name == a.name) {
            problems.push(Problem::new(
                Some(&a.name),
                "name",
                "axis name used twice".to_string(),
            ));
        }
    }
    ethercat::parse::checks(&ios, &axes, &mut problems);
    let gantries = gantry::parse(&gantry_tables, &axes, &mut problems);
    opcua::parse(
        opcua_table.as_ref(),
        &axes,
        &supervisor.state_dir,
        &mut problems,
    );
    for (k, io) in ios.iter().enumerate() {
        if !axes.iter().any(|a| a.io == k) && problems.is_empty() {
            warnings.push(format!("I/O process {} drives no axis", io.name));
        }
    }
    if problems.is_empty() {
        Ok(MachineConfig {
            supervisor,
            ios,
            axes,
            gantries,
            warnings,
        })
    } else {
        Err(problems)
    }
}

/// Reads `path`, or the built-in default machine when `None`. Returns the
/// config and a label for messages ("deploy/demo.toml (built in)"). Only a
/// regular file of at most [`file::MAX_CONFIG_BYTES`] is read.
pub fn load(path: Option<&Path>) -> Result<(MachineConfig, String), Vec<Problem>> {
    match path {
        None => parse(DEMO_TOML).map(|c| (c, "deploy/demo.toml (built in)".to_string())),
        Some(p) => {
            let text =
                file::read_config_file(p).map_err(|e| vec![Problem::new(None, "file", e)])?;
            parse(&text).map(|c| (c, p.display().to_string()))
        }
    }
}

/// CPUs this machine has online (`/sys/devices/system/cpu/online`, e.g.
/// `0-3,6`); `None` if unknown.
pub fn online_cpus() -> Option<Vec<usize>> {
    let text = std::fs::read_to_string("/sys/devices/system/cpu/online").ok()?;
    let mut cpus = Vec::new();
    for part in text.trim().split(',').filter(|p| !p.is_empty()) {
        match part.split_once('-') {
            Some((a, b)) => cpus.extend(a.parse::<usize>().ok()?..=b.parse::<usize>().ok()?),
            None => cpus.push(part.parse().ok()?),
        }
    }
    Some(cpus)
}

/// Checks that `cpu` exists on this machine; the message names the CPUs that do.
pub(crate) fn check_cpu(cpu: i64) -> Result<(), String> {
    match online_cpus() {
        Some(cpus) if cpu >= 0 && cpus.contains(&(cpu as usize)) => Ok(()),
        Some(cpus) => Err(format!(
            "CPU {cpu} does not exist here (online: {})",
            cpus.iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(",")
        )),
        None if (0..1024).contains(&cpu) => Ok(()),
        None => Err(format!("CPU {cpu} is outside 0..1024")),
    }
}

#[cfg(test)]
mod tests;
