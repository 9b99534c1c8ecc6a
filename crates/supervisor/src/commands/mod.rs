//! The three subcommands. Each returns the process exit code.

mod check;
mod home;
mod run;

use crate::cli::{Cli, Common};
use crate::session::{Session, SessionOptions};
use motion_config::MachineConfig;

pub fn run(c: Cli) -> i32 {
    match c {
        Cli::Check { common } => check::check(&common),
        Cli::Home {
            common,
            axes,
            json,
            parallel,
            timeout_s,
        } => home::home(&common, &axes, json, parallel, timeout_s),
        Cli::Run {
            common,
            duration_s,
            json,
            hlog,
            io_args,
        } => run::run(&common, duration_s, json, hlog.as_deref(), &io_args),
        Cli::Help => 0,
    }
}

/// Loads the machine; prints every problem and returns `None` on error.
fn load(common: &Common) -> Option<(MachineConfig, String)> {
    match motion_config::load(common.config.as_deref()) {
        Ok(x) => Some(x),
        Err(problems) => {
            let source = common
                .config
                .as_ref()
                .map_or("built-in config".to_string(), |p| p.display().to_string());
            eprintln!(
                "motion-supervisor: {} problem{} in {source}:",
                problems.len(),
                if problems.len() == 1 { "" } else { "s" }
            );
            for p in problems {
                eprintln!("  {p}");
            }
            None
        }
    }
}

/// Starts the cycle and the I/O process and waits until it answers; prints
/// why not and returns `None` on failure (everything started is stopped).
fn start(common: &Common, m: MachineConfig, io_args: &[String]) -> Option<Session> {
    let opts = SessionOptions {
        config_path: common.config.clone(),
        service_prefix: prefix(common, &m),
        io_args: io_args.to_vec(),
    };
    let mut session = match Session::start(m, &opts) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("motion-supervisor: {e}");
            return None;
        }
    };
    if let Err(e) = session.wait_io(std::time::Duration::from_secs(10)) {
        eprintln!("motion-supervisor: {e}");
        session.finish();
        return None;
    }
    Some(session)
}

fn prefix(common: &Common, m: &MachineConfig) -> String {
    common
        .service_prefix
        .clone()
        .unwrap_or_else(|| m.supervisor.service_prefix.clone())
}

/// RT thread settings as the operator should read them.
fn rt_lines(f: &crate::session::Finished) -> Vec<String> {
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
    if let Some(s) = f.snapshot.as_deref() {
        out.push(format!(
            "feedback frames: {} answered cycles, {} cycles without a fresh frame \
             ({} answered a command too old to use), {} refused",
            s.frames_received, s.frames_missing, s.frames_late, s.frames_rejected
        ));
    }
    let pct = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{:.1} %", v * 100.0));
    out.push(format!(
        "cpu: motion-supervisor {}, motion-io {} (of one core, over {:.1} s)",
        pct(f.supervisor_cpu),
        pct(f.io_cpu),
        f.wall_s
    ));
    out
}

fn rt_json(f: &crate::session::Finished) -> serde_json::Value {
    let r = f.outcome.as_ref().and_then(|o| o.report.as_ref());
    serde_json::json!({
        "rt": r.map(|r| serde_json::json!({
            "cpu": r.cpu,
            "policy": r.policy.to_string(),
            "priority": r.priority,
            "memory_locked": r.memory_locked,
            "warnings": r.warnings,
        })),
        "warnings": f.warnings,
        "allocations": {
            "system_calls_in_cycle": f.system_calls_in_cycle,
            "pool_allocs_in_cycle": f.pool_allocs_in_cycle,
        },
        "cpu": {"supervisor": f.supervisor_cpu, "io": f.io_cpu, "wall_s": f.wall_s},
        "frames": f.snapshot.as_deref().map(|s| serde_json::json!({
            "received": s.frames_received,
            "missing": s.frames_missing,
            "refused": s.frames_rejected,
            "too_old": s.frames_late,
        })),
    })
}
