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
];

/// The `[[axis]]` keys that only an axis of an EtherCAT I/O process has.
const AXIS_KEYS: [&str; 3] = [
    "ethercat_position",
    "ethercat_name",
    "ethercat_index_pulse_bit",
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
    }
}

/// The axis' EtherCAT keys: allowed on (and, but for a virtual axis,
/// required by) an axis of an EtherCAT I/O process only.
pub(crate) fn axis_keys(
    r: &mut Reader<'_>,
    engine: &AxisConfig,
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
    let index_pulse_bit = r.has("ethercat_index_pulse_bit").then(|| {
        r.u32_in(
            "ethercat_index_pulse_bit",
            INDEX_PULSE_BIT.0,
            INDEX_PULSE_BIT.0,
            INDEX_PULSE_BIT.1,
        ) as u8
    });
    let drive = match (position, name) {
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
    };
    Some(AxisEthercat {
        drive,
        index_pulse_bit,
    })
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
