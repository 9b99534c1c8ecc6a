//! The soak's results: the printed table (homing results per part, then the
//! supervisors' cycle and feedback figures per part, then every problem
//! with its details) and OUT/soak.json with the same counts. The counts are
//! figures, not assertions: nothing here fails the run.

use crate::cli::{Opts, Via};
use crate::ctx::Ctx;
use crate::figures::{Part, RunFigures};
use motion_bench::drive::Tally;
use motion_bench::sys;
use serde_json::{json, Value};

/// What the parts measured, and the conditions they ran in.
pub struct Outcome {
    pub unloaded: Part,
    pub stressed: Part,
    pub axes64: Part,
    pub interrupted: bool,
    /// Seconds of the whole soak.
    pub wall: f64,
    /// Load average at the start (the end's is read when reported).
    pub load_before: String,
    pub preemption: String,
    /// stress-ng's CPU.
    pub other_cpu: usize,
}

/// The printed report.
pub fn text(o: &Opts, ctx: &Ctx, out: &Outcome) -> String {
    let Outcome {
        unloaded,
        stressed,
        axes64,
        wall,
        load_before,
        preemption,
        other_cpu,
        ..
    } = out;
    let mut t = String::new();
    let mut line = |s: String| {
        t.push_str(&s);
        t.push('\n');
    };
    line(format!(
        "== soak: spurious homing failures, {} µs cycle, SCHED_FIFO {} on CPU {} (motion-io on the same CPU, the default), default settings (feedback_timeout_ms 10)",
        o.period_us, o.priority, o.cpu
    ));
    line(format!(
        "kernel {} | preemption: {preemption} | {} CPUs | load before {load_before}, after {} | wall {:.0} s",
        sys::kernel(),
        sys::cpus(),
        sys::loadavg(),
        wall
    ));
    line(String::new());
    line(format!(
        "{:<34}{:>9}{:>7}{:>10}{:>8}{:>10}{:>9}{:>10}{:>8}",
        "part", "homings", "ok", "12/40", "other", "not homed", "no rows", "lost betw", "time s"
    ));
    let row = |name: &str, p: &Part, between: bool| {
        format!(
            "{:<34}{:>9}{:>7}{:>10}{:>8}{:>10}{:>9}{:>10}{:>8.0}",
            name,
            p.tally.axis_homings + p.tally.run_failures,
            p.tally.ok,
            p.tally.feedback_lost,
            p.tally.other_errors,
            p.tally.not_homed,
            p.tally.run_failures,
            if between && o.via == Via::Daemon {
                p.tally.lost_between.to_string()
            } else {
                "-".into()
            },
            p.seconds
        )
    };
    line(row("1 axis, no load", unloaded, true));
    line(row(
        &format!("1 axis, stress-ng on CPU {other_cpu}"),
        stressed,
        true,
    ));
    let mut both = Tally::default();
    both.merge(&unloaded.tally);
    both.merge(&stressed.tally);
    line(row(
        "1 axis, all",
        &Part {
            tally: both.clone(),
            figures: RunFigures::default(),
            seconds: unloaded.seconds + stressed.seconds,
        },
        true,
    ));
    // 64 axes: axis homings, and runs
    line(row(
        &format!(
            "64 axes parallel, {} runs{}",
            axes64.tally.requests,
            if o.stress64 { ", stress-ng" } else { "" }
        ),
        axes64,
        false,
    ));
    line(format!(
        "one-axis homings {}; 64 axes: each run a fresh `motion-supervisor home --parallel --json`",
        match o.via {
            Via::Daemon if o.trace => "through one `motion-supervisor run` per block of --block, each a `motionctl trace X --home` (result from `motionctl status`)",
            Via::Daemon => "through one `motion-supervisor run` per block of --block, each a `motionctl home X --json`",
            Via::Home => "each a fresh `motion-supervisor home --json`",
        }
    ));
    line(String::new());
    line("columns: homings = axis homings (+ requests without a result); 12/40 = failed with ERR 12 / EXERR 40 (feedback lost); other = any other error; not homed = ended with HomedStatus clear (failed ones included); no rows = the command gave no result; lost betw = found not homed by `motionctl status` before the next homing".into());
    line(String::new());
    line(format!(
        "{:<34}{:>8}{:>11}{:>8}{:>9}{:>7}{:>7}{:>7}{:>7}{:>9}{:>12}",
        "supervisors (sum)",
        "runs",
        "cycles",
        "misses",
        "late rep",
        "gap 1",
        "2-3",
        "4-10",
        ">10",
        "longest",
        "wake max µs"
    ));
    for (name, p) in [
        ("1 axis, no load", unloaded),
        ("1 axis, stress-ng", stressed),
        ("64 axes", axes64),
    ] {
        let f = &p.figures;
        line(format!(
            "{:<34}{:>8}{:>11}{:>8}{:>9}{:>7}{:>7}{:>7}{:>7}{:>9}{:>12.0}",
            name,
            f.runs,
            f.cycles,
            f.deadline_misses,
            f.late_replies,
            f.gaps.one,
            f.gaps.two_to_three,
            f.gaps.four_to_ten,
            f.gaps.over_ten,
            f.gaps.longest_cycles,
            f.wakeup_max_us
        ));
    }
    let details: Vec<&String> = unloaded
        .tally
        .details
        .iter()
        .chain(&stressed.tally.details)
        .chain(&axes64.tally.details)
        .collect();
    if !details.is_empty() {
        line(String::new());
        line(format!("problems ({}):", details.len()));
        for d in details.iter().take(40) {
            line(format!("  {d}"));
        }
    }
    if ctx.leftovers.is_empty() {
        line("shared memory and session files: nothing left behind".into());
    } else {
        line(format!(
            "left behind by {} run(s) (then cleaned by the bench{}): {}",
            ctx.leftovers.len(),
            if ctx.not_cleaned.is_empty() {
                ""
            } else {
                "; NOT cleaned: see soak.json"
            },
            ctx.leftovers.join(", ")
        ));
    }
    t
}

/// soak.json.
pub fn json(o: &Opts, ctx: &Ctx, out: &Outcome) -> Value {
    let Outcome {
        unloaded,
        stressed,
        axes64,
        interrupted,
        wall,
        load_before,
        preemption,
        other_cpu,
    } = out;
    json!({
        "period_us": o.period_us,
        "cpu": o.cpu,
        "priority": o.priority,
        "via": format!("{:?}", o.via).to_lowercase(),
        "block": o.block,
        "stress_share": o.stress_share,
        "stress_cpu": other_cpu,
        "kernel": sys::kernel(),
        "preemption": preemption,
        "load_before": load_before,
        "load_after": sys::loadavg(),
        "wall_s": wall,
        "one_axis_no_load": unloaded.json(),
        "one_axis_stress": stressed.json(),
        "axes64": axes64.json(),
        "axes64_stress": o.stress64,
        "leftovers": ctx.leftovers,
        "leftovers_not_cleaned": ctx.not_cleaned,
        "interrupted": interrupted,
    })
}
