//! What a part of the soak counts — the homings' results (a [`Tally`]) and
//! the figures of the supervisors that ran them (cycles, misses, feedback
//! gaps, warnings), so that the failures can be read next to what the cycle
//! and the I/O link did meanwhile — and the results: the printed table and
//! soak.json with the same counts. The counts are figures, not assertions:
//! nothing here fails the run.

use crate::cli::{Opts, Via};
use crate::Ctx;
use motion_bench::drive::{HomeRun, Tally};
use motion_bench::host::loadavg;
use motion_bench::outcome::Bench;
use motion_bench::table::Text;
use motion_report::GapCounts;
use serde_json::{json, Value};

/// Latency and I/O figures of the supervisors of one part, summed.
#[derive(Default)]
pub struct RunFigures {
    pub runs: u64,
    pub cycles: u64,
    pub deadline_misses: u64,
    pub late_replies: u64,
    pub frames_missing: u64,
    pub gaps: GapCounts,
    pub wakeup_max_us: f64,
    pub warnings: Vec<String>,
}

impl RunFigures {
    /// Adds a `run --json` / `home --json` object: its latency and I/O
    /// figures (if it has them, or `always`) and its warnings (each once).
    pub fn add(&mut self, v: &Value, always: bool) {
        if always || v.get("latency").is_some() {
            let (lat, n) = (&v["latency"], |v: &Value| v.as_u64().unwrap_or(0));
            self.runs += 1;
            self.cycles += n(&lat["cycles"]);
            self.deadline_misses += n(&lat["deadline_misses"]);
            self.late_replies += n(&lat["late_replies"]);
            let max = lat["wakeup_us"]["max"].as_f64().unwrap_or(0.0);
            self.wakeup_max_us = self.wakeup_max_us.max(max);
            for io in v["io"].as_array().into_iter().flatten() {
                self.frames_missing += n(&io["frames_missing"]);
                if let Ok(g) = serde_json::from_value::<GapCounts>(io["gaps"].clone()) {
                    self.gaps.merge(&g);
                }
            }
        }
        for w in v["warnings"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(Value::as_str)
        {
            if !self.warnings.iter().any(|x| x == w) {
                self.warnings.push(w.to_string());
            }
        }
    }
}

/// One part (unloaded one-axis, stressed one-axis, 64-axis).
#[derive(Default)]
pub struct Part {
    pub tally: Tally,
    pub figures: RunFigures,
    pub seconds: f64,
}

impl Part {
    fn json(&self) -> Value {
        let f = &self.figures;
        json!({
            "seconds": motion_report::round(self.seconds, 1),
            "tally": self.tally,
            "supervisors": {
                "supervisor_runs": f.runs,
                "cycles": f.cycles,
                "deadline_misses": f.deadline_misses,
                "late_replies": f.late_replies,
                "frames_missing": f.frames_missing,
                "gaps": f.gaps,
                "wakeup_max_us": f.wakeup_max_us,
                "warnings": f.warnings,
            },
        })
    }
}

/// Counts one `home --json` run (rows, latency, gaps) into `p`.
pub fn count_home_run(p: &mut Part, what: &str, run: &HomeRun) {
    p.tally.add(what, run);
    if let Some(j) = &run.json {
        p.figures.add(j, false);
    }
}

/// What the parts measured.
pub struct Outcome {
    /// One axis unloaded, one axis stressed, 64 axes.
    pub parts: [Part; 3],
    pub interrupted: bool,
    /// Seconds of the whole soak.
    pub wall: f64,
}

/// The printed report.
pub fn text(o: &Opts, b: &Bench, ctx: &Ctx, out: &Outcome) -> String {
    let ([unloaded, stressed, axes64], cy, mut t) = (&out.parts, &o.cycle, Text::default());
    t.line(format!(
        "== soak: spurious homing failures, {} µs cycle, SCHED_FIFO {} on CPU {} (motion-io on the same CPU, the default), default settings (feedback_timeout_ms 10)",
        cy.period_us, cy.priority, cy.cpu
    ));
    let (before, after, wall) = (&b.env.load_before, loadavg(), out.wall);
    t.line(format!(
        "{} | load before {before}, after {after} | wall {wall:.0} s",
        b.env.head()
    ));
    t.line("");
    t.line(format!(
        "{:<34}{:>9}{:>7}{:>10}{:>8}{:>10}{:>9}{:>10}{:>8}",
        "part", "homings", "ok", "12/40", "other", "not homed", "no rows", "lost betw", "time s"
    ));
    let row = |name: &str, p: &Part, between: bool| {
        let y = &p.tally;
        let lost = match between && o.via == Via::Daemon {
            true => y.lost_between.to_string(),
            false => "-".into(),
        };
        format!(
            "{:<34}{:>9}{:>7}{:>10}{:>8}{:>10}{:>9}{:>10}{:>8.0}",
            name,
            y.axis_homings + y.run_failures,
            y.ok,
            y.feedback_lost,
            y.other_errors,
            y.not_homed,
            y.run_failures,
            lost,
            p.seconds
        )
    };
    t.line(row("1 axis, no load", unloaded, true));
    t.line(row(
        &format!("1 axis, stress-ng on CPU {}", ctx.other_cpu),
        stressed,
        true,
    ));
    let mut both = Part {
        seconds: unloaded.seconds + stressed.seconds,
        ..Part::default()
    };
    both.tally.merge(&unloaded.tally);
    both.tally.merge(&stressed.tally);
    t.line(row("1 axis, all", &both, true));
    let stress = if o.stress64 { ", stress-ng" } else { "" };
    t.line(row(
        &format!("64 axes parallel, {} runs{stress}", axes64.tally.requests),
        axes64,
        false,
    ));
    t.line(format!(
        "one-axis homings {}; 64 axes: each run a fresh `motion-supervisor home --parallel --json`",
        match o.via {
            Via::Daemon if o.trace => "through one `motion-supervisor run` per block of --block, each a `motionctl trace X --home` (result from `motionctl status`)",
            Via::Daemon => "through one `motion-supervisor run` per block of --block, each a `motionctl home X --json`",
            Via::Home => "each a fresh `motion-supervisor home --json`",
        }
    ));
    t.line("");
    t.line("columns: homings = axis homings (+ requests without a result); 12/40 = failed with ERR 12 / EXERR 40 (feedback lost); other = any other error; not homed = ended with HomedStatus clear (failed ones included); no rows = the command gave no result; lost betw = found not homed by `motionctl status` before the next homing");
    t.line("");
    supervisors(&mut t, &out.parts);
    problems(&mut t, ctx, &out.parts);
    t.0
}

/// The supervisors' own figures per part.
fn supervisors(t: &mut Text, parts: &[Part; 3]) {
    t.line(format!(
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
    for (name, p) in ["1 axis, no load", "1 axis, stress-ng", "64 axes"]
        .iter()
        .zip(parts)
    {
        let (f, g) = (&p.figures, &p.figures.gaps);
        t.line(format!(
            "{:<34}{:>8}{:>11}{:>8}{:>9}{:>7}{:>7}{:>7}{:>7}{:>9}{:>12.0}",
            name,
            f.runs,
            f.cycles,
            f.deadline_misses,
            f.late_replies,
            g.one,
            g.two_to_three,
            g.four_to_ten,
            g.over_ten,
            g.longest_cycles,
            f.wakeup_max_us
        ));
    }
}

/// Every problem with its details, and what was left behind.
fn problems(t: &mut Text, ctx: &Ctx, parts: &[Part; 3]) {
    let details: Vec<&String> = parts.iter().flat_map(|p| &p.tally.details).collect();
    if !details.is_empty() {
        t.line("");
        t.line(format!("problems ({}):", details.len()));
        for d in details.iter().take(40) {
            t.line(format!("  {d}"));
        }
    }
    if ctx.leftovers.is_empty() {
        return t.line("shared memory and session files: nothing left behind");
    }
    let not = if ctx.not_cleaned.is_empty() {
        ""
    } else {
        "; NOT cleaned: see soak.json"
    };
    t.line(format!(
        "left behind by {} run(s) (then cleaned by the bench{not}): {}",
        ctx.leftovers.len(),
        ctx.leftovers.join(", ")
    ));
}

/// soak.json.
pub fn json(o: &Opts, b: &Bench, ctx: &Ctx, out: &Outcome) -> Value {
    let ([unloaded, stressed, axes64], cy) = (&out.parts, &o.cycle);
    json!({
        "period_us": cy.period_us,
        "cpu": cy.cpu,
        "priority": cy.priority,
        "via": format!("{:?}", o.via).to_lowercase(),
        "block": o.block,
        "stress_share": o.stress_share,
        "stress_cpu": ctx.other_cpu,
        "kernel": b.env.kernel,
        "preemption": b.env.preemption,
        "load_before": b.env.load_before,
        "load_after": loadavg(),
        "wall_s": out.wall,
        "one_axis_no_load": unloaded.json(),
        "one_axis_stress": stressed.json(),
        "axes64": axes64.json(),
        "axes64_stress": o.stress64,
        "leftovers": ctx.leftovers,
        "leftovers_not_cleaned": ctx.not_cleaned,
        "interrupted": out.interrupted,
    })
}
