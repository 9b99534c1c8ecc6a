//! Soak bench: spurious homing failures. Many one-axis switch homings at the
//! supervisor's default settings (part of them with stress-ng on the other
//! CPU), then parallel homings of a 64-axis machine; counts every result
//! that failed with ERR 12 / EXERR 40 (feedback lost) or anything else, and
//! every axis that ended not homed. See `bench/README.md`.
//!
//! The sequence: checks, stage, the one-axis and the 64-axis [`parts`]
//! (a block through one daemon: [`daemon_block`]), the [`report`]; [`Ctx`]
//! is what every homing shares.

mod cli;
mod daemon_block;
mod parts;
mod report;

use clap::Parser;
use cli::{Opts, Which};
use motion_bench::bins::{self, Binaries};
use motion_bench::drive;
use motion_bench::outcome::{self, write_json, Bench};
use motion_bench::{host, machine, proc};
use report::Part;
use std::path::PathBuf;

fn main() {
    let o = Opts::parse();
    outcome::main("soak", || run(&o))
}

fn run(o: &Opts) -> Result<i32, String> {
    if !(0.0..=1.0).contains(&o.stress_share) || o.block == 0 {
        eprintln!("soak: --stress-share must be within 0..=1 and --block at least 1");
        return Ok(2);
    }
    if let Some(w) = o.print_config {
        let (s, state) = (o.cycle.supervisor("mbsoak"), outcome::tmp_dir("soak"));
        let (text, _) = match w {
            Which::One => machine::one_switch_axis_with(&s, state.to_str())?,
            Which::Axes64 => machine::axes64_with(&s)?,
        };
        print!("{text}");
        return Ok(0);
    }
    let bins = Binaries::find(o.files.supervisor.as_deref())?;
    let stress = o.stress_share > 0.0 || o.stress64;
    if stress && (host::cpus() < 2 || bins::find_in_path("stress-ng").is_none()) {
        let needed = "stress-ng (apt-get install -y stress-ng) and a second CPU are needed";
        return Err(format!("{needed} (or --stress-share 0)"));
    }
    let out = o.files.out("");
    let b = Bench::start("soak", Some(&out))?;
    let mut ctx = Ctx {
        b: bins,
        tmp: b.tmp.clone(),
        evidence: out.join("soak-evidence"),
        other_cpu: o.cycle.other_cpu(),
        leftovers: vec![],
        not_cleaned: vec![],
        seq: 0,
    };
    let (cy, h, other) = (&o.cycle, &b.host, ctx.other_cpu);
    let with = if o.stress64 { " with stress-ng" } else { "" };
    eprintln!(
        "soak: {} one-axis homings via {:?} in blocks of {} ({:.0} % with stress-ng on CPU {other}), \
         {} parallel homings of 64 axes{with}; {} µs cycle, SCHED_FIFO {} on CPU {}; kernel {} ({}); load {}",
        o.homings, o.via, o.block, o.stress_share * 100.0, o.runs64,
        cy.period_us, cy.priority, cy.cpu, h.kernel, h.preemption, h.load
    );
    let one = parts::one_axis(o, &mut ctx)?;
    let mut axes64 = Part::default();
    let interrupted = one.interrupted
        || (o.runs64 > 0 && parts::axes64(o, &mut ctx, &mut axes64)?)
        || proc::stop_requested();
    let res = report::Outcome {
        parts: [one.unloaded, one.stressed, axes64],
        interrupted,
        wall: b.t0.elapsed().as_secs_f64(),
    };
    print!("{}", report::text(o, &b, &ctx, &res));
    let path = out.join("soak.json");
    write_json(&path, &report::json(o, &b, &ctx, &res))?;
    Ok(b.end(&[&path], interrupted, &[], false))
}

/// What every homing of the soak shares: the binaries, the temporary
/// directory, the CPU for stress-ng and the spy, unique service prefixes,
/// and the shared memory runs left behind (reported, then cleaned).
pub struct Ctx {
    pub b: Binaries,
    /// Configs and traces of the runs.
    pub tmp: PathBuf,
    /// Where what tells why a homing failed is kept.
    pub evidence: PathBuf,
    /// Not the cycle's CPU: stress-ng and the spy go there.
    pub other_cpu: usize,
    /// What runs left in /dev/shm (cleaned by the bench).
    pub leftovers: Vec<String>,
    /// ... and what of it could not be cleaned.
    pub not_cleaned: Vec<String>,
    seq: u32,
}

impl Ctx {
    /// A unique service prefix for this bench's next supervisor.
    pub fn prefix(&mut self, tag: &str) -> String {
        self.seq += 1;
        format!("mbs{}{tag}{}", std::process::id(), self.seq)
    }

    /// The machine `text` written to the temporary directory for `prefix`.
    pub fn config(&self, prefix: &str, text: &str) -> Result<PathBuf, String> {
        drive::write_config(&self.tmp, prefix, text)
    }

    /// Reports what `prefix` left behind, then cleans it (see
    /// [`drive::clean_leftovers`]).
    pub fn check_leftovers(&mut self, prefix: &str) {
        let (found, remaining) = drive::clean_leftovers(prefix);
        if !found.is_empty() {
            let all = match remaining.is_empty() {
                true => "cleaned",
                false => "NOT all cleaned",
            };
            eprintln!("soak: WARNING: {prefix} left {} ({all})", found.join(", "));
            self.leftovers.extend(found);
            self.not_cleaned.extend(remaining);
        }
    }
}
