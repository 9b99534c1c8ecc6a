//! The machine configuration: TOML in, typed config out, or *every* problem
//! at once, each naming the axis and the key.
//!
//! Parsing walks the TOML table by hand instead of deriving serde types: a
//! derive stops at the first wrong key, while a commissioning engineer fixing
//! a config wants the whole list in one go. Engine-level rules (the CIP codes)
//! come from [`motion_homing::validate`], so they are written only once.
//!
//! Keys and enum spellings are fixed by `interface.md`; the keys this project
//! adds are listed in the README's configuration table.

mod keys;
pub mod names;
mod problem;

use keys::Reader;
pub use problem::Problem;

use motion_homing::{validate, AxisConfig};
use motion_plant::PlantConfig;
use std::path::Path;

/// The built-in default machine (`deploy/demo.toml`).
pub const DEMO_TOML: &str = include_str!("../../../deploy/demo.toml");

/// Most axes one supervisor drives (the frame layout's fixed capacity).
pub const MAX_AXES: usize = 64;

/// Where the I/O process comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IoMode {
    /// The supervisor spawns `motion-io --backend sim`.
    Sim,
    /// An I/O process is started by someone else; the supervisor waits for it.
    External,
}

/// `[supervisor]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SupervisorConfig {
    pub cycle_us: u32,
    pub cpu: usize,
    pub priority: i32,
    pub io: IoMode,
    pub service_prefix: String,
    /// Missing-feedback cycles tolerated during homing (engine
    /// `feedback_timeout_ns` = the larger of its 10 ms default and this × the
    /// cycle).
    pub stale_cycles: u32,
    /// Missing-command cycles after which `motion-io` stops every axis.
    pub io_watchdog_cycles: u32,
    /// `mlockall` the process (default true).
    pub lock_memory: bool,
    /// SCHED_FIFO priority of a spawned `motion-io` (0: normal scheduling).
    /// Default: 10 below the cycle, still above the kernel's IRQ threads (50).
    pub io_priority: i32,
    /// CPU a spawned `motion-io` is pinned to; `None`: another CPU than the
    /// cycle's, if the machine has one.
    pub io_cpu: Option<usize>,
    /// Hold `/dev/cpu_dma_latency` at this many µs while running (default 0,
    /// as cyclictest does); negative: leave the idle states alone.
    pub cpu_dma_latency_us: i32,
}

impl SupervisorConfig {
    pub fn cycle_ns(&self) -> u64 {
        u64::from(self.cycle_us) * 1000
    }
}

/// One `[[axis]]`: its engine config and the simulated plant behind it.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisEntry {
    pub name: String,
    pub engine: AxisConfig,
    pub sim: PlantConfig,
}

#[derive(Clone, Debug, PartialEq)]
pub struct MachineConfig {
    pub supervisor: SupervisorConfig,
    pub axes: Vec<AxisEntry>,
}

impl MachineConfig {
    /// Index of the axis called `name`.
    pub fn axis_index(&self, name: &str) -> Option<usize> {
        self.axes.iter().position(|a| a.name == name)
    }
}

