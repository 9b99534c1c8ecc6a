use super::{allocations, cpu, fail, load, options, rt_info, rt_lines};
use crate::cli::HomeArgs;
use crate::session::Session;
use motion_control::homing::{home_and_follow, HomeOutcome, HomeRequest};
use motion_control::progress::Progress;
use motion_control::Client;
use motion_report::{print_json, table, ErrorEntry, HomeReport};
use motion_rt::termination as signals;
use std::time::Duration;

/// `home`: the commissioning run of interface.md. It starts the daemon's
/// machinery in this process and homes through the control service, as
/// `motionctl home` does against a running daemon.
pub fn home(a: &HomeArgs) -> i32 {
    let (m, source) = match load(&a.common, a.json) {
        Ok(x) => x,
        Err(code) => return code,
    };
    for n in &a.axes {
        if m.axis_index(n).is_none() {
            let known: Vec<&str> = m.axes.iter().map(|x| x.name.as_str()).collect();
            return fail(
                a.json,
                vec![ErrorEntry {
                    axis: Some(n.clone()),
                    key: Some("axis".into()),
                    message: format!("no axis {n} in {source} (axes: {})", known.join(", ")),
                    ..ErrorEntry::default()
                }],
                2,
            );
        }
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
    let mut errors = Vec::new();
    let mut rows = Vec::new();
    match Client::connect(&session.domain.prefix, Some(&session.domain.runtime_dir)) {
        Err(e) => errors.push(ErrorEntry::message(format!("control service: {e}"))),
        Ok(mut client) => {
            let mut progress = Progress::new();
            let said = std::cell::Cell::new(false);
            let req = HomeRequest {
                axes: a.axes.clone(),
                parallel: a.parallel,
                timeout_s: a.timeout,
            };
            match home_and_follow(
                &mut client,
                &req,
                |st, members| progress.show(st, members),
                || match signals::received() {
                    Some(sig) => {
                        if !said.replace(true) {
                            log::info!("signal {sig}: stopping every axis");
                        }
                        true
                    }
                    None => false,
                },
            ) {
                Ok(HomeOutcome::Done(r, _)) => rows = r,
                Ok(HomeOutcome::Refused(resp)) => {
                    errors.push(ErrorEntry::message(format!(
                        "home refused: {}",
                        resp.message_text()
                    )));
                    for ans in resp.answers() {
                        if ans.accepted == 0 && ans.err != 0 {
                            errors.push(ErrorEntry {
                                axis: Some(motion_control::get_str(&ans.name)),
                                key: None,
                                err: Some(ans.err),
                                exerr: Some(ans.exerr),
                                message: motion_control::reason_text(ans.reason).into(),
                            });
                        }
                    }
                }
                Err(e) => errors.push(ErrorEntry::message(e.to_string())),
            }
        }
    }
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
        latency: f.latency.clone(),
        io: f.io.clone(),
        rt: rt_info(&f),
        warnings: f.warnings.clone(),
        allocations: allocations(&f),
        cpu: cpu(&f),
        errors: errors.clone(),
    };
    if a.json {
        print_json(&report);
    } else {
        print!("{}", table::axis_results(&report.axes));
        println!();
        print!("{}", report.latency.table());
        for l in rt_lines(&f) {
            println!("{l}");
        }
        for e in &errors {
            log::error!("{}", e.message);
        }
    }
    if let Some(sig) = signals::received() {
        return 128 + sig;
    }
    if !errors.is_empty() || report.axes.is_empty() || !report.axes.iter().all(|r| r.succeeded()) {
        1
    } else {
        0
    }
}
