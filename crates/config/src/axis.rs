//! `[[axis]]` and its `[axis.sim]`.

use crate::keys::Reader;
use crate::keytable::{axis::*, sim, Section};
use crate::limit_switches;
use crate::limits::MAX_COUNTS;
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
    let mut r = Reader::new(t, Some(&name), Section::Axis, problems);
    r.mark_used(&NAME);
    let io = io_of(&mut r, ios);
    let home_order = r.has(&HOME_ORDER).then(|| r.u32_in(&HOME_ORDER));
    let drift_limit = r.f64_in(&DRIFT_LIMIT);
    let mut engine = engine(&mut r, sup);
    crate::operations::keys(&mut r, &mut engine);
    let ethercat = crate::ethercat::parse::axis_keys(&mut r, &mut engine, ios.get(io));
    let sim_table = r.table(&SIM);
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
    match t.get(NAME.name).and_then(|v| v.as_str()) {
        Some(n) => match names::check_name(n) {
            Ok(()) => n.to_string(),
            Err(e) => {
                problems.push(Problem::new(Some(&fallback), NAME.name, e));
                fallback
            }
        },
        None => {
            problems.push(Problem::new(Some(&fallback), NAME.name, "missing"));
            fallback
        }
    }
}

/// The index of the axis's I/O process (`io`, which may be left out when
/// there is only one).
fn io_of(r: &mut Reader<'_>, ios: &[IoConfig]) -> usize {
    if !r.has(&IO) {
        if ios.len() > 1 {
            r.problem(
                &IO,
                "missing: with several [[io]] sections every axis names its I/O process".into(),
            );
        }
        return 0;
    }
    let io_name = r.string(&IO);
    match ios.iter().position(|i| i.name == io_name) {
        Some(k) => k,
        None => {
            let known: Vec<&str> = ios.iter().map(|i| i.name.as_str()).collect();
            r.problem(
                &IO,
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
    let counts_per_unit = r.f64_in(&COUNTS_PER_UNIT);
    let max_position = r.f64_in(&MAX_POSITION);
    if max_position * counts_per_unit > MAX_COUNTS {
        r.problem(
            &MAX_POSITION,
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
        configuration: r.choice(&CONFIGURATION, AC::NAMES),
        control_mode: r.choice(&CONTROL_MODE, CM::NAMES),
        travel: r.choice(&TRAVEL, TM::NAMES),
        unwind: r.f64_in(&UNWIND),
        counts_per_unit,
        marker: r.bool(&MARKER),
        marker_latch: r.bool(&MARKER_LATCH),
        registration: r.bool(&REGISTRATION),
        travel_limits: r.interval(&TRAVEL_LIMITS),
        home_mode: r.choice(&HOME_MODE, HM::NAMES),
        home_direction: r.choice(&HOME_DIRECTION, HD::NAMES),
        home_sequence: r.choice(&HOME_SEQUENCE, HS::NAMES),
        home_switch_normally_closed: r.bool(&HOME_SWITCH_NORMALLY_CLOSED),
        home_position: r.f64_in(&HOME_POSITION),
        home_offset: r.f64_in(&HOME_OFFSET),
        home_speed: r.f64_in(&HOME_SPEED),
        home_return_speed: r.f64_in(&HOME_RETURN_SPEED),
        home_acceleration: r.f64_in(&HOME_ACCELERATION),
        home_deceleration: r.f64_in(&HOME_DECELERATION),
        home_torque_level: r.f64_in(&HOME_TORQUE_LEVEL),
        home_torque_threshold: r.f64_in(&HOME_TORQUE_THRESHOLD),
        home_torque_time: r.f64_in(&HOME_TORQUE_TIME),
        home_timeout: r.f64_in(&HOME_TIMEOUT),
        home_creep_speed: r.f64_in(&HOME_CREEP_SPEED),
        search_limit: r.f64_in(&SEARCH_LIMIT),
        torque_limit: r.f64_in(&TORQUE_LIMIT),
        position_error_tolerance: r.f64_in(&POSITION_ERROR_TOLERANCE),
        velocity_error_tolerance: r.f64_in(&VELOCITY_ERROR_TOLERANCE),
        enable_timeout: r.f64_in(&ENABLE_TIMEOUT),
        feedback_timeout_ns: sup.feedback_timeout_ns(),
        feedback_loss_drain: sup.feedback_loss_drain,
        cycle_ns: sup.cycle_ns(),
        max_position,
        absolute: r.bool(&ABSOLUTE),
        max_speed: r.f64_in(&MAX_SPEED),
        marker_min_distance: 0.0,
        refuse_ambiguous_marker: r.bool(&REFUSE_AMBIGUOUS_MARKER),
        unhomed_speed: d.unhomed_speed,
        limit_switches: d.limit_switches,
        max_deceleration: d.max_deceleration,
        stream_acceleration: d.stream_acceleration,
        stream_timeout_ns: d.stream_timeout_ns,
        stream_unhomed: d.stream_unhomed,
        jerk: d.jerk,
        home_reverse_at_limit: r.bool(&HOME_REVERSE_AT_LIMIT),
        // set by the EtherCAT keys (`drive_homing`)
        drive_homing: false,
    };
    // A switch edge sampled once per cycle is known to a cycle of travel at
    // return speed; a marker closer than two such cycles to it is ambiguous.
    // The default check uses exactly that distance.
    let cycle_ms = f64::from(sup.cycle_us) / 1000.0;
    engine.marker_min_distance = r.f64_in_or(
        &MARKER_MIN_DISTANCE,
        2.0 * engine.home_return_speed * cycle_ms / 1000.0,
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
    let mut r = Reader::new(t.unwrap_or(&empty), Some(axis), Section::AxisSim, problems);
    let sim = PlantConfig {
        start: r.f64_in(&sim::START),
        switch: r.interval(&sim::SWITCH),
        // The sim wires the switch as the axis says.
        switch_normally_closed: engine.home_switch_normally_closed,
        marker_every: r.f64_in(&sim::MARKER_EVERY),
        marker_at: r.f64_in(&sim::MARKER_AT),
        hard_stop: r.interval(&sim::HARD_STOP),
        overtravel: limit_switches::read(&mut r),
        limit_switches_normally_closed: r.bool(&sim::LIMIT_SWITCHES_NORMALLY_CLOSED),
        // The probe input is wired to the switch the axis homes on.
        registration_input: limit_switches::registration_input(engine),
        external_speed: r.f64_in(&sim::EXTERNAL_SPEED),
        push_gain: r.f64_in(&sim::PUSH_GAIN),
        inertia_gain: r.f64_in(&sim::INERTIA_GAIN),
        friction: r.f64_in(&sim::FRICTION),
        enable_delay_cycles: r.u32_in(&sim::ENABLE_DELAY_CYCLES),
        torque_spike: None,
    };
    r.finish();
    sim
}
