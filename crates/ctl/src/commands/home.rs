use super::{client_error, fail, signal_code, EXIT_FAILED, EXIT_OK};
use crate::cli::HomeArgs;
use motion_control::homing::{home_and_follow, HomeOutcome, HomeRequest};
use motion_control::progress::Progress;
use motion_control::*;
use motion_report::{print_json, table, AcceptedReport, CtlHomeReport};
use std::time::Duration;

/// `home [AXIS]... [--json] [--no-wait] [--timeout S] [--parallel]`.
pub fn home(client: &mut Client, a: &HomeArgs) -> i32 {
    let req = HomeRequest {
        axes: a.axes.clone(),
        parallel: a.parallel,
        timeout_s: a.timeout.unwrap_or(0.0),
    };
    if a.no_wait {
        let mut r = ControlRequest::zeroed();
        r.kind = REQ_HOME;
        r.flags = if a.parallel { FLAG_PARALLEL } else { 0 };
        r.timeout_s = req.timeout_s;
        r.set_axes(&a.axes);
        return match client.call(&r, Duration::from_secs(3)) {
            Err(e) => client_error(a.json, &e),
            Ok(resp) if resp.result != RESULT_ACCEPTED => refused(a.json, &resp),
            Ok(resp) => {
                let names: Vec<String> = resp.answers().iter().map(|x| get_str(&x.name)).collect();
                if a.json {
                    print_json(&AcceptedReport { accepted: names });
                } else {
                    println!("homing started: {}", names.join(" "));
                }
                EXIT_OK
            }
        };
    }
    let mut progress = Progress::new();
    let outcome = home_and_follow(
        client,
        &req,
        |st, members| progress.show(st, members),
        || motion_rt::termination::received().is_some(),
    );
    match outcome {
        Err(e) => client_error(a.json, &e),
        Ok(HomeOutcome::Refused(resp)) => refused(a.json, &resp),
        Ok(HomeOutcome::Done(rows, _)) => {
            let ok = !rows.is_empty() && rows.iter().all(|r| r.succeeded());
            if a.json {
                print_json(&CtlHomeReport {
                    axes: rows,
                    errors: Vec::new(),
                });
            } else {
                print!("{}", table::axis_results(&rows));
            }
            match signal_code() {
                Some(code) => code,
                None if ok => EXIT_OK,
                None => EXIT_FAILED,
            }
        }
    }
}

/// A refused request: why, per axis where there is a reason.
fn refused(json: bool, resp: &ControlResponse) -> i32 {
    fail(
        json,
        resp.refusal("home", |x| x.reason != REASON_NONE),
        EXIT_FAILED,
    )
}
