//! `motion-io`: the drive-I/O process of `motion-supervisor`.
//!
//! Every cycle the supervisor publishes a `CommandFrame` on
//! `{prefix}/command` and wakes us on `{prefix}/command_ready`; we apply it to
//! the backend and answer with a `FeedbackFrame` (`answers_sequence` = the
//! command's sequence) on `{prefix}/feedback` plus a wake-up on
//! `{prefix}/feedback_ready`. See `motion-io --help` for the command line,
//! [`Backend`] for what a drive backend must guarantee and [`run`]
//! for the loop, the watchdog and the signal handling.
//!
//! Exit codes: 0 after SIGINT/SIGTERM or when the supervisor is gone
//! (`--exit-with-supervisor`); 1 on an IPC start-up failure, an EtherCAT
//! start-up failure (the message names the SubDevice and the object or
//! state) or no supervisor within 10 s (`--exit-with-supervisor`); 2 on a
//! command-line or config mistake.

use motion_io::cli;
mod ethercat;
mod ethercat_log;
mod run;
mod say;
mod scan;
mod sim;
mod stall;

use std::path::Path;
use std::time::{Duration, Instant};

use clap::Parser;
use motion_frames::backend::Backend;
use motion_ipc::{cleanup_domain, Domain, IoPorts, IpcError};
use motion_rt::{enter_realtime, RtConfig};

use crate::cli::{BackendKind, Options};
use crate::say::Say;
use crate::sim::SimBackend;

/// How long a spawned motion-io (`--exit-with-supervisor`) waits for its
/// supervisor before it gives up.
const SUPERVISOR_WAIT: Duration = Duration::from_secs(10);

fn main() {
    let code = real_main();
    // what is still queued for stderr, unless stderr is blocked
    say::flush(Duration::from_secs(1));
    std::process::exit(code);
}

fn real_main() -> i32 {
    motion_rt::logging::init("motion-io");
    // before going real-time: the writer thread stays SCHED_OTHER
    say::start_writer();
    let opts = match Options::try_parse() {
        Ok(o) => o,
        Err(e) => {
            let code = match e.kind() {
                clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion => 0,
                _ => 2,
            };
            let _ = e.print();
            return code;
        }
    };
    let say = Say { quiet: opts.quiet };
    if opts.quiet {
        log::set_max_level(log::LevelFilter::Warn);
    }
    if let Some(cli::Sub::Scan { interface, json }) = &opts.command {
        return scan::run(interface, *json);
    }

    let (cfg, label) = match motion_config::load(opts.config.as_deref()) {
        Ok(c) => c,
        Err(problems) => {
            for p in &problems {
                log::error!("config: {p}");
            }
            return 2;
        }
    };
    let io = match which_io(&cfg, opts.io.as_deref()) {
        Ok(k) => k,
        Err(e) => {
            log::error!("{e}");
            return 2;
        }
    };
    let io_name = cfg.ios[io].name.clone();
    let prefix = opts
        .service_prefix
        .clone()
        .unwrap_or_else(|| cfg.supervisor.service_prefix.clone());
    let runtime_dir = motion_ipc::runtime_dir_or_default(
        opts.runtime_dir
            .as_deref()
            .or(cfg.supervisor.runtime_dir.as_deref()),
    );
    if let Err(e) = motion_rt::termination::install() {
        say.always(format_args!("error: {e}"));
        return 1;
    }
    stall::install();
    apply_rt(&opts, say);

    let mine = cfg.only_io(io);
    let kind = opts
        .backend
        .unwrap_or_else(|| BackendKind::of(cfg.ios[io].backend));
    if kind != BackendKind::Ethercat && opts.interface.is_some() {
        log::error!("--interface is for --backend ethercat");
        return 2;
    }
    let mut backend: Box<dyn Backend> = match kind {
        BackendKind::Sim => Box::new(SimBackend::new(&mine)),
        BackendKind::Ethercat => match start_ethercat(&cfg, io, &opts, say) {
            Ok(b) => Box::new(b),
            Err(code) => return code,
        },
    };
    let settings = run::Settings {
        cycle_ns: cfg.supervisor.cycle_ns(),
        watchdog_cycles: cfg.supervisor.io_watchdog_cycles,
        spin: opts.spin,
        exit_with_supervisor: opts.exit_with_supervisor,
        say,
        prefix: prefix.clone(),
        runtime_dir: runtime_dir.clone(),
    };
    loop {
        let domain = match wait_for_supervisor(&settings, &runtime_dir) {
            Ok(d) => d,
            Err(code) => {
                if let Some(s) = backend.summary() {
                    say.notice(format_args!("{s}"));
                }
                return code;
            }
        };
        let outcome = serve(&domain, &io_name, backend.as_mut(), &settings, &label);
        // node and ports are gone: tidy the domain (dead peers), and the
        // session file of a supervisor that was killed
        let report = cleanup_domain(&domain);
        domain.withdraw_if_dead();
        if let Some(e) = &report.error {
            say.always(format_args!("cleanup: {e}"));
        }
        let code = match outcome {
            Ok(run::Outcome::Rejoin) => continue,
            Ok(o) => o.exit_code(),
            Err(code) => code,
        };
        if let Some(s) = backend.summary() {
            say.notice(format_args!("{s}"));
        }
        return code;
    }
}

