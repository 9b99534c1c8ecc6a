//! `[[axis]]` and its `[axis.sim]`.

use crate::keys::Reader;
use crate::limit_switches;
use crate::limits::*;
use crate::{names, AxisEntry, IoConfig, Problem, SupervisorConfig};
use motion_homing::{validate, AxisConfig};
use motion_plant::PlantConfig;

pub(crate) fn parse(
    index: usize,
    t: &toml::Table,
    sup: &SupervisorConfig,
    ios: &[IoConfig],
    problems: &mut Vec<Problem>,
) -> Option<AxisEntry> {
    let name = axis_name(index, t, problems);
    let before = problems.len();
    let mut r = Reader::new(t, Some(&name), "", problems);
    r.mark_used("name");
    let io = io_of(&mut r, ios);
    let home_order = r
        .has("home_order")
        .then(|| r.u32_in("home_order", 0, 0, 1000));
    let drift_limit = r.f64_in("drift_limit", 0.0, 0.0, POSITION, "units");
    let mut engine = engine(&mut r, sup);
    crate::operations::keys(&mut r, &mut engine);
    let ethercat = crate::ethercat::parse::axis_keys(&mut r, &mut engine, ios.get(io));
    let sim_table = r.table("sim");
    r.finish();
    let sim = parse_sim(&name, sim_table.as_ref(), &engine, problems);
    if ios
        .get(io)
        .is_none_or(|i| i.backend == crate::IoBackend::Sim)
    {
        let cycle_s = f64::from(sup.cycle_us) * 1e-6;
        limit_switches::check_sim(&name, &engine, &sim, cycle_s, problems);
    }
    engine_problems(&name, &engine, problems, before);
    (problems.len() == before).then_some(AxisEntry {
        name,
        io,
        home_order,
        drift_limit,
        engine,
        sim,
        ethercat,
    })
}

/// The axis's name; a missing or bad one is a problem, and the axis is
/// called `#n` (its place in the file) in the problems that follow.
fn axis_name(index: usize, t: &toml::Table, problems: &mut Vec<Problem>) -> String {
    let fallback = format!("#{}", index + 1);
    match t.get("name").and_then(|v| v.as_str()) {
        Some(n) => match names::check_name(n) {
            Ok(()) => n.to_string(),
            Err(e) => {
                problems.push(Problem::new(Some(&fallback), "name", e));
                fallback
            }
        },
        None => {
            problems.push(Problem::new(Some(&fallback), "name", "missing"));
            fallback
        }
    }
}

/// The index of the axis's I/O process (`io`, which may be left out when
/// there is only one).
fn io_of(r: &mut Reader<'_>, ios: &[IoConfig]) -> usize {
    if !r.has("io") {
        if ios.len() > 1 {
            r.problem(
                "io",
                "missing: with several [[io]] sections every axis names its I/O process".into(),
            );
        }
        return 0;
    }
    let io_name = r.string("io", "");
    match ios.iter().position(|i| i.name == io_name) {
        Some(k) => k,
        None => {
            let known: Vec<&str> = ios.iter().map(|i| i.name.as_str()).collect();
            r.problem(
                "io",
                format!(
                    "no I/O process {} (configured: {})",
                    names::shown(&io_name),
                    known.join(", ")
                ),
            );
            0
        }
    }
}

/// `counts_per_unit` and `max_position`: positions travel as exact integer
/// counts, so the largest one must be one.
fn scaling(r: &mut Reader<'_>) -> (f64, f64) {
    let counts_per_unit = r.f64_in(
        "counts_per_unit",
        1.0,
        COUNTS_PER_UNIT.0,
        COUNTS_PER_UNIT.1,
        "counts/unit",
    );
    let default = AxisConfig::default().max_position;
    let max_position = r.f64_in("max_position", default, 1e-3, POSITION, "units");
    if max_position * counts_per_unit > MAX_COUNTS {
        r.problem(
            "max_position",
            format!(
                "max_position {} × counts_per_unit {} = {:e} counts exceeds {MAX_COUNTS:e} \
                 (positions travel as exact integer counts)",
                crate::keys::num(max_position),
                crate::keys::num(counts_per_unit),
                max_position * counts_per_unit
            ),
        );
    }
    (counts_per_unit, max_position)
}

