//! `[[io]]`: the drive-I/O processes. Without any, `[supervisor] io` keeps
//! its meaning: one I/O process named `io` with the `sim` backend.
//!
//! `backend = "ethercat"` adds the keys of [`crate::EthercatIo`] (read in
//! [`crate::ethercat`]); on any other backend those keys are a problem.

use crate::keys::Reader;
use crate::{
    check_cpu, ethercat, names, IoBackend, IoConfig, IoMode, Problem, SupervisorConfig,
    DEFAULT_IO_NAME, MAX_IOS,
};

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
        let ethercat = ethercat::parse::io_keys(&mut r, &who, backend, sup);
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
