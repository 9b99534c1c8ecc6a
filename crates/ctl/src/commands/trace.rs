use super::{client_error, fail, signal_code, EXIT_FAILED, EXIT_OK};
use crate::cli::TraceArgs;
use motion_control::*;
use motion_plot::trace as plot;
use motion_report::{print_json, ErrorEntry, TraceReport};
use std::time::{Duration, Instant};

/// How long one request may take.
const REQUEST_TIMEOUT: Duration = Duration::from_secs(3);

/// `trace AXIS --out FILE.csv [--plot FILE.svg] [--home]`: arms the trace,
/// waits for the homing to end, writes the CSV (and the plot).
pub fn trace(client: &mut Client, a: &TraceArgs) -> i32 {
    if let Err(code) = arm(client, a) {
        return code;
    }
    let csv = match fetch_when_done(client, a) {
        Ok(csv) => csv,
        Err(code) => return code,
    };
    if let Err(e) = std::fs::write(&a.out, &csv) {
        return fail(
            a.json,
            vec![ErrorEntry::message(format!(
                "cannot write {}: {e}",
                a.out.display()
            ))],
            EXIT_FAILED,
        );
    }
    let rows = motion_report::trace::parse_csv(&String::from_utf8_lossy(&csv));
    if let Some(p) = &a.plot {
        if let Err(e) = plot::draw(&rows, &a.axis, p) {
            return fail(a.json, vec![ErrorEntry::message(e)], EXIT_FAILED);
        }
    }
    let report = TraceReport {
        axis: a.axis.clone(),
        cycles: rows.len(),
        duration_s: rows.last().map_or(0.0, |r| r.t_s),
        event_raw: rows.iter().find_map(|r| r.event_raw),
        csv: a.out.display().to_string(),
        plot: a.plot.as_ref().map(|p| p.display().to_string()),
    };
    if a.json {
        print_json(&report);
    } else {
        println!(
            "trace of {}: {} cycles over {:.3} s, event at {}; written to {}{}",
            report.axis,
            report.cycles,
            report.duration_s,
            report
                .event_raw
                .map_or("-".to_string(), |e| format!("{e:.6}")),
            report.csv,
            report
                .plot
                .as_ref()
                .map_or(String::new(), |p| format!(" and {p}"))
        );
    }
    EXIT_OK
}

/// Arms the trace of the axis (and with `--home` starts its homing); the
/// exit code when refused.
fn arm(client: &mut Client, a: &TraceArgs) -> Result<(), i32> {
    let axes = vec![a.axis.clone()];
    let resp = client
        .simple(REQ_TRACE, 0, &axes, REQUEST_TIMEOUT)
        .map_err(|e| client_error(a.json, &e))?;
    if resp.result != RESULT_ACCEPTED {
        return Err(fail(a.json, resp.refusal("trace", |_| false), EXIT_FAILED));
    }
    if a.home {
        let r = client
            .simple(REQ_HOME, 0, &axes, REQUEST_TIMEOUT)
            .map_err(|e| client_error(a.json, &e))?;
        if r.result != RESULT_ACCEPTED {
            return Err(fail(a.json, r.refusal("home", |_| false), EXIT_FAILED));
        }
    } else if !a.json {
        eprintln!(
            "trace of {} armed: waiting for its next homing (Ctrl-C to give up)",
            a.axis
        );
    }
    Ok(())
}

/// Asks for the trace every 200 ms until the homing has ended (the CSV),
/// `--timeout` runs out or a signal comes (the exit code).
fn fetch_when_done(client: &mut Client, a: &TraceArgs) -> Result<Vec<u8>, i32> {
    let axes = vec![a.axis.clone()];
    let until = Instant::now() + Duration::from_secs_f64(a.timeout);
    loop {
        if let Some(code) = signal_code() {
            return Err(code);
        }
        match client.fetch(REQ_TRACE_FETCH, 0, &axes, REQUEST_TIMEOUT) {
            Err(e) => return Err(client_error(a.json, &e)),
            Ok((data, r)) if r.result == RESULT_ACCEPTED => return Ok(data),
            Ok((_, r)) if r.result == RESULT_NOT_READY => {}
            Ok((_, r)) => {
                return Err(fail(
                    a.json,
                    vec![ErrorEntry::message(r.message_text())],
                    EXIT_FAILED,
                ))
            }
        }
        if Instant::now() > until {
            return Err(fail(
                a.json,
                vec![ErrorEntry::message(format!(
                    "no complete homing of {} within {} s",
                    a.axis, a.timeout
                ))],
                EXIT_FAILED,
            ));
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}
