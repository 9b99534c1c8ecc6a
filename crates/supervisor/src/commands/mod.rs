//! The three subcommands. Each returns the process exit code:
//! 0 success, 1 homing did not succeed or a run-time failure, 2 a bad
//! configuration or argument, 128+N ended by signal N.

mod check;
mod home;
mod run;

use crate::cli::{Cli, Command, Common};
use crate::session::{Finished, SessionOptions};
use motion_config::{MachineConfig, Problem};
use motion_report::{Allocations, CpuUse, ErrorEntry, RtInfo, RunReport};

/// How a command fails: a refused command line, and every other failure.
pub use motion_report::errors::{argument_error, fail};

pub fn run(c: Cli) -> i32 {
    match c.command {
        Command::Check(a) => check::check(&a),
        Command::Home(a) => home::home(&a),
        Command::Run(a) => run::run(&a),
    }
}

/// Problems as the JSON error entries (docs/commands.md, "JSON").
pub fn entries(problems: &[Problem]) -> Vec<ErrorEntry> {
    problems.iter().map(ErrorEntry::from).collect()
}

/// Loads the machine; on error reports every problem and returns exit code 2.
fn load(common: &Common, json: bool) -> Result<(MachineConfig, String), i32> {
    motion_config::load(common.config.as_deref()).map_err(|problems| {
        if !json {
            let source = common
                .config
                .as_ref()
                .map_or("built-in config".to_string(), |p| p.display().to_string());
            log::error!(
                "{} problem{} in {source}:",
                problems.len(),
                if problems.len() == 1 { "" } else { "s" }
            );
        }
        fail(json, entries(&problems), 2)
    })
}

fn options(common: &Common, m: &MachineConfig) -> SessionOptions {
    SessionOptions {
        config_path: common.config.clone(),
        service_prefix: common
            .service_prefix
            .clone()
            .unwrap_or_else(|| m.supervisor.service_prefix.clone()),
        runtime_dir: common.runtime_dir.clone(),
        io_args: Vec::new(),
        hlog_file: None,
        no_control_plane: false,
    }
}

/// RT thread settings as the operator should read them.
fn rt_lines(f: &Finished) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(r) = f.outcome.as_ref().and_then(|o| o.report.as_ref()) {
        out.push(format!("real-time thread: {r}"));
    }
    for w in &f.warnings {
        out.push(format!("  warning: {w}"));
    }
    out.push(format!(
        "allocations in the cycle after warm-up: {} system-allocator calls, {} served by the RT pool",
        f.system_calls_in_cycle, f.pool_allocs_in_cycle
    ));
    for io in &f.io {
        out.push(format!(
            "I/O process {}: {} answered cycles, {} without a fresh answer ({} too old, {} \
             refused); gaps 1: {}, 2-3: {}, 4-10: {}, >10: {}, longest {:.1} ms; attached {} \
             time(s)",
            io.name,
            io.frames_received,
            io.frames_missing,
            io.frames_too_old,
            io.frames_refused,
            io.gaps.one,
            io.gaps.two_to_three,
            io.gaps.four_to_ten,
            io.gaps.over_ten,
            io.longest_gap_ms,
            io.attachments
        ));
    }
    let pct = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{:.1} %", v * 100.0));
    let ios: Vec<String> = f
        .io_cpu
        .iter()
        .map(|(n, c)| format!("motion-io {n} {}", pct(*c)))
        .collect();
    out.push(format!(
        "cpu: motion-supervisor {}{}{} (of one core, over {:.1} s)",
        pct(f.supervisor_cpu),
        if ios.is_empty() { "" } else { ", " },
        ios.join(", "),
        f.wall_s
    ));
    out
}

/// What `run --json` reports of a finished session, and `home --json`
/// after its rows.
fn run_report(f: &Finished, errors: Vec<ErrorEntry>) -> RunReport {
    RunReport {
        latency: f.latency.clone(),
        io: f.io.clone(),
        rt: f
            .outcome
            .as_ref()
            .and_then(|o| o.report.as_ref())
            .map(|r| RtInfo {
                cpu: r.cpu,
                policy: r.policy.to_string(),
                priority: r.priority,
                memory_locked: r.memory_locked,
                warnings: r.warnings.clone(),
            }),
        warnings: f.warnings.clone(),
        allocations: Allocations {
            system_calls_in_cycle: f.system_calls_in_cycle,
            pool_allocs_in_cycle: f.pool_allocs_in_cycle,
        },
        cpu: CpuUse {
            supervisor: f.supervisor_cpu,
            io: f.io_cpu.clone(),
            wall_s: f.wall_s,
        },
        errors,
    }
}

/// The same as text: the latency table and the real-time lines.
fn print_run(f: &Finished, report: &RunReport) {
    print!("{}", report.latency.table());
    for l in rt_lines(f) {
        println!("{l}");
    }
}
