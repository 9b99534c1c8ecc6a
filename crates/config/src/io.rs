//! `[[io]]`: the drive-I/O processes. Without any, `[supervisor] io` keeps
//! its meaning: one I/O process named `io` with the `sim` backend.
//!
//! `backend = "ethercat"` adds the keys of [`EthercatIo`]; on any other
//! backend those keys are a problem (they would be silently ignored).

use crate::keys::Reader;
use crate::limits::*;
use crate::{
    check_cpu, names, EthercatDc, EthercatIo, IoBackend, IoConfig, IoMode, Problem,
    SupervisorConfig, DEFAULT_IO_NAME, MAX_IOS,
};

/// The `[[io]]` keys that only an EtherCAT I/O process has.
pub(crate) const ETHERCAT_KEYS: &[&str] = &[
    "interface",
    "dc",
    "sm_watchdog_ms",
    "reply_timeout_us",
    "startup_timeout_s",
    "mode_in_pdo",
    "dc_static_sync_iterations",
];

const DC_MODES: &[(&str, EthercatDc)] = &[
    ("auto", EthercatDc::Auto),
    ("on", EthercatDc::On),
    ("off", EthercatDc::Off),
];

fn parse_ethercat(r: &mut Reader<'_>, label: &str, sup: &SupervisorConfig) -> EthercatIo {
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

pub(crate) fn parse(
    tables: &[toml::Table],
    sup: &SupervisorConfig,
    problems: &mut Vec<Problem>,
    warnings: &mut Vec<String>,
) -> Vec<IoConfig> {
    if tables.is_empty() {
        return vec![IoConfig {
            name: DEFAULT_IO_NAME.to_string(),
            spawn: sup.io,
            cpu: sup.io_cpu,
            priority: sup.io_priority,
            backend: IoBackend::Sim,
            ethercat: None,
        }];
    }
    if sup.io != IoMode::Sim {
        warnings.push(
            "[supervisor] io is ignored: the [[io]] sections say how each I/O process starts"
                .into(),
        );
    }
    if tables.len() > MAX_IOS {
        problems.push(Problem::new(
            None,
            "io",
            format!("{} [[io]] sections, at most {MAX_IOS}", tables.len()),
        ));
    }
    let mut ios: Vec<IoConfig> = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        let label = format!("io #{}", i + 1);
        let mut r = Reader::new(t, None, "io.", problems);
        let name = r.string("name", "");
        if let Err(e) = names::check_io_name(&name) {
            r.problem("name", format!("{label}: {e}"));
        }
        let spawn = match r.string("spawn", "sim").as_str() {
            // "sim" (interface.md) means "the supervisor starts it", whatever
            // its backend; "supervisor" says so.
            "sim" | "supervisor" => IoMode::Sim,
            "external" => IoMode::External,
            other => {
                r.problem(
                    "spawn",
                    format!(
                        "{label}: {} is not one of \"sim\", \"supervisor\", \"external\"",
                        names::shown(other)
                    ),
                );
                IoMode::Sim
            }
        };
        let backend = r.choice("backend", IoBackend::NAMES, IoBackend::Sim);
        let who = if names::check_io_name(&name).is_ok() {
            format!("I/O process {name}")
        } else {
            label.clone()
        };
        let ethercat = if backend == IoBackend::Ethercat {
            Some(parse_ethercat(&mut r, &who, sup))
        } else {
            for k in ETHERCAT_KEYS {
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
        };
        let cpu = r.has("cpu").then(|| r.u32("cpu", 0) as usize);
        if let Some(c) = cpu {
            if let Err(e) = check_cpu(c as i64) {
                r.problem("cpu", format!("{label}: {e}"));
            }
        }
        let priority = r.i32("priority", sup.io_priority);
        if !(0..=99).contains(&priority) {
            r.problem(
                "priority",
                format!("{label}: {priority} is outside 0..=99 (0: normal scheduling)"),
            );
        }
        if ios.iter().any(|o| o.name == name) {
            r.problem(
                "name",
                format!("I/O process name {} used twice", names::shown(&name)),
            );
        }
        r.finish();
        ios.push(IoConfig {
            name,
            spawn,
            cpu,
            priority,
            backend,
            ethercat,
        });
    }
    ios
}
