//! What a part of the soak counts — the homings' results (a [`Tally`]) and
//! the figures of the supervisors that ran them (cycles, misses, feedback
//! gaps, warnings), so that the failures can be read next to what the cycle
//! and the I/O link did meanwhile — and the results: the printed table and
//! soak.json with the same counts. The counts are figures, not assertions:
//! nothing here fails the run.

use crate::cli::{Opts, Via};
use crate::Ctx;
use motion_bench::homing::{HomeRun, Tally};
use motion_bench::outcome::Bench;
use motion_bench::table::{line, Text};
use motion_report::{GapCounts, RunReport};
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
    /// Adds the report of a `run --json` or `home --json`: its latency and
    /// I/O figures and its warnings (each once).
    pub fn add(&mut self, r: &RunReport) {
        let l = &r.latency;
        self.runs += 1;
        self.cycles += l.cycles;
        self.deadline_misses += l.deadline_misses;
        self.late_replies += l.late_replies;
        self.wakeup_max_us = self.wakeup_max_us.max(l.wakeup_us.max);
        for io in &r.io {
            self.frames_missing += io.frames_missing;
            self.gaps.merge(&io.gaps);
        }
        for w in &r.warnings {
            if !self.warnings.contains(w) {
                self.warnings.push(w.clone());
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
    let report = run
        .json
        .clone()
        .and_then(|j| serde_json::from_value(j).ok());
    if let Some(r) = report {
        p.figures.add(&r);
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

/// The columns of the homings' table and of the supervisors' one: their
/// widths (negative: left-aligned) and headings.
const HOMINGS: [i32; 9] = [-34, 9, 7, 10, 8, 10, 9, 10, 8];
const HOMINGS_HEAD: &str = "part|homings|ok|12/40|other|not homed|no rows|lost betw|time s";
const SUPERVISORS: [i32; 11] = [-34, 8, 11, 8, 9, 7, 7, 7, 7, 9, 12];
const SUPERVISORS_HEAD: &str =
    "supervisors (sum)|runs|cycles|misses|late rep|gap 1|2-3|4-10|>10|longest|wake max µs";

/// The printed report.
pub fn text(o: &Opts, b: &Bench, ctx: &Ctx, out: &Outcome) -> String {
    let ([unloaded, stressed, axes64], cy, mut t) = (&out.parts, &o.cycle, Text::default());
    t.line(format!(
        "== soak: spurious homing failures, {} µs cycle, SCHED_FIFO {} on CPU {} (motion-io on the same CPU, the default), default settings (feedback_timeout_ms 10)",
        cy.period_us, cy.priority, cy.cpu
    ));
    t.line(b.load_line(out.wall));
    t.line("");
    t.line(line(&HOMINGS, HOMINGS_HEAD.split('|')));
    let row = |name: &str, p: &Part, between: bool| {
        let y = &p.tally;
        let lost = match between && o.via == Via::Daemon {
            true => y.lost_between.to_string(),
            false => "-".into(),
        };
        let n = [
            y.axis_homings + y.run_failures,
            y.ok,
            y.feedback_lost,
            y.other_errors,
            y.not_homed,
            y.run_failures,
        ];
        let cells = [name.to_string()]
            .into_iter()
            .chain(n.map(|n| n.to_string()));
        line(&HOMINGS, cells.chain([lost, format!("{:.0}", p.seconds)]))
    };
    t.line(row("1 axis, no load", unloaded, true));
    let other = ctx.other_cpu;
    t.line(row(
        &format!("1 axis, stress-ng on CPU {other}"),
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
    let runs = axes64.tally.requests;
    t.line(row(
        &format!("64 axes parallel, {runs} runs{stress}"),
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
    t.line(line(&SUPERVISORS, SUPERVISORS_HEAD.split('|')));
    for (name, p) in ["1 axis, no load", "1 axis, stress-ng", "64 axes"]
        .iter()
        .zip(parts)
    {
        let (f, g) = (&p.figures, &p.figures.gaps);
        let n = [
            f.runs,
            f.cycles,
            f.deadline_misses,
            f.late_replies,
            g.one,
            g.two_to_three,
            g.four_to_ten,
            g.over_ten,
            g.longest_cycles,
        ];
        let cells = [name.to_string()]
            .into_iter()
            .chain(n.map(|n| n.to_string()));
        t.line(line(
            &SUPERVISORS,
            cells.chain([format!("{:.0}", f.wakeup_max_us)]),
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
    let not = match ctx.not_cleaned.is_empty() {
        true => "",
        false => "; NOT cleaned: see soak.json",
    };
    t.line(format!(
        "left behind by {} run(s) (then cleaned by the bench{not}): {}",
        ctx.leftovers.len(),
        ctx.leftovers.join(", ")
    ));
}

/// soak.json.
pub fn json(o: &Opts, b: &Bench, ctx: &Ctx, out: &Outcome) -> Value {
    let [unloaded, stressed, axes64] = &out.parts;
    let more = json!({
        "via": format!("{:?}", o.via).to_lowercase(),
        "block": o.block,
        "stress_share": o.stress_share,
        "stress_cpu": ctx.other_cpu,
        "one_axis_no_load": unloaded.json(),
        "one_axis_stress": stressed.json(),
        "axes64": axes64.json(),
        "axes64_stress": o.stress64,
        "leftovers": ctx.leftovers,
        "leftovers_not_cleaned": ctx.not_cleaned,
        "interrupted": out.interrupted,
    });
    motion_bench::outcome::with(b.json_head(&o.cycle, out.wall), more)
}
