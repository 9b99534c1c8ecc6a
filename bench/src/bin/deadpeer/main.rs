//! Dead-peer reaction time: from a signal (SIGKILL, or SIGSTOP) sent to the
//! `motion-io` process while an axis is homing to the first stopping
//! command the supervisor publishes for that axis (see [`trial`] for how it
//! is observed). See `bench/README.md`.
//!
//! This file is the command line, the sequence of trials and the report;
//! [`trial`] is one trial.

mod trial;

use clap::{Parser, ValueEnum};
use motion_bench::bins::Binaries;
use motion_bench::flags::{Cycle, Files};
use motion_bench::outcome::{self, with, write_json, Bench};
use motion_bench::proc;
use motion_bench::table::{line, Text};
use motion_report::nearest_rank as pct;
use serde::Serialize;
use serde_json::{json, Value};
use trial::Trial;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Sig {
    /// SIGKILL: the process is gone.
    #[default]
    Kill,
    /// SIGSTOP: the process hangs (SIGCONT after the trial).
    Stop,
}

impl Sig {
    fn number(self) -> i32 {
        [libc::SIGKILL, libc::SIGSTOP][self as usize]
    }

    fn name(self) -> &'static str {
        ["SIGKILL", "SIGSTOP"][self as usize]
    }
}

#[derive(Debug, Parser)]
#[command(
    name = "deadpeer",
    about = "Measures how fast the supervisor stops a homing axis when its motion-io is \
             SIGKILLed or SIGSTOPped: signal → first stopping command, observed by a spy \
             subscriber on the command topic (the supervisor's own send timestamps).",
    after_help = "Exit status: 0 when every trial ran (whatever the times: they are figures, not \
                  assertions), 1 if a trial could not be run, 2 on a command-line mistake, 130 if \
                  interrupted."
)]
pub struct Opts {
    /// Trials per signal.
    #[arg(long, default_value_t = 20)]
    trials: u32,
    /// Signals, in this order.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "kill,stop")]
    signals: Vec<Sig>,
    #[command(flatten)]
    cycle: Cycle,
    /// CPU of the spy thread (default: another CPU than --cpu).
    #[arg(long, value_parser = motion_config::args::cpu)]
    spy_cpu: Option<usize>,
    /// SCHED_FIFO priority of the spy thread (0: normal scheduling).
    #[arg(long, default_value_t = 70, value_parser = clap::value_parser!(i32).range(0..=99))]
    spy_priority: i32,
    /// Home Speed of the axis, units/s (its seek takes 60 s at most).
    #[arg(long, default_value_t = 20.0)]
    speed: f64,
    /// How long the axis cruises at Home Speed before the signal, ms (plus
    /// a random part of one period, so the signal falls anywhere in the cycle).
    #[arg(long, default_value_t = 200)]
    cruise_ms: u64,
    #[command(flatten)]
    files: Files,
}

impl Opts {
    fn spy_cpu(&self) -> usize {
        self.spy_cpu.unwrap_or(self.cycle.other_cpu())
    }
}

fn main() {
    let o = Opts::parse();
    outcome::main("deadpeer", || run(&o))
}

fn run(o: &Opts) -> Result<i32, String> {
    if !(o.speed > 0.0 && o.speed <= 1000.0) {
        eprintln!("deadpeer: --speed must be within (0, 1000] units/s");
        return Ok(2);
    }
    let bins = Binaries::find(o.files.supervisor.as_deref())?;
    let out = o.files.out("");
    let b = Bench::start("deadpeer", Some(&out))?;
    let (cy, env) = (&o.cycle, &b.host);
    let signals: Vec<&str> = o.signals.iter().map(|s| s.name()).collect();
    eprintln!(
        "deadpeer: {} trial(s) per signal ({}), {} µs cycle, SCHED_FIFO {} on CPU {} (motion-io there too), \
         spy on CPU {}; feedback_timeout_ms 10 (default); kernel {} ({}); load {}",
        o.trials, signals.join(", "), cy.period_us, cy.priority, cy.cpu, o.spy_cpu(), env.kernel,
        env.preemption, env.load
    );
    let (mut trials, mut leftovers, mut interrupted) = (Vec::new(), Vec::new(), false);
    'all: for &sig in &o.signals {
        for i in 0..o.trials {
            if proc::stop_requested() {
                interrupted = true;
                break 'all;
            }
            let t = trial::run(o, &bins, &b, (sig, i), &mut leftovers)?;
            progress(o, &t);
            trials.push(t);
        }
    }
    let wall = b.t0.elapsed().as_secs_f64();
    let (text, summary) = report(o, &b, &trials, &leftovers, wall);
    print!("{text}");
    let more = json!({
        "spy_cpu": o.spy_cpu(),
        "spy_priority": o.spy_priority,
        "speed": o.speed,
        "feedback_timeout_ms": 10,
        "summary": summary,
        "trials": trials,
        "leftovers": leftovers,
        "interrupted": interrupted,
    });
    let path = out.join(format!("deadpeer-{}us.json", cy.period_us));
    write_json(&path, &with(b.json_head(cy, wall), more))?;
    Ok(b.end(&[&path], interrupted, &[], false))
}

