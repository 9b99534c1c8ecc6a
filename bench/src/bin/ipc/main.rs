//! IPC bench: the command/feedback round trip through iceoryx2 between two
//! processes, measured as the supervisor's cycle measures it, with
//!
//! * (a) a real `motion-io --backend sim` waiting on the event,
//! * (b) the same with `--spin` (busy-polling on its own CPU),
//! * (c) a bare iceoryx2 echo of the same payload sizes (this binary re-run
//!   with `--role echo`), event-waiting and spinning.
//!
//! One message per period, not back to back. See `bench/README.md`.
//!
//! This file is the sequence — the process's role, the stage (motion-io,
//! real-time settings, a temporary directory), one [`run_mode`] per mode,
//! the report — and the modules are its steps: [`cli`] and [`mode`] what to
//! run, [`run_mode`] one mode, measured by [`measure`] through an
//! [`exchange`] ([`bare`] for the bare modes), [`report`] the table, and
//! [`echo`] the peer this binary also is.

mod bare;
mod cli;
mod echo;
mod exchange;
mod measure;
mod mode;
mod report;
mod run_mode;

use cli::Opts;
use measure::Measured;
use mode::Mode;
use motion_bench::proc;
use motion_bench::sys;
use motion_ipc::Domain;
use run_mode::run_mode;
use std::path::PathBuf;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if echo::wanted(&args) {
        std::process::exit(echo::main());
    }
    std::process::exit(bench_main());
}

fn bench_main() -> i32 {
    let o = Opts::parse_checked();
    proc::install_stop_handler();
    let io_bin =
        o.io.clone()
            .or_else(|| std::env::var_os("MOTION_IO_BIN").map(PathBuf::from))
            .or_else(|| sys::sibling_exe("motion-io"));
    if o.modes.iter().any(|m| !m.bare()) && !io_bin.as_deref().is_some_and(sys::is_executable) {
        eprintln!(
            "ipc: motion-io not found next to this binary; build it first: \
             `cargo build --release --workspace --bins` (same CARGO_TARGET_DIR), or pass --io PATH"
        );
        return 1;
    }
    for w in sys::enter_rt(None, None) {
        eprintln!("ipc: warning: {w}");
    }
    // as the supervisor does by default (cpu_dma_latency_us = 0)
    let _idle = match o.cpu_dma_latency {
        us if us >= 0 => match sys::hold_cpu_dma_latency(us) {
            Ok(f) => Some(f),
            Err(e) => {
                eprintln!("ipc: warning: {e}");
                None
            }
        },
        _ => None,
    };
    let others = sys::other_rt_tasks();
    for t in &others {
        eprintln!("ipc: WARNING: another real-time thread is running: {t}");
    }

    let pid = std::process::id();
    let tmp = std::env::temp_dir().join(format!("motion-bench-ipc-{pid}"));
    if let Err(e) = std::fs::create_dir_all(&tmp) {
        eprintln!("ipc: cannot create {}: {e}", tmp.display());
        return 1;
    }
    let mut results: Vec<(Mode, Measured)> = Vec::new();
    let mut failures: Vec<String> = Vec::new();
    let mut leftovers: Vec<String> = Vec::new();
    for (k, &mode) in o.modes.iter().enumerate() {
        if proc::stop_requested() {
            break;
        }
        let prefix = format!("mbi{pid}m{k}");
        eprintln!(
            "ipc: {} ({}): {} messages at {} µs ...",
            mode.label(),
            mode.key(),
            o.count,
            o.period_us
        );
        match run_mode(&o, mode, &prefix, io_bin.as_deref(), &tmp) {
            Ok(m) => results.push((mode, m)),
            Err(e) => {
                eprintln!("ipc: {}: FAILED: {e}", mode.key());
                failures.push(format!("{}: {e}", mode.key()));
            }
        }
        let left = Domain::shm_files_of_prefix(&prefix);
        if !left.is_empty() {
            leftovers.push(format!("{prefix}: {}", left.join(", ")));
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);

    report::print(&o, &results, &others, &leftovers);
    if proc::stop_requested() {
        eprintln!("ipc: interrupted");
        return 130;
    }
    if failures.is_empty() {
        0
    } else {
        for f in &failures {
            println!("ipc: FAILED: {f}");
        }
        1
    }
}
