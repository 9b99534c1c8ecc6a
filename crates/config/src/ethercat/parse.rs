//! Reading the EtherCAT keys: those of an `[[io]]` with `backend =
//! "ethercat"` ([`io_keys`]), those of its axes ([`axis_keys`]), and the
//! checks across the axes of one bus ([`checks`]). On any other backend the
//! keys are a problem (they would be silently ignored).

use motion_homing::AxisConfig;

use super::{AxisEthercat, EthercatDrive, EthercatIo, DC_MODES};
use crate::keys::Reader;
use crate::keytable::ethercat::{self as keys, *};
use crate::keytable::io::BACKEND;
use crate::keytable::Key;
use crate::limits::{ETHERCAT_MAX_AXES, ETHERCAT_MIN_CYCLE_US};
use crate::{names, AxisEntry, IoBackend, IoConfig, Problem, SupervisorConfig};

/// The EtherCAT keys of the `[[io]]` read by `r` (`who` names it in
/// messages): `Some` on `backend = "ethercat"`, else `None` and each key
/// given is a problem.
pub(crate) fn io_keys(
    r: &mut Reader<'_>,
    who: &str,
    backend: IoBackend,
    sup: &SupervisorConfig,
) -> Option<EthercatIo> {
    if backend == IoBackend::Ethercat {
        return Some(ethercat_io(r, who, sup));
    }
    for k in keys::IO.keys {
        if r.has(k) {
            r.mark_used(k);
            r.problem(
                k,
                format!(
                    "{who}: only for backend = \"ethercat\" (this I/O process has \
                     backend = \"{}\")",
                    backend.name()
                ),
            );
        }
    }
    None
}

fn ethercat_io(r: &mut Reader<'_>, label: &str, sup: &SupervisorConfig) -> EthercatIo {
    let interface = if r.has(&INTERFACE) {
        let i = r.string(&INTERFACE);
        if let Err(e) = names::check_interface_name(&i) {
            r.problem(&INTERFACE, format!("{label}: {e}"));
        }
        i
    } else {
        r.problem(
            &INTERFACE,
            format!(
                "{label}: missing: backend = \"ethercat\" needs the network interface of the \
                 bus (e.g. interface = \"eth1\"; motion-io --interface overrides it)"
            ),
        );
        String::new()
    };
    let dc = r.choice(&DC, DC_MODES);
    let sm_watchdog_ms = r.u32_in(&SM_WATCHDOG_MS);
    if u64::from(sm_watchdog_ms) * 1000 < 3 * u64::from(sup.cycle_us) {
        r.problem(
            &SM_WATCHDOG_MS,
            format!(
                "{label}: {sm_watchdog_ms} ms is shorter than 3 cycles of {} µs",
                sup.cycle_us
            ),
        );
    }
    let reply_timeout_us = r.has(&REPLY_TIMEOUT_US).then(|| {
        let v = r.u32_in(&REPLY_TIMEOUT_US);
        let most = sup.cycle_us / 100 * 95;
        if v > most {
            r.problem(
                &REPLY_TIMEOUT_US,
                format!(
                    "{label}: {v} µs leaves no time in a cycle of {} µs (at most 95 %: {most} µs)",
                    sup.cycle_us
                ),
            );
        }
        v
    });
    let startup_timeout_s = r.u32_in(&STARTUP_TIMEOUT_S);
    let mode_in_pdo = r.bool(&MODE_IN_PDO);
    let dc_static_sync_iterations = r.u32_in(&DC_STATIC_SYNC_ITERATIONS);
    let quick_stop_timeout_ms = r.u32_in(&QUICK_STOP_TIMEOUT_MS);
    if sup.cycle_us < ETHERCAT_MIN_CYCLE_US {
        r.problem(
            &BACKEND,
            format!(
                "{label}: the EtherCAT bus cycles at [supervisor] cycle_us = {} µs; it needs \
                 at least {ETHERCAT_MIN_CYCLE_US} µs",
                sup.cycle_us
            ),
        );
    }
    EthercatIo {
        interface,
        dc,
        sm_watchdog_ms,
        reply_timeout_us,
        startup_timeout_s,
        mode_in_pdo,
        dc_static_sync_iterations,
        quick_stop_timeout_ms,
    }
}