/// The engine's configuration of the axis: its keys, each in its physical
/// range, and the feedback-loss rule and cycle of `[supervisor]`.
fn engine(r: &mut Reader<'_>, sup: &SupervisorConfig) -> AxisConfig {
    use motion_homing::{
        AxisConfiguration as AC, ControlMode as CM, HomeDirection as HD, HomeMode as HM,
        HomeSequence as HS, TravelMode as TM,
    };
    let d = AxisConfig::default();
    let (counts_per_unit, max_position) = scaling(r);
    let mut engine = AxisConfig {
        configuration: r.choice("configuration", AC::NAMES, AC::Servo),
        control_mode: r.choice("control_mode", CM::NAMES, CM::Position),
        travel: r.choice("travel", TM::NAMES, TM::Linear),
        unwind: r.f64_in("unwind", 0.0, 0.0, POSITION, "units"),
        counts_per_unit,
        marker: r.bool("marker", false),
        marker_latch: r.bool("marker_latch", true),
        registration: r.bool("registration", false),
        travel_limits: r.interval("travel_limits", POSITION),
        home_mode: r.choice("home_mode", HM::NAMES, HM::Active),
        home_direction: r.choice("home_direction", HD::NAMES, HD::BidirectionalForward),
        home_sequence: r.choice("home_sequence", HS::NAMES, HS::Immediate),
        home_switch_normally_closed: r.bool("home_switch_normally_closed", false),
        home_position: r.f64_in("home_position", 0.0, -POSITION, POSITION, "units"),
        home_offset: r.f64_in("home_offset", 0.0, -POSITION, POSITION, "units"),
        home_speed: r.f64_in("home_speed", 0.0, 0.0, SPEED, "units/s"),
        home_return_speed: r.f64_in("home_return_speed", 0.0, 0.0, SPEED, "units/s"),
        home_acceleration: r.f64_in("home_acceleration", 0.0, 0.0, ACCELERATION, "units/s²"),
        home_deceleration: r.f64_in("home_deceleration", 0.0, 0.0, ACCELERATION, "units/s²"),
        home_torque_level: r.f64_in("home_torque_level", 0.0, 0.0, TORQUE, "% rated"),
        home_torque_threshold: r.f64_in("home_torque_threshold", 0.0, 0.0, TORQUE, "% rated"),
        home_torque_time: r.f64_in("home_torque_time", 0.0, 0.0, SHORT_TIME_S, "s"),
        home_timeout: r.f64_in("home_timeout", 0.0, 0.0, TIMEOUT_S, "s"),
        home_creep_speed: r.f64_in("home_creep_speed", 0.0, 0.0, SPEED, "units/s"),
        search_limit: r.f64_in("search_limit", 0.0, 0.0, 2.0 * POSITION, "units"),
        torque_limit: r.f64_in("torque_limit", d.torque_limit, 0.0, TORQUE, "% rated"),
        position_error_tolerance: r.f64_in("position_error_tolerance", 0.0, 0.0, POSITION, "units"),
        velocity_error_tolerance: r.f64_in("velocity_error_tolerance", 0.0, 0.0, SPEED, "units/s"),
        enable_timeout: r.f64_in("enable_timeout", d.enable_timeout, 1e-3, SHORT_TIME_S, "s"),
        feedback_timeout_ns: sup.feedback_timeout_ns(),
        feedback_loss_drain: sup.feedback_loss_drain,
        cycle_ns: sup.cycle_ns(),
        max_position,
        absolute: r.bool("absolute", false),
        max_speed: r.f64_in("max_speed", 0.0, 0.0, SPEED, "units/s"),
        marker_min_distance: 0.0,
        refuse_ambiguous_marker: r.bool("refuse_ambiguous_marker", false),
        unhomed_speed: d.unhomed_speed,
        limit_switches: d.limit_switches,
        max_deceleration: d.max_deceleration,
        stream_acceleration: d.stream_acceleration,
        stream_timeout_ns: d.stream_timeout_ns,
        stream_unhomed: d.stream_unhomed,
        home_reverse_at_limit: r.bool("home_reverse_at_limit", false),
        // set by the EtherCAT keys (`drive_homing`)
        drive_homing: false,
    };
    // A switch edge sampled once per cycle is known to a cycle of travel at
    // return speed; a marker closer than two such cycles to it is ambiguous.
    // The default check uses exactly that distance.
    let cycle_ms = f64::from(sup.cycle_us) / 1000.0;
    engine.marker_min_distance = r.f64_in(
        "marker_min_distance",
        2.0 * engine.home_return_speed * cycle_ms / 1000.0,
        0.0,
        POSITION,
        "units",
    );
    engine
}

/// The engine's own rules (with their CIP codes) on top of the problems of
/// this axis found since `before`. Numbers the range checks already
/// reported are not reported again by the engine's (coarser) finiteness rule.
fn engine_problems(name: &str, engine: &AxisConfig, problems: &mut Vec<Problem>, before: usize) {
    for e in validate(engine) {
        let p = Problem::from_engine(name, &e);
        if !problems[before..]
            .iter()
            .any(|q| q.axis == p.axis && q.key == p.key)
        {
            problems.push(p);
        }
    }
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
        start: r.f64_in("start", d.start, -POSITION, POSITION, "units"),
        switch: r.interval("switch", POSITION),
        // The sim wires the switch as the axis says.
        switch_normally_closed: engine.home_switch_normally_closed,
        marker_every: r.f64_in("marker_every", 0.0, 0.0, POSITION, "units"),
        marker_at: r.f64_in("marker_at", 0.0, -POSITION, POSITION, "units"),
        hard_stop: r.interval("hard_stop", POSITION),
        overtravel: limit_switches::read(&mut r),
        limit_switches_normally_closed: r.bool("limit_switches_normally_closed", false),
        // The probe input is wired to the switch the axis homes on.
        registration_input: limit_switches::registration_input(engine),
        external_speed: r.f64_in("external_speed", 0.0, -SPEED, SPEED, "units/s"),
        push_gain: r.f64_in("push_gain", d.push_gain, 0.0, 1e6, "% per unit"),
        inertia_gain: r.f64_in("inertia_gain", d.inertia_gain, 0.0, 1e3, "% per unit/s²"),
        friction: r.f64_in("friction", d.friction, 0.0, TORQUE, "% rated"),
        enable_delay_cycles: r.u32_in("enable_delay_cycles", d.enable_delay_cycles, 0, 10_000),
        torque_spike: None,
    };
    r.finish();
    sim
}
