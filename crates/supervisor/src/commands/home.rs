use super::{fail, load, options, print_run, run_report};
use crate::cli::HomeArgs;
use crate::session::Session;
use motion_config::MachineConfig;
use motion_control::homing::{home_and_follow, HomeOutcome, HomeRequest};
use motion_control::progress::Progress;
use motion_control::Client;
use motion_report::{print_json, table, AxisResult, ErrorEntry, HomeReport};
use motion_rt::termination as signals;
use std::time::Duration;

/// `home`: the commissioning run (docs/commands.md). It starts the daemon's
/// machinery in this process and homes through the control service, as
/// `motionctl home` does against a running daemon.
pub fn home(a: &HomeArgs) -> i32 {
    let (m, source) = match load(&a.common, a.json) {
        Ok(x) => x,
        Err(code) => return code,
    };
    if let Err(code) = known_axes(a, &m, &source) {
        return code;
    }
    let opts = options(&a.common, &m);
    let mut session = match Session::start(m, &opts) {
        Ok(s) => s,
        Err(e) => return fail(a.json, vec![ErrorEntry::message(e)], 1),
    };
    if let Err(e) = session.wait_io(Duration::from_secs(10)) {
        drop(session);
        return fail(a.json, vec![ErrorEntry::message(e)], 1);
    }
    log::info!(
        "homing {} of {source}{}",
        if a.axes.is_empty() {
            "every axis".to_string()
        } else {
            a.axes.join(", ")
        },
        if a.parallel {
            " in parallel"
        } else {
            " in home order"
        }
    );
    let (rows, mut errors) = home_through_control(&session, a);
    for e in session.poll_children(false) {
        log::warn!("{e}");
    }
    if let Some(sig) = signals::received() {
        errors.push(ErrorEntry::message(format!(
            "signal {sig}: every axis was stopped"
        )));
    }
    let f = session.finish();
    let report = HomeReport {
        axes: rows,
        run: run_report(&f, errors),
    };
    if a.json {
        print_json(&report);
    } else {
        print!("{}", table::axis_results(&report.axes));
        println!();
        print_run(&f, &report.run);
        for e in &report.run.errors {
            log::error!("{}", e.message);
        }
    }
    if let Some(sig) = signals::received() {
        return 128 + sig;
    }
    let homed = !report.axes.is_empty() && report.axes.iter().all(|r| r.succeeded());
    if report.run.errors.is_empty() && homed {
        0
    } else {
        1
    }
}

/// Every axis named on the command line is in the machine (exit code 2
/// otherwise).
fn known_axes(a: &HomeArgs, m: &MachineConfig, source: &str) -> Result<(), i32> {
    for n in &a.axes {
        if m.axis_index(n).is_none() {
            let known: Vec<&str> = m.axes.iter().map(|x| x.name.as_str()).collect();
            return Err(fail(
                a.json,
                vec![ErrorEntry {
                    axis: Some(n.clone()),
                    key: Some("axis".into()),
                    message: format!("no axis {n} in {source} (axes: {})", known.join(", ")),
                    ..ErrorEntry::default()
                }],
                2,
            ));
        }
    }
    Ok(())
}

/// Homes through the session's own control service and follows the homing
/// to its end (a signal stops every axis): the rows, and what went wrong.
fn home_through_control(session: &Session, a: &HomeArgs) -> (Vec<AxisResult>, Vec<ErrorEntry>) {
    let mut client =
        match Client::connect(&session.domain.prefix, Some(&session.domain.runtime_dir)) {
            Ok(c) => c,
            Err(e) => {
                return (
                    Vec::new(),
                    vec![ErrorEntry::message(format!("control service: {e}"))],
                )
            }
        };
    let mut progress = Progress::new();
    let said = std::cell::Cell::new(false);
    let req = HomeRequest {
        axes: a.axes.clone(),
        parallel: a.parallel,
        timeout_s: a.timeout,
    };
    let interrupted = || match signals::received() {
        Some(sig) => {
            if !said.replace(true) {
                log::info!("signal {sig}: stopping every axis");
            }
            true
        }
        None => false,
    };
    match home_and_follow(
        &mut client,
        &req,
        |st, members| progress.show(st, members),
        interrupted,
    ) {
        Ok(HomeOutcome::Done(rows, _)) => (rows, Vec::new()),
        Ok(HomeOutcome::Refused(resp)) => (
            Vec::new(),
            resp.refusal("home", |x| x.accepted == 0 && x.err != 0),
        ),
        Err(e) => (Vec::new(), vec![ErrorEntry::message(e.to_string())]),
    }
}