/// The axis' EtherCAT keys: allowed on (and, but for a virtual axis,
/// required by) an axis of an EtherCAT I/O process only. `drive_homing`
/// marks the engine's configuration (`engine.drive_homing`): its plan is
/// then the drive's homing.
pub(crate) fn axis_keys(
    r: &mut Reader<'_>,
    engine: &mut AxisConfig,
    io: Option<&IoConfig>,
) -> Option<AxisEthercat> {
    let given: Vec<&Key> = keys::AXIS
        .keys
        .iter()
        .copied()
        .filter(|k| r.has(k))
        .collect();
    let io_name = io.map_or("?", |i| i.name.as_str());
    let on_ethercat = io.is_some_and(|i| i.backend == IoBackend::Ethercat);
    if !on_ethercat {
        let backend = io.map_or("sim", |i| i.backend.name());
        for k in given {
            r.mark_used(k);
            r.problem(
                k,
                format!(
                    "only for an axis of an EtherCAT I/O process (its I/O process {io_name} \
                     has backend = \"{backend}\")"
                ),
            );
        }
        return None;
    }
    if engine.configuration == motion_homing::AxisConfiguration::Virtual {
        for k in given {
            r.mark_used(k);
            r.problem(k, "a virtual axis has no drive".into());
        }
        return None;
    }
    let drive = drive_key(r, io_name);
    let bit = |r: &mut Reader<'_>, key: &Key| {
        r.has(key)
            .then(|| r.u32_in_or(key, key.range_of().0 as u32) as u8)
    };
    let index_pulse_bit = bit(r, &ETHERCAT_INDEX_PULSE_BIT);
    let home_switch_bit = bit(r, &ETHERCAT_HOME_SWITCH_BIT);
    let brake_delay_ms = r.u32_in(&ETHERCAT_BRAKE_DELAY_MS);
    let drive_homing_method = drive_homing(r, engine);
    engine.drive_homing = drive_homing_method.is_some();
    if engine.home_sequence.uses_marker()
        && !engine.marker_latch
        && !engine.drive_homing
        && index_pulse_bit.is_none()
    {
        r.problem(
            &ETHERCAT_INDEX_PULSE_BIT,
            "missing: a marker sequence with marker_latch = false sees the index pulse in a \
             manufacturer bit of 0x60FD: name it (16..=31), or latch the marker \
             (marker_latch = true, touch probe 0x60B8)"
                .into(),
        );
    }
    Some(AxisEthercat {
        drive,
        index_pulse_bit,
        home_switch_bit,
        brake_delay_ms,
        drive_homing_method,
    })
}

/// `ethercat_position` or `ethercat_name`: exactly one of them.
fn drive_key(r: &mut Reader<'_>, io_name: &str) -> EthercatDrive {
    let position = r
        .has(&ETHERCAT_POSITION)
        .then(|| r.u32_in_or(&ETHERCAT_POSITION, 0) as u16);
    let name = r.has(&ETHERCAT_NAME).then(|| {
        let n = r.string(&ETHERCAT_NAME);
        if let Err(e) = names::check_subdevice_name(&n) {
            r.problem(&ETHERCAT_NAME, e);
        }
        n
    });
    match (position, name) {
        (Some(p), None) => EthercatDrive::Position(p),
        (None, Some(n)) => EthercatDrive::Name(n),
        (Some(p), Some(_)) => {
            r.problem(
                &ETHERCAT_NAME,
                "give ethercat_position or ethercat_name, not both".into(),
            );
            EthercatDrive::Position(p)
        }
        (None, None) => {
            r.problem(
                &ETHERCAT_POSITION,
                format!(
                    "missing: an axis of EtherCAT I/O process {io_name} names its drive with \
                     ethercat_position (bus position, 0 = first) or ethercat_name"
                ),
            );
            EthercatDrive::Position(0)
        }
    }
}

