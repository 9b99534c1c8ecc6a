//! `[[io]]`: the drive-I/O processes. Without any, `[supervisor] io` keeps
//! its meaning: one I/O process named `io` with the `sim` backend.
//!
//! `backend = "ethercat"` adds the keys of [`crate::EthercatIo`] (read in
//! [`crate::ethercat`]); on any other backend those keys are a problem.

use crate::keys::Reader;
use crate::keytable::{io::*, Section};
use crate::{
    check_cpu, ethercat, names, IoBackend, IoConfig, IoMode, Problem, SupervisorConfig,
    DEFAULT_IO_NAME, MAX_IOS, SPAWN_NAMES,
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
        let mut r = Reader::new(t, None, Section::Io, problems);
        let name = r.string(&NAME);
        if let Err(e) = names::check_io_name(&name) {
            r.problem(&NAME, format!("{label}: {e}"));
        }
        let spawn = spawn(&mut r, &label);
        let backend = r.choice(&BACKEND, IoBackend::NAMES);
        let who = if names::check_io_name(&name).is_ok() {
            format!("I/O process {name}")
        } else {
            label.clone()
        };
        let ethercat = ethercat::parse::io_keys(&mut r, &who, backend, sup);
        let cpu = r.has(&CPU).then(|| r.u32(&CPU) as usize);
        if let Some(c) = cpu {
            if let Err(e) = check_cpu(c as i64) {
                r.problem(&CPU, format!("{label}: {e}"));
            }
        }
        let priority = r.i32_or(&PRIORITY, sup.io_priority);
        let (lo, hi) = PRIORITY.range_of();
        if !(lo..=hi).contains(&f64::from(priority)) {
            r.problem(
                &PRIORITY,
                format!("{label}: {priority} is outside {lo}..={hi} (0: normal scheduling)"),
            );
        }
        if ios.iter().any(|o| o.name == name) {
            r.problem(
                &NAME,
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

/// `spawn`: one of [`SPAWN_NAMES`] (`label` names the I/O process in the
/// problem).
fn spawn(r: &mut Reader<'_>, label: &str) -> IoMode {
    let given = r.string(&SPAWN);
    match SPAWN_NAMES.iter().find(|(n, _)| *n == given) {
        Some((_, mode)) => *mode,
        None => {
            let names: Vec<String> = SPAWN_NAMES
                .iter()
                .map(|(n, _)| format!("\"{n}\""))
                .collect();
            r.problem(
                &SPAWN,
                format!(
                    "{label}: {} is not one of {}",
                    names::shown(&given),
                    names.join(", ")
                ),
            );
            IoMode::Sim
        }
    }
}
