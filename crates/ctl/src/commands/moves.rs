//! `move AXIS (--to P | --by D) [--speed V] [--accel A] [--decel D]
//! [--no-wait] [--json]` (MAM; the flags are the engine's
//! `MoveSpec`, `spec_args.rs`): waits like `home`; exit 0 only when every
//! axis ended at its target.

use super::{client_error, fail, signal_code, EXIT_FAILED, EXIT_OK};
use crate::cli::MoveArgs;
use motion_control::follow::{follow, followed, Followed};
use motion_control::progress::Progress;
use motion_control::*;
use motion_report::{print_json, AcceptedReport, MotionReport, MotionRow};
use std::time::Duration;

/// How long a move may take before `motionctl` gives up following it (the
/// move itself goes on: stop it with `stop`).
const FOLLOW_WALL: Duration = Duration::from_secs(86_400);

pub fn move_axis(client: &mut Client, a: &MoveArgs) -> i32 {
    let resp = match client.operate(std::slice::from_ref(&a.axis), Operation::Move(a.spec.spec)) {
        Ok(r) => r,
        Err(e) => return op_error(a.json, "move", &e),
    };
    if a.no_wait {
        let names: Vec<String> = resp.answers().iter().map(|x| get_str(&x.name)).collect();
        if a.json {
            print_json(&AcceptedReport { accepted: names });
        } else {
            println!("move started: {}", names.join(" "));
        }
        return EXIT_OK;
    }
    let mut progress = Progress::new();
    let outcome = follow(
        client,
        &followed(&resp),
        resp.cycle,
        FOLLOW_WALL,
        |st, members| progress.show_motion(st, members),
        || motion_rt::termination::received().is_some(),
    );
    match outcome {
        Err(e) => client_error(a.json, &e),
        Ok((rows, _)) => report(a.json, MotionReport { axes: rows }),
    }
}

/// How long a hold-to-run command (`jog`, `stream`) follows its axes to
/// rest once it has ended its operation.
const SETTLE_WALL: Duration = Duration::from_secs(600);

/// Follows `axes` from `cycle` until their operations are over, after a
/// hold-to-run command ended them (a signal has done its work by then: it
/// does not cut this short): a row per axis.
pub fn follow_to_rest(
    client: &mut Client,
    axes: &[Followed],
    cycle: u64,
    progress: &mut Progress,
) -> Result<Vec<MotionRow>, ClientError> {
    let (rows, _) = follow(
        client,
        axes,
        cycle,
        SETTLE_WALL,
        |st, m| progress.show_motion(st, m),
        || false,
    )?;
    Ok(rows)
}

/// Prints the rows (JSON or a table) and returns the exit code: the
/// signal's, else 0 when every axis ended as asked.
pub fn report(json: bool, r: MotionReport) -> i32 {
    if json {
        print_json(&r);
    } else {
        print!("{}", motion_report::table::motion_rows(&r.axes));
    }
    match signal_code() {
        Some(code) => code,
        None if r.succeeded() => EXIT_OK,
        None => EXIT_FAILED,
    }
}

/// A refused or failed operation request: the reason per axis, exit 1 (or
/// the client's exit code).
pub fn op_error(json: bool, what: &str, e: &OpError) -> i32 {
    match e {
        OpError::Client(e) => client_error(json, e),
        OpError::Refused(resp) => fail(
            json,
            resp.refusal(what, |x| x.reason != REASON_NONE),
            EXIT_FAILED,
        ),
    }
}
