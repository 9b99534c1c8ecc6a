use super::{fail, load, options, print_run, run_report};
use crate::cli::RunArgs;
use crate::session::Session;
use motion_report::{print_json, ErrorEntry};
use motion_rt::termination as signals;
use std::time::{Duration, Instant};

/// `run`: the daemon. Serves the control and status services until
/// SIGINT/SIGTERM (or `--duration`); spawned I/O processes that end are
/// started again; then every axis is stopped and the summary printed.
pub fn run(a: &RunArgs) -> i32 {
    let (m, source) = match load(&a.common, a.json) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let mut opts = options(&a.common, &m);
    opts.io_args = a.io_args.clone();
    opts.hlog_file = a.hlog.clone();
    opts.no_control_plane = a.no_control_plane;
    let mut session = match Session::start(m, &opts) {
        Ok(s) => s,
        Err(e) => return fail(a.json, vec![ErrorEntry::message(e)], 1),
    };
    log::info!(
        "running {source} at {} µs, service prefix {:?}, session file {}; SIGINT/SIGTERM to stop",
        session.machine.supervisor.cycle_us,
        session.domain.prefix,
        motion_ipc::session_path(&session.domain.runtime_dir, &session.domain.prefix).display()
    );
    for w in &session.warnings {
        log::warn!("{w}");
    }
    let started = Instant::now();
    let mut last_line = Instant::now();
    let mut errors = Vec::new();
    loop {
        std::thread::sleep(Duration::from_millis(50));
        if let Some(sig) = signals::received() {
            log::info!("signal {sig}: stopping every axis");
            break;
        }
        if a.duration
            .is_some_and(|d| started.elapsed().as_secs_f64() >= d)
        {
            break;
        }
        for e in session.poll_children(true) {
            log::warn!("{e}");
        }
        if let Some(e) = session.check_alive() {
            log::error!("{e}");
            errors.push(ErrorEntry::message(e));
            break;
        }
        if last_line.elapsed() >= Duration::from_secs(10) {
            last_line = Instant::now();
            let s = session.hub.lock().since_start.summary();
            log::info!(
                "{} cycles, {} deadline misses, wake-up p99 {:.1} µs max {:.1} µs, round trip p99 {:.1} µs",
                s.cycles,
                s.deadline_misses,
                s.wakeup_us.p99,
                s.wakeup_us.max,
                s.io_roundtrip_us.p99
            );
        }
    }
    let f = session.finish();
    let report = run_report(&f, errors);
    if a.json {
        print_json(&report);
    } else {
        print_run(&f, &report);
    }
    if report.errors.is_empty() {
        0
    } else {
        1
    }
}
