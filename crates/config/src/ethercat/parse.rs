//! Reading the EtherCAT keys: those of an `[[io]]` with `backend =
//! "ethercat"` ([`io_keys`]), those of its axes ([`axis_keys`]), and the
//! checks across the axes of one bus ([`checks`]). On any other backend the
//! keys are a problem (they would be silently ignored).

use motion_homing::AxisConfig;

use super::{AxisEthercat, EthercatDc, EthercatDrive, EthercatIo};
use crate::keys::Reader;
use crate::limits::*;
use crate::{names, AxisEntry, IoBackend, IoConfig, Problem, SupervisorConfig};

/// The `[[io]]` keys that only an EtherCAT I/O process has.
const IO_KEYS: &[&str] = &[
    "interface",
    "dc",
    "sm_watchdog_ms",
    "reply_timeout_us",
    "startup_timeout_s",
    "mode_in_pdo",
    "dc_static_sync_iterations",
    "quick_stop_timeout_ms",
];

/// The `[[axis]]` keys that only an axis of an EtherCAT I/O process has.
const AXIS_KEYS: [&str; 7] = [
    "ethercat_position",
    "ethercat_name",
    "ethercat_index_pulse_bit",
    "ethercat_home_switch_bit",
    "ethercat_brake_delay_ms",
    "drive_homing",
    "drive_homing_method",
];

const DC_MODES: &[(&str, EthercatDc)] = &[
    ("auto", EthercatDc::Auto),
    ("on", EthercatDc::On),
    ("off", EthercatDc::Off),
];

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
    for k in IO_KEYS {
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
    let d = EthercatIo::default();
    let interface = if r.has("interface") {
        let i = r.string("interface", "");
        if let Err(e) = names::check_interface_name(&i) {
            r.problem("interface", format!("{label}: {e}"));
        }
        i
    } else {
        r.problem(
            "interface",
            format!(
                "{label}: missing: backend = \"ethercat\" needs the network interface of the \
                 bus (e.g. interface = \"eth1\"; motion-io --interface overrides it)"
            ),
        );
        String::new()
    };
    let dc = r.choice("dc", DC_MODES, d.dc);
    let sm_watchdog_ms = r.u32_in(
        "sm_watchdog_ms",
        d.sm_watchdog_ms,
        SM_WATCHDOG_MS.0,
        SM_WATCHDOG_MS.1,
    );
    if u64::from(sm_watchdog_ms) * 1000 < 3 * u64::from(sup.cycle_us) {
        r.problem(
            "sm_watchdog_ms",
            format!(
                "{label}: {sm_watchdog_ms} ms is shorter than 3 cycles of {} µs",
                sup.cycle_us
            ),
        );
    }
    let reply_timeout_us = r.has("reply_timeout_us").then(|| {
        let v = r.u32_in(
            "reply_timeout_us",
            0,
            REPLY_TIMEOUT_US.0,
            REPLY_TIMEOUT_US.1,
        );
        let most = sup.cycle_us / 100 * 95;
        if v > most {
            r.problem(
                "reply_timeout_us",
                format!(
                    "{label}: {v} µs leaves no time in a cycle of {} µs (at most 95 %: {most} µs)",
                    sup.cycle_us
                ),
            );
        }
        v
    });
    let startup_timeout_s = r.u32_in(
        "startup_timeout_s",
        d.startup_timeout_s,
        STARTUP_TIMEOUT_S.0,
        STARTUP_TIMEOUT_S.1,
    );
    let mode_in_pdo = r.bool("mode_in_pdo", d.mode_in_pdo);
    let dc_static_sync_iterations = r.u32_in(
        "dc_static_sync_iterations",
        d.dc_static_sync_iterations,
        DC_STATIC_SYNC_ITERATIONS.0,
        DC_STATIC_SYNC_ITERATIONS.1,
    );
    let quick_stop_timeout_ms = r.u32_in(
        "quick_stop_timeout_ms",
        d.quick_stop_timeout_ms,
        QUICK_STOP_TIMEOUT_MS.0,
        QUICK_STOP_TIMEOUT_MS.1,
    );
    if sup.cycle_us < ETHERCAT_MIN_CYCLE_US {
        r.problem(
            "backend",
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
    let given: Vec<&str> = AXIS_KEYS.iter().copied().filter(|k| r.has(k)).collect();
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
    let bit = |r: &mut Reader<'_>, key: &str| {
        r.has(key)
            .then(|| r.u32_in(key, INDEX_PULSE_BIT.0, INDEX_PULSE_BIT.0, INDEX_PULSE_BIT.1) as u8)
    };
    let index_pulse_bit = bit(r, "ethercat_index_pulse_bit");
    let home_switch_bit = bit(r, "ethercat_home_switch_bit");
    let brake_delay_ms = r.u32_in(
        "ethercat_brake_delay_ms",
        0,
        BRAKE_DELAY_MS.0,
        BRAKE_DELAY_MS.1,
    );
    let drive_homing_method = drive_homing(r, engine);
    engine.drive_homing = drive_homing_method.is_some();
    if engine.home_sequence.uses_marker()
        && !engine.marker_latch
        && !engine.drive_homing
        && index_pulse_bit.is_none()
    {
        r.problem(
            "ethercat_index_pulse_bit",
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
    let position = r.has("ethercat_position").then(|| {
        r.u32_in(
            "ethercat_position",
            0,
            ETHERCAT_POSITION.0,
            ETHERCAT_POSITION.1,
        ) as u16
    });
    let name = r.has("ethercat_name").then(|| {
        let n = r.string("ethercat_name", "");
        if let Err(e) = names::check_subdevice_name(&n) {
            r.problem("ethercat_name", e);
        }
        n
    });
    match (position, name) {
        (Some(p), None) => EthercatDrive::Position(p),
        (None, Some(n)) => EthercatDrive::Name(n),
        (Some(p), Some(_)) => {
            r.problem(
                "ethercat_name",
                "give ethercat_position or ethercat_name, not both".into(),
            );
            EthercatDrive::Position(p)
        }
        (None, None) => {
            r.problem(
                "ethercat_position",
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
    let method = r.has("drive_homing_method").then(|| {
        let m = r.i32("drive_homing_method", 0);
        if m == 0 || !(DRIVE_HOMING_METHOD.0..=DRIVE_HOMING_METHOD.1).contains(&m) {
            r.problem(
                "drive_homing_method",
                format!("{m}: a CiA 402 homing method is -128..=127 and not 0"),
            );
        }
        m.clamp(-128, 127) as i8
    });
    let on = r.bool("drive_homing", method.is_some());
    if !on {
        if method.is_some() {
            r.problem(
                "drive_homing_method",
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
            "drive_homing",
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
                "drive_homing_method",
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
