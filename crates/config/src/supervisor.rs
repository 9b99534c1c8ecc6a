//! `[supervisor]`.

use crate::keys::Reader;
use crate::limits::*;
use crate::{check_cpu, names, IoMode, Problem, SupervisorConfig};
use std::path::PathBuf;

pub(crate) fn parse(
    t: Option<&toml::Table>,
    problems: &mut Vec<Problem>,
    warnings: &mut Vec<String>,
) -> SupervisorConfig {
    let empty = toml::Table::new();
    let mut r = Reader::new(t.unwrap_or(&empty), None, "supervisor.", problems);
    let cycle_us = r.u32_in("cycle_us", 1000, CYCLE_US.0, CYCLE_US.1);
    let cpu = r.u32("cpu", 1);
    if let Err(e) = check_cpu(i64::from(cpu)) {
        r.problem("cpu", e);
    }
    let priority = r.u32_in("priority", 80, 1, 99) as i32;
    let io = r.choice("io", IoMode::NAMES, IoMode::Sim);
    let service_prefix = r.string("service_prefix", "motion");
    if let Err(e) = names::check_service_prefix(&service_prefix) {
        r.problem("service_prefix", e);
    }
    let cycle_ms = f64::from(cycle_us) / 1000.0;
    let feedback_timeout_ms = feedback_timeout_ms(&mut r, cycle_ms, warnings);
    let feedback_loss_drain = r.f64_in("feedback_loss_drain", 0.25, 0.0, 1.0, "");
    let max_watchdog = ((WATCHDOG_MS / cycle_ms) as u32).max(1);
    let io_watchdog_cycles = r.u32_in("io_watchdog_cycles", 50.min(max_watchdog), 1, max_watchdog);
    let lock_memory = r.bool("lock_memory", true);
    let cpu_dma_latency_us = r.i32("cpu_dma_latency_us", 0);
    if cpu_dma_latency_us > 10_000 {
        r.problem(
            "cpu_dma_latency_us",
            format!("{cpu_dma_latency_us} µs is above 10000 (negative: leave idle states alone)"),
        );
    }
    let (io_priority, io_cpu) = io_scheduling(&mut r, priority);
    let (runtime_dir, state_dir) = directories(&mut r);
    r.finish();
    SupervisorConfig {
        cycle_us,
        cpu: cpu as usize,
        priority,
        io,
        service_prefix,
        feedback_timeout_ms,
        feedback_loss_drain,
        io_watchdog_cycles,
        lock_memory,
        io_priority,
        io_cpu,
        cpu_dma_latency_us,
        runtime_dir,
        state_dir,
    }
}

/// The feedback-loss rule in time. The older `stale_cycles` (cycles in a
/// row) is still read, converted to the same time at this cycle.
fn feedback_timeout_ms(r: &mut Reader<'_>, cycle_ms: f64, warnings: &mut Vec<String>) -> f64 {
    let mut feedback_timeout_ms = r.f64_in(
        "feedback_timeout_ms",
        10.0,
        FEEDBACK_TIMEOUT_MS.0,
        FEEDBACK_TIMEOUT_MS.1,
        "ms",
    );
    if r.has("stale_cycles") {
        let stale = r.u32("stale_cycles", 0);
        let ms = f64::from(stale) * cycle_ms;
        if r.has("feedback_timeout_ms") {
            r.problem(
                "stale_cycles",
                "give feedback_timeout_ms or the older stale_cycles, not both".into(),
            );
        } else if !(FEEDBACK_TIMEOUT_MS.0..=FEEDBACK_TIMEOUT_MS.1).contains(&ms) {
            r.problem(
                "stale_cycles",
                format!(
                    "{stale} cycles = {ms} ms is outside {}..={} ms (a larger value would \
                     switch feedback-loss detection off)",
                    FEEDBACK_TIMEOUT_MS.0, FEEDBACK_TIMEOUT_MS.1
                ),
            );
        } else {
            warnings.push(format!(
                "[supervisor] stale_cycles = {stale} is read as feedback_timeout_ms = {ms}; \
                 the feedback-loss rule is now stated in ms"
            ));
            feedback_timeout_ms = ms;
        }
    }
    feedback_timeout_ms
}

/// `io_priority` (default 10 below the cycle) and `io_cpu` (-1: the
/// cycle's CPU) of the spawned I/O processes.
fn io_scheduling(r: &mut Reader<'_>, priority: i32) -> (i32, Option<usize>) {
    let io_priority = r.i32("io_priority", (priority - 10).max(1));
    if !(0..=99).contains(&io_priority) {
        r.problem(
            "io_priority",
            format!("{io_priority} is outside 0..=99 (0: normal scheduling)"),
        );
    }
    let io_cpu = match r.i32("io_cpu", -1) {
        c if c >= 0 => {
            if let Err(e) = check_cpu(i64::from(c)) {
                r.problem("io_cpu", e);
            }
            Some(c as usize)
        }
        -1 => None,
        c => {
            r.problem(
                "io_cpu",
                format!("{c}: a CPU number, or -1 for the cycle's CPU"),
            );
            None
        }
    };
    (io_priority, io_cpu)
}

/// `runtime_dir` (if given) and `state_dir` (else the default).
fn directories(r: &mut Reader<'_>) -> (Option<PathBuf>, PathBuf) {
    let runtime_dir = r.has("runtime_dir").then(|| {
        let d = r.string("runtime_dir", "");
        if let Err(e) = crate::args::runtime_dir(&d) {
            r.problem("runtime_dir", e);
        }
        PathBuf::from(d)
    });
    let state_dir = if r.has("state_dir") {
        let d = r.string("state_dir", "");
        if !d.starts_with('/') || d.len() > 200 || d.contains("..") {
            r.problem(
                "state_dir",
                format!(
                    "{} must be an absolute path of at most 200 characters without \"..\"",
                    names::shown(&d)
                ),
            );
        }
        PathBuf::from(d)
    } else {
        default_state_dir()
    };
    (runtime_dir, state_dir)
}

/// systemd's `$STATE_DIRECTORY` (the unit's `StateDirectory=motion`), else
/// `/var/lib/motion` for root, else `$HOME/.local/state/motion`.
pub fn default_state_dir() -> std::path::PathBuf {
    if let Some(d) = std::env::var_os("STATE_DIRECTORY") {
        // Several directories are separated by ':'; ours is the first.
        let first = d
            .to_string_lossy()
            .split(':')
            .next()
            .unwrap_or("")
            .to_string();
        if first.starts_with('/') {
            return first.into();
        }
    }
    if nix::unistd::geteuid().is_root() {
        return "/var/lib/motion".into();
    }
    match std::env::var_os("HOME") {
        Some(h) => std::path::Path::new(&h).join(".local/state/motion"),
        None => format!("/tmp/motion-state-{}", nix::unistd::geteuid()).into(),
    }
}