/// `drive_homing` / `drive_homing_method`: the method the drive homes the
/// axis with, if it does (a method given means `drive_homing = true`).
fn drive_homing(r: &mut Reader<'_>, engine: &AxisConfig) -> Option<i8> {
    let method = r.has(&DRIVE_HOMING_METHOD).then(|| {
        let m = r.i32_or(&DRIVE_HOMING_METHOD, 0);
        let (lo, hi) = DRIVE_HOMING_METHOD.range_of();
        if m == 0 || !(lo..=hi).contains(&f64::from(m)) {
            r.problem(
                &DRIVE_HOMING_METHOD,
                format!("{m}: a CiA 402 homing method is -128..=127 and not 0"),
            );
        }
        m.clamp(-128, 127) as i8
    });
    let on = r.bool_or(&DRIVE_HOMING, method.is_some());
    if !on {
        if method.is_some() {
            r.problem(
                &DRIVE_HOMING_METHOD,
                "drive_homing = false: the drive does not home this axis, its method is unused"
                    .into(),
            );
        }
        return None;
    }
    let seq = engine.home_sequence;
    if engine.home_mode != motion_homing::HomeMode::Active
        || seq == motion_homing::HomeSequence::Immediate
    {
        r.problem(
            &DRIVE_HOMING,
            format!(
                "the drive homes actively; home_mode = {:?} with home_sequence = {:?} leaves it \
                 nothing to do",
                engine.home_mode.name(),
                seq.name()
            ),
        );
        return None;
    }
    match method.or_else(|| super::homing::standard_method(seq, engine.home_direction)) {
        Some(m) => Some(m),
        None => {
            r.problem(
                &DRIVE_HOMING_METHOD,
                format!(
                    "missing: no standard CiA 402 homing method does home_sequence = {:?} \
                     {:?}{}: set the drive's method (see its 0x60E3 or motion-io scan)",
                    seq.name(),
                    engine.home_direction.name(),
                    if seq.uses_torque() {
                        " (hard-stop methods are the manufacturer's, negative on most drives)"
                    } else {
                        ""
                    }
                ),
            );
            None
        }
    }
}

/// Across the axes of each EtherCAT I/O process: one drive per axis, and
/// no more axes than the backend drives.
pub(crate) fn checks(ios: &[IoConfig], axes: &[AxisEntry], problems: &mut Vec<Problem>) {
    for (k, io) in ios.iter().enumerate() {
        if io.backend != IoBackend::Ethercat {
            continue;
        }
        let mine: Vec<&AxisEntry> = axes.iter().filter(|a| a.io == k).collect();
        if mine.len() > ETHERCAT_MAX_AXES {
            problems.push(Problem::new(
                None,
                "io",
                format!(
                    "EtherCAT I/O process {} drives {} axes, at most {ETHERCAT_MAX_AXES}",
                    io.name,
                    mine.len(),
                ),
            ));
        }
        for (i, a) in mine.iter().enumerate() {
            let Some(e) = &a.ethercat else { continue };
            if let Some(b) = mine[..i]
                .iter()
                .find(|b| b.ethercat.as_ref().is_some_and(|f| f.drive == e.drive))
            {
                let (key, what) = match &e.drive {
                    EthercatDrive::Position(p) => ("ethercat_position", format!("position {p}")),
                    EthercatDrive::Name(n) => {
                        ("ethercat_name", format!("name {}", names::shown(n)))
                    }
                };
                problems.push(Problem::new(
                    Some(&a.name),
                    key,
                    format!("the SubDevice at {what} already drives axis {}", b.name),
                ));
            }
        }
    }
}

impl Default for EthercatIo {
    /// The key table's defaults.
    fn default() -> Self {
        EthercatIo {
            interface: String::new(),
            dc: super::EthercatDc::default(),
            sm_watchdog_ms: SM_WATCHDOG_MS.default_f64() as u32,
            reply_timeout_us: None,
            startup_timeout_s: STARTUP_TIMEOUT_S.default_f64() as u32,
            mode_in_pdo: MODE_IN_PDO.default_bool(),
            dc_static_sync_iterations: DC_STATIC_SYNC_ITERATIONS.default_f64() as u32,
            quick_stop_timeout_ms: QUICK_STOP_TIMEOUT_MS.default_f64() as u32,
        }
    }
}
