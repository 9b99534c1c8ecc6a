//! Control-plane cost bench: what the control and status services (and the
//! thread that serves them) cost the real-time cycle. `motion-supervisor
//! run` on the demo machine, idle, in alternating slices: (a) with
//! `--no-control-plane`, (b) with the control plane and a deployed
//! machine's clients attached (an HMI watching the status, a PLC polling it,
//! statistics now and then), (c) with `--homing` also X homed again and
//! again. See `bench/README.md`.
//!
//! The sequence: find the binaries, run the [`slice`]s, merge, judge and
//! print them ([`report`]), write cpcost.json.

mod cli;
mod report;
mod slice;
mod variant;

use clap::Parser;
use cli::Opts;
use motion_bench::bins::Binaries;
use motion_bench::outcome::{self, write_json, Bench};
use report::Merged;
use variant::Variant;

fn main() {
    let o = Opts::parse();
    outcome::main("cpcost", || run(&o))
}

fn run(o: &Opts) -> Result<i32, String> {
    let bins = Binaries::find(o.files.supervisor.as_deref())?;
    let out = o.files.out("cpcost");
    let mut b = Bench::start("cpcost", Some(&out))?;
    let (variants, cy, s) = (Variant::all(o), &o.cycle, &o.slicing);
    let letters: Vec<String> = variants.iter().map(|v| v.letter().to_string()).collect();
    eprintln!(
        "cpcost: {} s per variant ({}) at {} µs, {} slice(s) of ≤ {} s, SCHED_FIFO {} on CPU {}",
        s.duration,
        letters.join(", "),
        cy.period_us,
        s.count(),
        s.slice,
        cy.priority,
        cy.cpu
    );
    eprintln!("cpcost: supervisor {}", bins.supervisor.display());
    b.warn_not_rt();
    let mut r = slice::run(o, &bins, &mut b, &variants)?;
    let wall = b.t0.elapsed().as_secs_f64();
    let groups: Vec<Merged> = variants.iter().map(|&v| Merged::of(v, &r.done)).collect();
    if groups.iter().all(|g| !g.g.ran()) {
        return b.nothing_measured(r.interrupted, &r.failures);
    }
    for g in &groups {
        g.judge(r.interrupted || !r.failures.is_empty(), &mut r.failures);
    }
    let warnings: Vec<String> = r.warnings.into_iter().collect();
    print!("{}", report::text(o, &b, &groups, &warnings, r.leftovers));
    let path = out.join("cpcost.json");
    let status = (r.interrupted, r.failures.as_slice());
    let json = report::json(o, &b, wall, &groups, &warnings, status);
    if let Err(e) = write_json(&path, &json) {
        r.failures.push(e);
    }
    Ok(b.end(&[&path], r.interrupted, &r.failures, true))
}
