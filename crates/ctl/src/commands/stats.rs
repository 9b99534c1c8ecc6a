use super::{client_error, fail, EXIT_FAILED, EXIT_OK};
use crate::cli::StatsArgs;
use motion_control::*;
use motion_report::{print_json, ErrorEntry, StatsReport};
use std::time::Duration;

/// `stats [--json] [--reset] [--since-reset] [--hlog FILE]`.
pub fn stats(client: &mut Client, a: &StatsArgs) -> i32 {
    let since = if a.since_reset { FLAG_SINCE_RESET } else { 0 };
    let t = Duration::from_secs(5);
    // The log first: a reset below must not empty it.
    if let Some(path) = &a.hlog {
        match client.fetch(REQ_HLOG, since, &[], t) {
            Err(e) => return client_error(a.json, &e),
            Ok((_, resp)) if resp.result != RESULT_ACCEPTED => {
                return fail(
                    a.json,
                    vec![ErrorEntry::message(resp.message_text())],
                    EXIT_FAILED,
                )
            }
            Ok((data, _)) => {
                if let Err(e) = std::fs::write(path, &data) {
                    return fail(
                        a.json,
                        vec![ErrorEntry::message(format!(
                            "cannot write {}: {e}",
                            path.display()
                        ))],
                        EXIT_FAILED,
                    );
                }
            }
        }
    }
    let flags = since | if a.reset { FLAG_RESET } else { 0 };
    let (data, resp) = match client.fetch(REQ_STATS, flags, &[], t) {
        Ok(x) => x,
        Err(e) => return client_error(a.json, &e),
    };
    if resp.result != RESULT_ACCEPTED {
        return fail(
            a.json,
            vec![ErrorEntry::message(resp.message_text())],
            EXIT_FAILED,
        );
    }
    let report: StatsReport = match serde_json::from_slice(&data) {
        Ok(r) => r,
        Err(e) => {
            return fail(
                a.json,
                vec![ErrorEntry::message(format!(
                    "the supervisor's statistics could not be read: {e}"
                ))],
                EXIT_FAILED,
            )
        }
    };
    if a.json {
        print_json(&report);
    } else {
        println!(
            "since {} ({:.1} s ago){}",
            report.since,
            report.seconds,
            if a.reset { "; reset now" } else { "" }
        );
        print!("{}", report.latency.table());
        for io in &report.io {
            println!(
                "I/O {}: {}; gaps 1: {}, 2-3: {}, 4-10: {}, >10: {}, longest {:.1} ms",
                io.name,
                if io.attached {
                    "attached"
                } else {
                    "NOT attached"
                },
                io.gaps.one,
                io.gaps.two_to_three,
                io.gaps.four_to_ten,
                io.gaps.over_ten,
                io.longest_gap_ms
            );
        }
        println!(
            "allocations in the cycle after warm-up: {} system-allocator calls",
            report.allocations.system_calls_in_cycle
        );
        if let Some(p) = &a.hlog {
            println!("interval log written to {}", p.display());
        }
    }
    EXIT_OK
}
