//! Control-plane cost bench: what the control and status services (and the
//! thread that serves them) cost the real-time cycle. `motion-supervisor
//! run` on the demo machine, idle, in alternating slices: (a) with
//! `--no-control-plane`, (b) with the control plane and a deployed
//! machine's clients attached (an HMI watching the status, a PLC polling it,
//! statistics now and then), (c) with `--homing` also X homed again and
//! again. See `bench/README.md`.
//!
//! This file is the sequence — find the binaries, run the slices, merge,
//! judge, report — and the modules are its steps: [`cli`] the command line,
//! [`variant`] what is compared, [`slice`] one supervisor run with
//! [`clients`] attached, [`report`] the merge, the verdict, the table and
//! cpcost.json.

mod cli;
mod clients;
mod report;
mod slice;
mod variant;

use clap::Parser;
use cli::Opts;
use motion_bench::drive::Binaries;
use motion_bench::outcome::{self, write_json, Bench};
use motion_bench::proc;
use motion_bench::table::us;
use report::Merged;
use slice::{Done, Outcome};
use std::collections::BTreeSet;
use variant::Variant;

fn main() {
    let o = Opts::parse();
    outcome::main("cpcost", || run(&o))
}

fn run(o: &Opts) -> Result<i32, String> {
    let bins = Binaries::find(o.files.supervisor.as_deref())?;
    let out = o.files.out("cpcost");
    let mut b = Bench::start("cpcost", Some(&out))?;
    let (variants, cy) = (Variant::all(o), &o.cycle);
    let letters: Vec<String> = variants.iter().map(|v| v.letter().to_string()).collect();
    eprintln!(
        "cpcost: {} s per variant ({}) at {} µs, {} slice(s) of ≤ {} s, SCHED_FIFO {} on CPU {}",
        o.slicing.duration,
        letters.join(", "),
        cy.period_us,
        o.slicing.count(),
        o.slicing.slice,
        cy.priority,
        cy.cpu
    );
    eprintln!("cpcost: supervisor {}", bins.supervisor.display());
    b.warn_not_rt();
    let mut r = slices(o, &bins, &mut b, &variants)?;
    let wall = b.t0.elapsed().as_secs_f64();
    let groups: Vec<Merged> = (variants.iter())
        .map(|&v| {
            Merged::of(
                v,
                &r.done
                    .iter()
                    .filter(|d| d.0 == v)
                    .map(|d| &d.1)
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    if groups.iter().all(|g| !g.g.ran()) {
        return b.nothing_measured(r.interrupted, &r.failures);
    }
    for g in &groups {
        g.judge(r.interrupted || !r.failures.is_empty(), &mut r.failures);
    }
    let warnings: Vec<String> = r.warnings.into_iter().collect();
    print!("{}", report::text(o, &b, &groups, &warnings, r.leftovers));
    let path = out.join("cpcost.json");
    let json = report::json(
        o,
        &b,
        wall,
        &groups,
        &warnings,
        (r.interrupted, &r.failures),
    );
    if let Err(e) = write_json(&path, &json) {
        r.failures.push(e);
    }
    Ok(b.end(&[&path], r.interrupted, &r.failures, true))
}

/// What the slices left.
struct Ran {
    done: Vec<(Variant, Done)>,
    failures: Vec<String>,
    /// The supervisors' warnings (each once).
    warnings: BTreeSet<String>,
    /// Runs that left files in /dev/shm (cleaned by the bench), files left.
    leftovers: (usize, usize),
    interrupted: bool,
}

/// The alternating slices, odd ones in reverse order (neither variant always
/// follows the other), until a failure or a stop request.
fn slices(o: &Opts, bins: &Binaries, b: &mut Bench, variants: &[Variant]) -> Result<Ran, String> {
    let mut r = Ran {
        done: Vec::new(),
        failures: Vec::new(),
        warnings: BTreeSet::new(),
        leftovers: (0, 0),
        interrupted: false,
    };
    let n = o.slicing.count();
    'slices: for i in 0..n {
        let mut order = variants.to_vec();
        if i % 2 == 1 {
            order.reverse();
        }
        for v in order {
            if proc::stop_requested() {
                r.interrupted = true;
                break 'slices;
            }
            let (outcome, w, left) = slice::run((o, bins, &b.tmp), v, i, o.slice_len(i))?;
            r.warnings.extend(w);
            if !left.is_empty() {
                r.leftovers = (r.leftovers.0 + 1, r.leftovers.1 + left.len());
            }
            match outcome {
                Outcome::Done(d) => {
                    progress(i, n, v, &d);
                    r.done.push((v, *d));
                }
                Outcome::Failed(e) => {
                    let (k, label) = (i + 1, v.label());
                    r.failures
                        .push(format!("slice {k} {label}: motion-supervisor: {e}"));
                    break 'slices;
                }
                Outcome::Interrupted => {
                    r.interrupted = true;
                    break 'slices;
                }
            }
        }
        b.other_rt.note("during the bench");
    }
    Ok(r)
}

/// One line per slice on stderr.
fn progress(i: usize, n: usize, v: Variant, d: &Done) {
    let (l, c) = (&d.slice.lat, &d.clients);
    let cpu = d
        .slice
        .cpu
        .map_or("-".into(), |c| format!("{:.1} %", c * 100.0));
    let requests = match v.serves() {
        true => format!(
            "; {} request(s), {} failed, {} cut off",
            c.made(),
            c.failed(),
            c.cut_off()
        ),
        false => String::new(),
    };
    eprintln!(
        "cpcost: slice {}/{n} {:<22} {:>6} cycles, wake-up p99 {:>6} µs, compute p50/p99 {}/{} µs, {} miss(es), CPU {cpu}{requests}",
        i + 1,
        v.label(),
        l.cycles,
        us(l.wakeup_us.p99),
        us(l.compute_us.p50),
        us(l.compute_us.p99),
        l.deadline_misses
    );
}