/// The index of the I/O process this process serves: the one `--io`
/// names, or the config's only one.
fn which_io(cfg: &motion_config::MachineConfig, name: Option<&str>) -> Result<usize, String> {
    let known = || {
        let names: Vec<&str> = cfg.ios.iter().map(|i| i.name.as_str()).collect();
        names.join(", ")
    };
    match (name, cfg.ios.len()) {
        (Some(name), _) => cfg.io_index(name).ok_or_else(|| {
            format!(
                "--io {name}: the config has no such I/O process (configured: {})",
                known()
            )
        }),
        (None, 1) => Ok(0),
        (None, _) => Err(format!(
            "the config has several I/O processes ({}): say which one with --io NAME",
            known()
        )),
    }
}

/// Starts the EtherCAT bus for the axes of I/O process `io` (blocking
/// until every SubDevice is in OP) and logs the start-up report; on
/// failure logs why and returns the exit code.
fn start_ethercat(
    cfg: &motion_config::MachineConfig,
    io: usize,
    opts: &Options,
    say: Say,
) -> Result<ethercat::EthercatIo, i32> {
    let names = cfg
        .axes_of(io)
        .iter()
        .map(|&a| cfg.axes[a].name.clone())
        .collect();
    let started = motion_config::EthercatBus::for_io(
        cfg,
        io,
        opts.interface.as_deref(),
        opts.cpu,
        opts.priority,
    )
    .map_err(|message| ethercat::StartError { code: 2, message })
    .and_then(|(bus, map)| {
        say.info(format_args!(
            "EtherCAT: starting the bus on {} (cycle {} us, dc {:?}, SM watchdog {} ms)",
            bus.keys.interface,
            bus.cycle().as_micros(),
            bus.keys.dc,
            bus.sm_watchdog().as_millis()
        ));
        ethercat::EthercatIo::start(bus, map, names, say, &cfg.ios[io].name)
    });
    match started {
        Ok(b) => {
            for line in b.report_lines() {
                say.notice(format_args!("{line}"));
            }
            Ok(b)
        }
        Err(e) => {
            say.always(format_args!("error: {}", e.message));
            Err(e.code)
        }
    }
}

/// Joins the domain of the supervisor running under the prefix, waiting
/// for one to appear (with `--exit-with-supervisor`, at most 10 s).
fn wait_for_supervisor(s: &run::Settings, runtime_dir: &Path) -> Result<Domain, i32> {
    let start = Instant::now();
    let mut said = false;
    loop {
        match Domain::join(&s.prefix, Some(runtime_dir)) {
            Ok(d) => return Ok(d),
            Err(IpcError::NoSupervisor(why)) => {
                if !said {
                    s.say
                        .info(format_args!("waiting for the supervisor: {why}"));
                    said = true;
                }
                if s.exit_with_supervisor && start.elapsed() > SUPERVISOR_WAIT {
                    s.say.always(format_args!(
                        "error: no supervisor within {} s: {why}; exiting",
                        SUPERVISOR_WAIT.as_secs()
                    ));
                    return Err(1);
                }
            }
            Err(e) => {
                // An unsafe or malformed session file is never trusted.
                s.say.always(format_args!("error: {e}"));
                return Err(1);
            }
        }
        if motion_rt::termination::received().is_some() {
            return Err(0);
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Creates node and ports in `domain`, runs the loop, drops them again.
fn serve(
    domain: &Domain,
    io_name: &str,
    backend: &mut dyn Backend,
    s: &run::Settings,
    label: &str,
) -> Result<run::Outcome, i32> {
    let say = s.say;
    let node = match domain.create_node("motion-io") {
        Ok(n) => n,
        Err(e) => {
            say.always(format_args!("error: {e}"));
            return Err(1);
        }
    };
    // The session file may appear a moment before the services.
    let until = Instant::now() + SUPERVISOR_WAIT;
    let mut ports = loop {
        match IoPorts::open(&node, domain, io_name) {
            Ok(p) => break p,
            Err(e) if e.is_no_supervisor() && Instant::now() < until => {
                std::thread::sleep(Duration::from_millis(20));
            }
            Err(e) => {
                say.always(format_args!("error: I/O process {io_name}: {e}"));
                return if e.is_no_supervisor() {
                    Ok(run::Outcome::Rejoin)
                } else {
                    Err(1)
                };
            }
        }
    };
    let names = backend.axis_names();
    say.info(format_args!(
        "I/O process {io_name}: backend {}, {} {} ({}), supervisor pid {} (prefix {:?}), \
         cycle {} us, watchdog {} cycles, {}, config {label}",
        backend.name(),
        backend.axis_count(),
        if backend.axis_count() == 1 {
            "axis"
        } else {
            "axes"
        },
        names.join(", "),
        domain.pid,
        domain.prefix,
        s.cycle_ns / 1000,
        s.watchdog_cycles,
        if s.spin {
            "busy-polling"
        } else {
            "event wake-up"
        },
    ));
    // joined: what it says from now on goes to the supervisor's stderr
    // directly, not through the pipe a spawning supervisor reads (lost if
    // the supervisor is killed)
    motion_rt::logging::direct_stderr();
    let outcome = run::run(&mut ports, backend, s, &domain.id);
    drop(ports);
    drop(node);
    // Outliving the supervisor, this was the domain's last node: iceoryx2
    // would leave the node counter behind (removed only when no live node
    // remains, so with the supervisor running this changes nothing).
    let _ = motion_ipc::cleanup_domain(domain);
    Ok(outcome)
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
