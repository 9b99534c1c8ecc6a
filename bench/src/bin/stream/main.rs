//! The supervised setpoint stream's figures: the latency from a
//! program publishing a setpoint to the command frame that carries it, in
//! cycles, at 1 and 4 kHz ([`latency`]); what a 1 kHz stream of 64 axes
//! costs the cycle's compute and wake-up, against none, as ratios of one
//! run's alternating slices ([`cost`]); the following error of the sim
//! plant streaming a circle on two axes ([`circle`]). See `bench/README.md`
//! and README "Performance".
//!
//! This file is the command line, the sequence and the report; the machine
//! and the streaming program are the bench library's (`motion_bench::machine`,
//! `motion_bench::stream`).

mod circle;
mod cost;
mod latency;

use clap::Parser;
use motion_bench::bins::Binaries;
use motion_bench::flags::{Cycle, Files, Slicing};
use motion_bench::outcome::{self, write_json, Bench};
use serde_json::json;

#[derive(Debug, Parser)]
#[command(
    name = "stream",
    about = "Setpoint stream figures: publish → command frame latency in cycles (1 and 4 kHz), \
             the cost of a 1 kHz stream of 64 axes (compute and wake-up p99, with / without, \
             alternating slices), the following error of a circle on two sim axes.",
    after_help = "Exit status: 0 when every part ran (the figures are figures, not assertions), \
                  1 if a part could not run, 2 on a command-line mistake, 130 if interrupted."
)]
pub struct Opts {
    #[command(flatten)]
    cycle: Cycle,
    /// Seconds of each latency run and of the circle.
    #[arg(long, default_value_t = 10.0, value_parser = motion_config::args::seconds)]
    seconds: f64,
    /// The cost part's slices (--duration per variant, --slice).
    #[command(flatten)]
    slicing: Slicing<5000, 2000>,
    /// SCHED_FIFO priority of the streaming program (0: normal), on another
    /// CPU than the cycle.
    #[arg(long, default_value_t = 70, value_parser = clap::value_parser!(i32).range(0..=99))]
    client_priority: i32,
    /// Circle radius (units) and frequency (Hz).
    #[arg(long, default_value_t = 10.0, value_parser = motion_config::args::number)]
    radius: f64,
    #[arg(long, default_value_t = 0.5, value_parser = motion_config::args::number)]
    hz: f64,
    /// Parts to run.
    #[arg(long, value_delimiter = ',', default_value = "latency,cost,circle")]
    parts: Vec<String>,
    #[command(flatten)]
    files: Files,
}

fn main() {
    let o = Opts::parse();
    outcome::main("stream", || run(&o))
}

fn run(o: &Opts) -> Result<i32, String> {
    let bins = Binaries::find(o.files.supervisor.as_deref())?;
    let out = o.files.out("");
    let b = Bench::start("stream", Some(&out))?;
    b.warn_not_rt();
    let want = |p: &str| o.parts.iter().any(|x| x == p);
    let mut failures = Vec::new();
    let mut lat = Vec::new();
    if want("latency") {
        for period in [1000, 250] {
            match latency::run(o, &bins, &b, period) {
                Ok(l) => lat.push(l),
                Err(e) => failures.push(format!("latency {period} µs: {e}")),
            }
        }
    }
    let cost = want("cost")
        .then(|| cost::run(o, &bins, &b))
        .and_then(|r| r.map_err(|e| failures.push(format!("cost: {e}"))).ok());
    let circle = want("circle")
        .then(|| circle::run(o, &bins, &b))
        .and_then(|r| r.map_err(|e| failures.push(format!("circle: {e}"))).ok());
    print!("{}", text(o, &b, &lat, cost.as_ref(), circle.as_ref()));
    let report = json!({
        "environment": b.environment(),
        "cpu": o.cycle.cpu,
        "priority": o.cycle.priority,
        "client_priority": o.client_priority,
        "latency": lat,
        "cost": cost.as_ref().map(cost::Cost::json),
        "circle": circle,
        "failures": failures,
    });
    let path = out.join("stream.json");
    write_json(&path, &report)?;
    let interrupted = motion_bench::proc::stop_requested();
    Ok(b.end(&[&path], interrupted, &failures, false))
}

/// The printed report.
fn text(
    o: &Opts,
    b: &Bench,
    lat: &[latency::Latency],
    cost: Option<&cost::Cost>,
    circle: Option<&circle::Circle>,
) -> String {
    let f = |x: Option<f64>| x.map_or("-".into(), |x| format!("{x:.2}"));
    let mut s = format!(
        "== stream: cycle SCHED_FIFO {} on CPU {}; the program (and spy) on CPU {} at FIFO {}\n{}\n",
        o.cycle.priority,
        o.cycle.cpu,
        o.cycle.other_cpu(),
        o.client_priority,
        b.host.head()
    );
    for l in lat {
        s += &format!(
            "latency {} µs: {} setpoints, {} carried, {} overtaken; cycles p50 {} p99 {} max {}; µs p50 {} p99 {} max {}; spy missed {}\n",
            l.period_us, l.setpoints, l.carried, l.overtaken, f(l.cycles_p50), f(l.cycles_p99),
            f(l.cycles_max), f(l.us_p50), f(l.us_p99), f(l.us_max), l.spy_missed
        );
    }
    if let Some(c) = cost {
        let r = |a: f64, b: f64| f((b > 0.0).then(|| a / b));
        s += &format!(
            "cost, 64 axes at 1 kHz ({} s per variant): compute p50/p99 {:.1}/{:.1} µs without, {:.1}/{:.1} µs with a stream (p99 ratio {}); wake-up p99 {:.1} / {:.1} µs (ratio {}); deadline misses {} / {}\n",
            c.none.secs, c.none.c.p50, c.none.c.p99, c.stream.c.p50, c.stream.c.p99,
            r(c.stream.c.p99, c.none.c.p99), c.none.w.p99, c.stream.w.p99,
            r(c.stream.w.p99, c.none.w.p99), c.none.misses, c.stream.misses
        );
    }
    if let Some(c) = circle {
        let g = |x: Option<f64>| x.map_or("-".into(), |x| format!("{x:.4}"));
        s += &format!(
            "circle r {} at {} Hz ({:.1} units/s), {} samples: following error p50 {} / {}, p99 {} / {}, max {} / {}; contour error p99 {} max {}\n",
            c.radius, c.hz, c.speed, c.samples, g(c.following_p50[0]), g(c.following_p50[1]),
            g(c.following_p99[0]), g(c.following_p99[1]), g(c.following_max[0]),
            g(c.following_max[1]), g(c.contour_p99), g(c.contour_max)
        );
    }
    s
}
