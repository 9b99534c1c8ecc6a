//! `[supervisor]`.

use crate::keys::Reader;
use crate::keytable::supervisor::*;
use crate::keytable::Section;
use crate::limits::WATCHDOG_MS;
use crate::{check_cpu, names, IoMode, Problem, SupervisorConfig};
use std::path::PathBuf;

pub(crate) fn parse(
    t: Option<&toml::Table>,
    problems: &mut Vec<Problem>,
    warnings: &mut Vec<String>,
) -> SupervisorConfig {
    let empty = toml::Table::new();
    let mut r = Reader::new(t.unwrap_or(&empty), None, Section::Supervisor, problems);
    let cycle_us = r.u32_in(&CYCLE_US);
    let cpu = r.u32(&CPU);
    if let Err(e) = check_cpu(i64::from(cpu)) {
        r.problem(&CPU, e);
    }
    let priority = r.u32_in(&PRIORITY) as i32;
    let io = r.choice(&IO, IoMode::NAMES);
    let service_prefix = r.string(&SERVICE_PREFIX);
    if let Err(e) = names::check_service_prefix(&service_prefix) {
        r.problem(&SERVICE_PREFIX, e);
    }
    let cycle_ms = f64::from(cycle_us) / 1000.0;
    let feedback_timeout_ms = feedback_timeout_ms(&mut r, cycle_ms, warnings);
    let feedback_loss_drain = r.f64_in(&FEEDBACK_LOSS_DRAIN);
    let max_watchdog = ((WATCHDOG_MS / cycle_ms) as u32).max(1);
    let io_watchdog_cycles =
        r.u32_within(&IO_WATCHDOG_CYCLES, 50.min(max_watchdog), 1, max_watchdog);
    let lock_memory = r.bool(&LOCK_MEMORY);
    let cpu_dma_latency_us = r.i32(&CPU_DMA_LATENCY_US);
    let (_, most) = CPU_DMA_LATENCY_US.range_of();
    if f64::from(cpu_dma_latency_us) > most {
        r.problem(
            &CPU_DMA_LATENCY_US,
            format!("{cpu_dma_latency_us} µs is above {most} (negative: leave idle states alone)"),
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
    let mut feedback_timeout_ms = r.f64_in(&FEEDBACK_TIMEOUT_MS);
    if r.has(&STALE_CYCLES) {
        let (lo, hi) = FEEDBACK_TIMEOUT_MS.range_of();
        let stale = r.u32(&STALE_CYCLES);
        let ms = f64::from(stale) * cycle_ms;
        if r.has(&FEEDBACK_TIMEOUT_MS) {
            r.problem(
                &STALE_CYCLES,
                "give feedback_timeout_ms or the older stale_cycles, not both".into(),
            );
        } else if !(lo..=hi).contains(&ms) {
            r.problem(
                &STALE_CYCLES,
                format!(
                    "{stale} cycles = {ms} ms is outside {}..={} ms (a larger value would \
                     switch feedback-loss detection off)",
                    lo, hi
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
    let io_priority = r.i32_or(&IO_PRIORITY, (priority - 10).max(1));
    let (lo, hi) = IO_PRIORITY.range_of();
    if !(lo..=hi).contains(&f64::from(io_priority)) {
        r.problem(
            &IO_PRIORITY,
            format!("{io_priority} is outside {lo}..={hi} (0: normal scheduling)"),
        );
    }
    let io_cpu = match r.i32(&IO_CPU) {
        c if c >= 0 => {
            if let Err(e) = check_cpu(i64::from(c)) {
                r.problem(&IO_CPU, e);
            }
            Some(c as usize)
        }
        -1 => None,
        c => {
            r.problem(
                &IO_CPU,
                format!("{c}: a CPU number, or -1 for the cycle's CPU"),
            );
            None
        }
    };
    (io_priority, io_cpu)
}

/// `runtime_dir` (if given) and `state_dir` (else the default).
fn directories(r: &mut Reader<'_>) -> (Option<PathBuf>, PathBuf) {
    let runtime_dir = r.has(&RUNTIME_DIR).then(|| {
        let d = r.string(&RUNTIME_DIR);
        if let Err(e) = crate::args::runtime_dir(&d) {
            r.problem(&RUNTIME_DIR, e);
        }
        PathBuf::from(d)
    });
    let state_dir = if r.has(&STATE_DIR) {
        r.directory(&STATE_DIR)
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
