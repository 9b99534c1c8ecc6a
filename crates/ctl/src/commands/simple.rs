use super::{client_error, fail, EXIT_FAILED, EXIT_OK};
use crate::cli::AxesArgs;
use motion_control::*;
use motion_report::print_json;
use std::time::Duration;

/// `stop` / `unhome` / `enable` / `disable` / `reset`: one request, every
/// axis's answer.
pub fn axes(client: &mut Client, kind: u32, what: &str, a: &AxesArgs) -> i32 {
    let resp = match client.simple(kind, 0, &a.axes, Duration::from_secs(3)) {
        Ok(r) => r,
        Err(e) => return client_error(a.json, &e),
    };
    if resp.result != RESULT_ACCEPTED {
        return fail(a.json, resp.refusal(what, |x| x.accepted == 0), EXIT_FAILED);
    }
    let names: Vec<String> = resp.answers().iter().map(|x| get_str(&x.name)).collect();
    if a.json {
        print_json(&motion_report::AcceptedReport { accepted: names });
    } else {
        println!("{what}: {}", names.join(" "));
    }
    EXIT_OK
}
