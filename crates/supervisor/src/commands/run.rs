use super::{load, rt_json, rt_lines, start};
use crate::cli::Common;
use motion_rt::termination as signals;
use std::path::Path;
use std::time::{Duration, Instant};

pub fn run(
    common: &Common,
    duration_s: Option<f64>,
    json: bool,
    hlog: Option<&Path>,
    io_args: &[String],
) -> i32 {
    let Some((m, source)) = load(common) else {
        return 2;
    };
    let Some(mut session) = start(common, m, io_args) else {
        return 1;
    };
    if !json {
        eprintln!(
            "motion-supervisor: running {source} at {} µs; SIGINT/SIGTERM to stop",
            session.machine.supervisor.cycle_us
        );
    }
    // The measured window starts now.
    session.poll();
    session.totals.reset();
    let mut hlog_writer = match hlog.map(crate::hlog::HlogWriter::create).transpose() {
        Ok(w) => w,
        Err(e) => {
            eprintln!("motion-supervisor: {e}");
            session.finish();
            return 1;
        }
    };
    let started = Instant::now();
    let mut last_line = Instant::now();
    let mut io_reported = false;
    let code = loop {
        std::thread::sleep(Duration::from_millis(50));
        session.shared.collect_intervals(&mut session.totals, |h| {
            if let Some(w) = hlog_writer.as_mut() {
                w.interval(h);
            }
        });
        session.shared.latest_snapshot(&mut session.snapshot);
        if let Some(sig) = signals::received() {
            if !json {
                eprintln!("motion-supervisor: signal {sig}: stopping every axis");
            }
            break 0;
        }
        if duration_s.is_some_and(|d| started.elapsed().as_secs_f64() >= d) {
            break 0;
        }
        if let Some(e) = session.check_alive() {
            if session.io.as_mut().is_some_and(|io| io.exited().is_some()) {
                if !io_reported {
                    eprintln!("motion-supervisor: {e}; cycling on, feedback lost");
                    io_reported = true;
                }
            } else {
                eprintln!("motion-supervisor: {e}");
                break 1;
            }
        }
        if !json && last_line.elapsed() >= Duration::from_secs(10) {
            last_line = Instant::now();
            let s = session.totals.summary();
            eprintln!(
                "motion-supervisor: {} cycles, {} deadline misses, wake-up p99 {:.1} µs max {:.1} µs, round trip p99 {:.1} µs",
                s.cycles, s.deadline_misses, s.wakeup.p99, s.wakeup.max, s.roundtrip.p99
            );
        }
    };
    let f = session.finish_with(|h| {
        if let Some(w) = hlog_writer.as_mut() {
            w.interval(h);
        }
    });
    if let Some(w) = hlog_writer.as_mut() {
        w.finish();
    }
    let summary = f.totals.summary();
    if json {
        let mut v = rt_json(&f);
        v["latency"] = summary.to_json();
        println!("{v}");
    } else {
        print!("{}", summary.table());
        for l in rt_lines(&f) {
            println!("{l}");
        }
    }
    code
}
