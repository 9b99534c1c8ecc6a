use super::moves::op_error;
use super::{client_error, fail, EXIT_FAILED, EXIT_OK};
use crate::cli::{AxesArgs, ChangeArgs, RedefineArgs};
use motion_control::*;
use motion_report::print_json;
use std::time::Duration;

/// What `stop` / `unhome` / `enable` / `disable` / `reset` / `change` send.
pub enum Simple {
    /// A control-plane request (`REQ_STOP`, `REQ_UNHOME`).
    Kind(u32),
    /// An operation of the engine without parameters.
    Op(Operation),
}

/// `stop` / `unhome` / `enable` / `disable` / `reset`: one request, every
/// axis's answer.
pub fn axes(client: &mut Client, what: Simple, a: &AxesArgs) -> i32 {
    let sent = match what {
        Simple::Kind(kind) => client.simple(kind, 0, &a.axes, Duration::from_secs(3)),
        Simple::Op(op) => client.send(
            &Request::Operate {
                axes: Axes::from_names(&a.axes),
                op,
            },
            Duration::from_secs(3),
        ),
    };
    let what = match what {
        Simple::Kind(REQ_STOP) => "stop",
        Simple::Kind(_) => "unhome",
        Simple::Op(op) => op.kind().name(),
    };
    let resp = match sent {
        Ok(r) => r,
        Err(e) => return client_error(a.json, &e),
    };
    if resp.result != RESULT_ACCEPTED {
        return fail(a.json, resp.refusal(what, |x| x.accepted == 0), EXIT_FAILED);
    }
    accepted(a.json, what, &resp)
}

/// Prints the axes an accepted request names (JSON or a line): exit 0.
fn accepted(json: bool, what: &str, resp: &ControlResponse) -> i32 {
    let names: Vec<String> = resp.answers().iter().map(|x| get_str(&x.name)).collect();
    if json {
        print_json(&motion_report::AcceptedReport { accepted: names });
    } else {
        println!("{what}: {}", names.join(" "));
    }
    EXIT_OK
}

/// `change AXIS [--speed V] [--accel A] [--decel D] [--jerk J]` (MCD): one
/// request, answered at once (the motion it changes goes on; `move` or
/// `jog` follows it).
pub fn change(client: &mut Client, a: &ChangeArgs) -> i32 {
    let named = AxesArgs {
        axes: vec![a.axis.clone()],
        json: a.json,
    };
    axes(client, Simple::Op(Operation::Change(a.spec.spec)), &named)
}

/// `redefine AXIS (--position P | --by D)` (MRP): accepted and complete in
/// the cycle that takes it (nothing moves), so the answer is the outcome:
/// the axes it was applied to (`status` shows the new positions and soft
/// limits).
pub fn redefine(client: &mut Client, a: &RedefineArgs) -> i32 {
    let op = Operation::Redefine(a.spec.spec);
    let resp = match client.operate(std::slice::from_ref(&a.axis), op) {
        Ok(r) => r,
        Err(e) => return op_error(a.json, "redefine", &e),
    };
    accepted(a.json, "redefine", &resp)
}