/// Parses and validates a machine configuration.
pub fn parse(text: &str) -> Result<MachineConfig, Vec<Problem>> {
    let table: toml::Table = match text.parse() {
        Ok(t) => t,
        Err(e) => return Err(vec![Problem::syntax(text, &e)]),
    };
    let mut problems = Vec::new();
    let mut top = Reader::new(&table, None, "", &mut problems);
    let sup_table = top.table("supervisor");
    let axis_tables = top.array_of_tables("axis");
    top.finish();

    let supervisor = parse_supervisor(sup_table.as_ref(), &mut problems);
    let mut axes = Vec::new();
    for (i, t) in axis_tables.iter().enumerate() {
        if let Some(a) = parse_axis(i, t, &supervisor, &mut problems) {
            axes.push(a);
        }
    }
    if axis_tables.is_empty() {
        problems.push(Problem::new(None, "axis", "no [[axis]] configured"));
    }
    if axes.len() > MAX_AXES {
        problems.push(Problem::new(
            None,
            "axis",
            format!("{} axes configured, at most {MAX_AXES}", axes.len()),
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
    if problems.is_empty() {
        Ok(MachineConfig { supervisor, axes })
    } else {
        Err(problems)
    }
}

/// Reads `path`, or the built-in default machine when `None`. Returns the
/// config and a label for messages ("deploy/demo.toml (built in)").
pub fn load(path: Option<&Path>) -> Result<(MachineConfig, String), Vec<Problem>> {
    match path {
        None => parse(DEMO_TOML).map(|c| (c, "deploy/demo.toml (built in)".to_string())),
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| {
                vec![Problem::new(
                    None,
                    "file",
                    format!("cannot read {}: {e}", p.display()),
                )]
            })?;
            parse(&text).map(|c| (c, p.display().to_string()))
        }
    }
}

fn parse_supervisor(t: Option<&toml::Table>, problems: &mut Vec<Problem>) -> SupervisorConfig {
    let empty = toml::Table::new();
    let mut r = Reader::new(t.unwrap_or(&empty), None, "supervisor.", problems);
    let cycle_us = r.u32("cycle_us", 1000);
    let cpu = r.u32("cpu", 1) as usize;
    let priority = r.u32("priority", 80) as i32;
    let io = match r.string("io", "sim").as_str() {
        "sim" => IoMode::Sim,
        "external" => IoMode::External,
        other => {
            r.problem(
                "io",
                format!("\"{other}\" is not one of \"sim\", \"external\""),
            );
            IoMode::Sim
        }
    };
    let service_prefix = r.string("service_prefix", "motion");
    let stale_cycles = r.u32("stale_cycles", 3);
    let io_watchdog_cycles = r.u32("io_watchdog_cycles", 50);
    let lock_memory = r.bool("lock_memory", true);
    let cpu_dma_latency_us = r.i32("cpu_dma_latency_us", 0);
    let io_priority = r.i32("io_priority", (priority - 10).max(1));
    let io_cpu = match r.i32("io_cpu", -1) {
        c if c >= 0 => Some(c as usize),
        _ => None,
    };
    if !(0..=99).contains(&io_priority) {
        r.problem(
            "io_priority",
            format!("{io_priority} is outside 0..=99 (0: normal scheduling)"),
        );
    }
    if !(20..=100_000).contains(&cycle_us) {
        r.problem("cycle_us", format!("{cycle_us} µs is outside 20..=100000"));
    }
    if !(1..=99).contains(&priority) {
        r.problem(
            "priority",
            format!("{priority} is outside SCHED_FIFO's 1..=99"),
        );
    }
    if service_prefix.is_empty()
        || service_prefix.len() > 64
        || !service_prefix
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        r.problem(
            "service_prefix",
            format!("\"{service_prefix}\" must be 1..=64 characters of [A-Za-z0-9_-]"),
        );
    }
    if io_watchdog_cycles == 0 {
        r.problem("io_watchdog_cycles", "must be at least 1".into());
    }
    r.finish();
    SupervisorConfig {
        cycle_us,
        cpu,
        priority,
        io,
        service_prefix,
        stale_cycles,
        io_watchdog_cycles,
        lock_memory,
        io_priority,
        io_cpu,
        cpu_dma_latency_us,
    }
}

