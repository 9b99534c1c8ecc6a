//! `motion-io`: the drive-I/O process of `motion-supervisor`.
//!
//! Every cycle the supervisor publishes a `CommandFrame` on
//! `{prefix}/command` and wakes us on `{prefix}/command_ready`; we apply it to
//! the backend and answer with a `FeedbackFrame` (`answers_sequence` = the
//! command's sequence) on `{prefix}/feedback` plus a wake-up on
//! `{prefix}/feedback_ready`. See `motion-io --help` for the command line,
//! [`backend::Backend`] for what a drive backend must guarantee and [`run`]
//! for the loop, the watchdog and the signal handling.
//!
//! Exit codes: 0 after SIGINT/SIGTERM or when the supervisor is gone
//! (`--exit-with-supervisor`); 1 on an IPC start-up failure or no supervisor
//! within 10 s (`--exit-with-supervisor`); 2 on a command-line or config
//! mistake.

mod backend;
mod cli;
mod run;
mod say;
mod sim;

use std::io::Write;

use motion_frames::ipc::cleanup_domain;
use motion_frames::{IoPorts, IpcConfig};
use motion_rt::{enter_realtime, RtConfig};

use crate::backend::Backend;
use crate::cli::{BackendKind, Options, Parsed, USAGE};
use crate::say::Say;
use crate::sim::SimBackend;

fn main() {
    std::process::exit(real_main());
}

fn real_main() -> i32 {
    let opts = match cli::parse(std::env::args().skip(1)) {
        Ok(Parsed::Run(o)) => o,
        Ok(Parsed::Help) => {
            let _ = writeln!(std::io::stdout(), "{USAGE}");
            return 0;
        }
        Err(e) => {
            say::line(format_args!("{e}\n{USAGE}"));
            return 2;
        }
    };
    let say = Say { quiet: opts.quiet };

    let (cfg, label) = match motion_config::load(opts.config.as_deref()) {
        Ok(c) => c,
        Err(problems) => {
            for p in &problems {
                say::line(format_args!("config: {p}"));
            }
            return 2;
        }
    };
    let prefix = opts
        .service_prefix
        .clone()
        .unwrap_or_else(|| cfg.supervisor.service_prefix.clone());
    let ipc = IpcConfig::new(prefix);
    if let Err(e) = ipc.iceoryx2_config() {
        say.always(format_args!("{e}"));
        return 2;
    }
    if let Err(e) = motion_rt::termination::install() {
        say.always(format_args!("error: {e}"));
        return 1;
    }
    apply_rt(&opts, say);

    let mut backend: Box<dyn Backend> = match opts.backend {
        BackendKind::Sim => Box::new(SimBackend::new(&cfg)),
    };
    let settings = run::Settings {
        cycle_ns: cfg.supervisor.cycle_ns(),
        watchdog_cycles: cfg.supervisor.io_watchdog_cycles,
        spin: opts.spin,
        exit_with_supervisor: opts.exit_with_supervisor,
        say,
    };

    let code = serve(&ipc, backend.as_mut(), &settings, &label);

    // node and ports are gone: tidy the domain (dead peers, and the
    // node-counter segment if nobody is left)
    let report = cleanup_domain(&ipc);
    match &report.error {
        Some(e) => say.always(format_args!("cleanup: {e}")),
        None => say.info(format_args!("iceoryx2 domain on exit: {report}")),
    }
    code
}

/// Creates node and ports, runs the loop, drops them again. Returns the
/// exit code.
fn serve(ipc: &IpcConfig, backend: &mut dyn Backend, s: &run::Settings, label: &str) -> i32 {
    let say = s.say;
    let node = match ipc.create_node("motion-io") {
        Ok(n) => n,
        Err(e) => {
            say.always(format_args!("error: {e}"));
            return 1;
        }
    };
    let mut ports = match IoPorts::create(&node, &ipc.prefix) {
        Ok(p) => p,
        Err(e) => {
            say.always(format_args!("error: {e}"));
            return 1;
        }
    };
    let names = backend.axis_names();
    say.info(format_args!(
        "backend {}, {} {} ({}), service prefix {:?}, cycle {} us, watchdog {} cycles, {}, \
         config {label}",
        backend.name(),
        backend.axis_count(),
        if backend.axis_count() == 1 {
            "axis"
        } else {
            "axes"
        },
        names.join(", "),
        ipc.prefix,
        s.cycle_ns / 1000,
        s.watchdog_cycles,
        if s.spin {
            "busy-polling"
        } else {
            "event wake-up"
        },
    ));
    let outcome = run::run(&mut ports, backend, s);
    drop(ports);
    drop(node);
    outcome.exit_code()
}

/// `--cpu` / `--priority`: optional, never fatal.
fn apply_rt(opts: &Options, say: Say) {
    match (opts.cpu, opts.priority) {
        (None, None) => {}
        (cpu, Some(priority)) => {
            let report = enter_realtime(&RtConfig {
                cpu,
                priority,
                lock_memory: true,
                prefault_stack: 64 * 1024,
            });
            for w in &report.warnings {
                say.always(format_args!("rt: warning: {w}"));
            }
            let summary = report.to_string();
            say.info(format_args!(
                "rt: {}",
                summary.lines().next().unwrap_or_default()
            ));
            if opts.spin {
                say.always(format_args!(
                    "rt: warning: --spin under SCHED_FIFO can trigger the kernel's RT \
                     throttling (stalls of tens of ms, also on other CPUs); prefer --spin \
                     without --priority"
                ));
            }
        }
        (Some(cpu), None) => match pin(cpu) {
            Ok(()) => say.info(format_args!("rt: pinned to cpu {cpu}, SCHED_OTHER")),
            Err(e) => say.always(format_args!("rt: warning: cpu affinity {cpu}: {e}")),
        },
    }
}

/// Pins the process to `cpu` without touching the scheduling policy.
fn pin(cpu: usize) -> Result<(), String> {
    use nix::sched::{sched_setaffinity, CpuSet};
    use nix::unistd::Pid;
    let mut set = CpuSet::new();
    set.set(cpu).map_err(|e| format!("{e} (no such CPU)"))?;
    sched_setaffinity(Pid::from_raw(0), &set).map_err(|e| {
        let cpus = std::thread::available_parallelism().map_or(0, |n| n.get());
        format!("{e} (is CPU {cpu} online? this process may use {cpus} CPUs)")
    })
}
