//! IPC bench: the command/feedback round trip through iceoryx2 between two
//! processes, measured as the supervisor's cycle measures it, with
//!
//! * (a) a real `motion-io --backend sim` waiting on the event,
//! * (b) the same with `--spin` (busy-polling on its own CPU),
//! * (c) a bare iceoryx2 echo of the same payload sizes (this binary re-run
//!   with `--role echo`, see [`echo`]), event-waiting and spinning.
//!
//! One message per period, not back to back. See `bench/README.md`. The
//! sequence: the stage (motion-io, real-time settings), one [`run_mode`] per
//! mode, the [`report`].

mod cli;
mod echo;
mod exchange;
mod measure;
mod mode;
mod report;
mod run_mode;

use cli::Opts;
use motion_bench::outcome::{self, Bench};
use motion_bench::proc;
use motion_bench::{bins, host};
use motion_ipc::Domain;
use std::path::PathBuf;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if echo::wanted(&args) {
        std::process::exit(echo::main());
    }
    let o = Opts::parse_checked();
    outcome::main("ipc", || run(&o))
}

fn run(o: &Opts) -> Result<i32, String> {
    let io_bin = (o.io.clone())
        .or_else(|| std::env::var_os("MOTION_IO_BIN").map(PathBuf::from))
        .or_else(|| bins::beside_this_exe("motion-io"));
    if o.modes.iter().any(|m| !m.bare()) && !io_bin.as_deref().is_some_and(bins::is_executable) {
        return Err(
            "motion-io not found next to this binary; build it first: `cargo build \
                    --release --workspace --bins` (same CARGO_TARGET_DIR), or pass --io PATH"
                .into(),
        );
    }
    let b = Bench::start("ipc", None)?;
    for w in host::enter_rt(None, None) {
        eprintln!("ipc: warning: {w}");
    }
    // as the supervisor does by default (cpu_dma_latency_us = 0)
    let us = o.cpu_dma_latency;
    let _idle = (us >= 0)
        .then(|| motion_rt::hold_cpu_dma_latency(us).map_err(|e| eprintln!("ipc: warning: {e}")))
        .and_then(Result::ok);
    let (mut results, mut failures, mut leftovers) = (Vec::new(), Vec::new(), Vec::new());
    for (k, &mode) in o.modes.iter().enumerate() {
        if proc::stop_requested() {
            break;
        }
        let prefix = format!("mbi{}m{k}", std::process::id());
        let (label, key) = (mode.label(), mode.key());
        eprintln!(
            "ipc: {label} ({key}): {} messages at {} µs ...",
            o.count, o.cycle.period_us
        );
        match run_mode::run_mode(o, mode, &prefix, io_bin.as_deref(), &b.tmp) {
            Ok(m) => results.push((mode, m)),
            Err(e) => {
                eprintln!("ipc: {key}: FAILED: {e}");
                failures.push(format!("{key}: {e}"));
            }
        }
        let left = Domain::shm_files_of_prefix(&prefix);
        if !left.is_empty() {
            leftovers.push(format!("{prefix}: {}", left.join(", ")));
        }
    }
    report::print(o, &b, &results, &leftovers);
    Ok(b.end(&[], proc::stop_requested(), &failures, false))
}