fn parse_axis(
    index: usize,
    t: &toml::Table,
    sup: &SupervisorConfig,
    problems: &mut Vec<Problem>,
) -> Option<AxisEntry> {
    let name = match t.get("name").and_then(|v| v.as_str()) {
        Some(n) if !n.is_empty() && n.len() <= 32 && !n.contains(char::is_whitespace) => {
            n.to_string()
        }
        Some(n) => {
            problems.push(Problem::new(
                Some(&format!("#{}", index + 1)),
                "name",
                format!("\"{n}\" must be 1..=32 characters without spaces"),
            ));
            format!("#{}", index + 1)
        }
        None => {
            problems.push(Problem::new(
                Some(&format!("#{}", index + 1)),
                "name",
                "missing".to_string(),
            ));
            format!("#{}", index + 1)
        }
    };
    let before = problems.len();
    let mut r = Reader::new(t, Some(&name), "", problems);
    r.mark_used("name");
    let d = AxisConfig::default();
    use motion_homing::{
        AxisConfiguration as AC, ControlMode as CM, HomeDirection as HD, HomeMode as HM,
        HomeSequence as HS, TravelMode as TM,
    };
    let engine = AxisConfig {
        configuration: r.choice("configuration", names::CONFIGURATIONS, AC::Servo),
        control_mode: r.choice("control_mode", names::CONTROL_MODES, CM::Position),
        travel: r.choice("travel", names::TRAVEL_MODES, TM::Linear),
        unwind: r.f64("unwind", 0.0),
        counts_per_unit: r.f64("counts_per_unit", 1.0),
        marker: r.bool("marker", false),
        marker_latch: r.bool("marker_latch", true),
        registration: r.bool("registration", false),
        absolute: r.bool("absolute", false),
        travel_limits: r.pair("travel_limits"),
        home_mode: r.choice("home_mode", names::HOME_MODES, HM::Active),
        home_direction: r.choice(
            "home_direction",
            names::HOME_DIRECTIONS,
            HD::BidirectionalForward,
        ),
        home_sequence: r.choice("home_sequence", names::HOME_SEQUENCES, HS::Immediate),
        home_switch_normally_closed: r.bool("home_switch_normally_closed", false),
        home_position: r.f64("home_position", 0.0),
        home_offset: r.f64("home_offset", 0.0),
        home_speed: r.f64("home_speed", 0.0),
        home_return_speed: r.f64("home_return_speed", 0.0),
        home_acceleration: r.f64("home_acceleration", 0.0),
        home_deceleration: r.f64("home_deceleration", 0.0),
        home_torque_level: r.f64("home_torque_level", 0.0),
        home_torque_threshold: r.f64("home_torque_threshold", 0.0),
        home_torque_time: r.f64("home_torque_time", 0.0),
        home_timeout: r.f64("home_timeout", 0.0),
        home_creep_speed: r.f64("home_creep_speed", 0.0),
        search_limit: r.f64("search_limit", 0.0),
        torque_limit: r.f64("torque_limit", d.torque_limit),
        position_error_tolerance: r.f64("position_error_tolerance", 0.0),
        velocity_error_tolerance: r.f64("velocity_error_tolerance", 0.0),
        enable_timeout: r.f64("enable_timeout", d.enable_timeout),
        // The engine's rule is in time (default 10 ms at any rate); a larger
        // `stale_cycles` still makes it at least that many cycles tolerant.
        feedback_timeout_ns: d
            .feedback_timeout_ns
            .max(u64::from(sup.stale_cycles) * sup.cycle_ns()),
        feedback_loss_drain: d.feedback_loss_drain,
        max_position: r.f64("max_position", d.max_position),
        max_speed: d.max_speed,
        marker_min_distance: d.marker_min_distance,
        refuse_ambiguous_marker: d.refuse_ambiguous_marker,
    };
    let sim_table = r.table("sim");
    r.finish();
    let sim = parse_sim(&name, sim_table.as_ref(), &engine, problems);
    for e in validate(&engine) {
        problems.push(Problem::from_engine(&name, &e));
    }
    (problems.len() == before).then_some(AxisEntry { name, engine, sim })
}

fn parse_sim(
    axis: &str,
    t: Option<&toml::Table>,
    engine: &AxisConfig,
    problems: &mut Vec<Problem>,
) -> PlantConfig {
    let empty = toml::Table::new();
    let mut r = Reader::new(t.unwrap_or(&empty), Some(axis), "sim.", problems);
    let d = PlantConfig::default();
    let sim = PlantConfig {
        start: r.f64("start", d.start),
        switch: r.pair("switch"),
        // The sim wires the switch as the axis says.
        switch_normally_closed: engine.home_switch_normally_closed,
        marker_every: r.f64("marker_every", 0.0),
        marker_at: r.f64("marker_at", 0.0),
        hard_stop: r.pair("hard_stop"),
        overtravel: r.pair("overtravel"),
        external_speed: r.f64("external_speed", 0.0),
        push_gain: r.f64("push_gain", d.push_gain),
        inertia_gain: r.f64("inertia_gain", d.inertia_gain),
        friction: r.f64("friction", d.friction),
        enable_delay_cycles: r.u32("enable_delay_cycles", d.enable_delay_cycles),
        torque_spike: None,
    };
    if sim.marker_every < 0.0 {
        r.problem("marker_every", "must not be negative".into());
    }
    r.finish();
    sim
}

#[cfg(test)]
mod tests;