/// `x` in ms, two decimals (`-` if none).
fn ms(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{x:.2}"))
}

/// One line per trial on stderr.
fn progress(o: &Opts, t: &Trial) {
    let problems = match t.problems.is_empty() {
        true => String::new(),
        false => format!(" PROBLEMS: {}", t.problems.join("; ")),
    };
    let code = |x: Option<u16>| x.map_or("-".into(), |x| x.to_string());
    eprintln!(
        "deadpeer: {} trial {}/{}: signal → stop {} ms (from the last feedback {} ms), {} command(s), result {}/{} {}{problems}",
        t.signal.name(),
        t.index + 1,
        o.trials,
        ms(t.reaction_ms),
        ms(t.from_last_feedback_ms),
        t.commands_until_stop.map_or("-".into(), |x| x.to_string()),
        code(t.err),
        code(t.exerr),
        t.error.as_deref().unwrap_or("")
    );
}

/// The columns of the report's table.
const WIDTHS: [i32; 10] = [-10, 7, 9, 9, 9, 9, 9, 3, -28, 12];

/// The printed report and the JSON summary per signal.
fn report(
    o: &Opts,
    b: &Bench,
    trials: &[Trial],
    leftovers: &[String],
    wall: f64,
) -> (String, Vec<Value>) {
    let (mut t, cy) = (Text::default(), &o.cycle);
    t.line(format!(
        "== deadpeer: signal to motion-io while X seeks at {} units/s → first stopping command, {} µs cycle, SCHED_FIFO {} on CPU {}",
        o.speed, cy.period_us, cy.priority, cy.cpu
    ));
    t.line(b.load_line(wall));
    t.line(format!(
        "configured bound: feedback_timeout_ms = 10 (default) → the rule trips after > 10 ms of missing answers, + 1 cycle ({} ms) to the first slower command; goal ≤ 20 ms",
        f64::from(cy.period_us) / 1000.0
    ));
    t.line("");
    let head =
        "signal|trials|min ms|p50 ms|p90 ms|max ms|mean||from last feedback p50/max|12/40 result";
    t.line(line(&WIDTHS, head.split('|')));
    let mut summary = Vec::new();
    for &sig in &o.signals {
        let ts: Vec<&Trial> = trials.iter().filter(|t| t.signal == sig).collect();
        let sorted = |f: fn(&Trial) -> Option<f64>| {
            let mut v: Vec<f64> = ts.iter().filter_map(|t| f(t)).collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let (r, f) = (
            sorted(|t| t.reaction_ms),
            sorted(|t| t.from_last_feedback_ms),
        );
        let lost = ts
            .iter()
            .filter(|t| t.err == Some(12) && t.exerr == Some(40))
            .count();
        let mean = (!r.is_empty()).then(|| r.iter().sum::<f64>() / r.len() as f64);
        let cells = [
            r.first().copied(),
            pct(&r, 0.5),
            pct(&r, 0.9),
            r.last().copied(),
            mean,
        ];
        let (n, m) = (r.len(), ts.len());
        let first = [sig.name().to_string(), format!("{n}/{m}")];
        let last = [
            String::new(),
            format!("{} / {}", ms(pct(&f, 0.5)), ms(f.last().copied())),
        ];
        let cells = first.into_iter().chain(cells.map(ms)).chain(last);
        t.line(line(&WIDTHS, cells.chain([format!("{lost} of {m}")])));
        summary.push(json!({
            "signal": sig,
            "trials": ts.len(),
            "measured": r.len(),
            "reaction_ms": {"min": r.first(), "p50": pct(&r, 0.5), "p90": pct(&r, 0.9), "max": r.last(), "mean": mean},
            "from_last_feedback_ms": {"min": f.first(), "p50": pct(&f, 0.5), "max": f.last()},
            "results_12_40": lost,
        }));
    }
    t.line("");
    t.line("p50/p90: nearest rank; reaction = the supervisor's send time of the first command slower than the cruise (or disabling) − CLOCK_MONOTONIC right before kill(2)");
    let problems: Vec<String> = (trials.iter())
        .flat_map(|t| {
            t.problems
                .iter()
                .map(move |p| format!("{} trial {}: {p}", t.signal.name(), t.index + 1))
        })
        .collect();
    if !problems.is_empty() {
        t.line(format!("problems ({}):", problems.len()));
        problems
            .iter()
            .take(30)
            .for_each(|p| t.line(format!("  {p}")));
    }
    t.line(match leftovers.is_empty() {
        true => "shared memory and session files: nothing left behind".into(),
        false => format!(
            "left behind (then cleaned by the bench): {}",
            leftovers.join(", ")
        ),
    });
    (t.0, summary)
}
