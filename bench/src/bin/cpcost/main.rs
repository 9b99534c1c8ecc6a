//! Control-plane cost bench: what the control and status services (and the
//! thread that serves them) cost the real-time cycle. `motion-supervisor
//! run` on the demo machine, idle, in alternating slices: (a) with
//! `--no-control-plane`, (b) with the control plane and a deployed
//! machine's clients attached (an HMI watching the status, a PLC polling it,
//! statistics now and then), (c) with `--homing` also X homed again and
//! again. See `bench/README.md`.
//!
//! This file is the sequence — find the binaries, set the stage, run the
//! slices, merge, judge, report — and the modules are its steps:
//!
//! * [`cli`] the command line; [`host`] the machine it runs on;
//!   [`variant`] what is compared;
//! * [`slice`] one supervisor run of one variant, with [`clients`] attached;
//! * [`summary`] the slices merged per variant and the verdict;
//! * [`table`] the printed report, [`json`] cpcost.json.

mod cli;
mod clients;
mod json;
mod slice;
mod summary;
mod table;
mod variant;

use clap::Parser;
use cli::Opts;
use motion_bench::drive::Binaries;
use motion_bench::hist::us;
use motion_bench::host::{Env, OtherRt};
use motion_bench::proc;
use slice::{Outcome, Slice};
use std::collections::BTreeSet;
use std::path::PathBuf;
use std::time::Instant;
use summary::Group;
use variant::Variant;

fn main() {
    let o = Opts::parse();
    proc::install_stop_handler();
    std::process::exit(match run(&o) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("cpcost: FAILED: {e}");
            1
        }
    });
}

/// Slices of `--slice` s that make up `--duration` (the last one shorter).
fn slice_count(o: &Opts) -> usize {
    (o.duration / o.slice - 1e-9).ceil().max(1.0) as usize
}

/// Seconds of slice `i`; the last one at least 2 s (the clients must
/// attach).
fn slice_len(o: &Opts, i: usize) -> f64 {
    (o.duration - i as f64 * o.slice).min(o.slice).max(2.0)
}

fn run(o: &Opts) -> Result<i32, String> {
    let b = Binaries::find(o.supervisor.as_deref())?;
    let env = Env::probe();
    let pid = std::process::id();
    let tmp = std::env::temp_dir().join(format!("motion-bench-cpcost-{pid}"));
    std::fs::create_dir_all(&tmp).map_err(|e| format!("cannot create {}: {e}", tmp.display()))?;
    let _tmp_guard = RemoveDir(tmp.clone());
    std::fs::create_dir_all(&o.out)
        .map_err(|e| format!("cannot create {}: {e}", o.out.display()))?;

    let variants = Variant::all(o);
    let slices = slice_count(o);
    eprintln!(
        "cpcost: {} s per variant ({}) at {} µs, {} slice(s) of ≤ {} s, SCHED_FIFO {} on CPU {}",
        o.duration,
        variants
            .iter()
            .map(|v| v.letter().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        o.period_us,
        slices,
        o.slice,
        o.priority,
        o.cpu
    );
    eprintln!("cpcost: supervisor {}", b.supervisor.display());
    if !env.is_rt {
        eprintln!(
            "cpcost: kernel is not PREEMPT_RT ({}): the numbers are upper bounds",
            env.preemption
        );
    }
    let mut other_rt = OtherRt::new("cpcost");
    other_rt.note("before the bench");

    let t0 = Instant::now();
    let plan = slice::Plan {
        o,
        b: &b,
        tmp: &tmp,
        pid,
    };
    let mut done: Vec<(Variant, Slice)> = Vec::new();
    let mut failures = Vec::new();
    let mut warnings = BTreeSet::new();
    let (mut leftover_runs, mut leftover_files) = (0, 0);
    let mut interrupted = false;
    'slices: for i in 0..slices {
        let len = slice_len(o, i);
        // odd slices in reverse order: neither variant always follows the other
        let order: Vec<Variant> = if i % 2 == 0 {
            variants.clone()
        } else {
            variants.iter().rev().copied().collect()
        };
        for v in order {
            if proc::stop_requested() {
                interrupted = true;
                break 'slices;
            }
            let (outcome, w, left) = slice::run(&plan, v, i, len)?;
            warnings.extend(w);
            if !left.is_empty() {
                leftover_runs += 1;
                leftover_files += left.len();
            }
            match outcome {
                Outcome::Done(s) => {
                    progress(i, slices, v, &s);
                    done.push((v, *s));
                }
                Outcome::Failed(e) => {
                    failures.push(format!(
                        "slice {} {}: motion-supervisor: {e}",
                        i + 1,
                        v.label()
                    ));
                    break 'slices;
                }
                Outcome::Interrupted => {
                    interrupted = true;
                    break 'slices;
                }
            }
        }
        other_rt.note("during the bench");
    }
    let wall = t0.elapsed().as_secs_f64();

    let groups: Vec<Group> = variants
        .iter()
        .map(|&v| {
            let s: Vec<&Slice> = done.iter().filter(|d| d.0 == v).map(|d| &d.1).collect();
            Group::of(v, &s)
        })
        .collect();
    if groups.iter().all(|g| !g.ran()) {
        for f in &failures {
            eprintln!("cpcost: FAILED: {f}");
        }
        if interrupted {
            eprintln!("cpcost: interrupted (signal {})", proc::stop_signal());
            return Ok(130);
        }
        return Err(failures.join("; "));
    }
    for g in &groups {
        g.judge(interrupted || !failures.is_empty(), &mut failures);
    }
    let warnings: Vec<String> = warnings.into_iter().collect();
    print!(
        "{}",
        table::text(
            o,
            &groups,
            &table::Notes {
                env: &env,
                other_rt: &other_rt,
                warnings: &warnings,
                leftovers: (leftover_runs, leftover_files),
            }
        )
    );
    let json_path = o.out.join("cpcost.json");
    if let Err(e) = json::write(
        &json_path,
        o,
        &env,
        wall,
        &groups,
        &other_rt,
        &warnings,
        interrupted,
        &failures,
    ) {
        failures.push(e);
    }
    println!("files: {}", json_path.display());

    if interrupted {
        eprintln!(
            "cpcost: interrupted (signal {}): results above are partial",
            proc::stop_signal()
        );
        return Ok(130);
    }
    if failures.is_empty() {
        println!("cpcost: OK");
        Ok(0)
    } else {
        for f in &failures {
            println!("cpcost: FAILED: {f}");
        }
        Ok(1)
    }
}

/// One line per slice on stderr.
fn progress(i: usize, n: usize, v: Variant, s: &Slice) {
    let c = &s.clients;
    eprintln!(
        "cpcost: slice {}/{} {:<22} {:>6} cycles, wake-up p99 {:>6} µs, compute p50/p99 {}/{} µs, {} miss(es), CPU {}{}",
        i + 1,
        n,
        v.label(),
        s.cycles,
        us(s.json_wakeup.p99),
        us(s.json_compute.p50),
        us(s.json_compute.p99),
        s.misses,
        s.cpu.map_or("-".into(), |c| format!("{:.1} %", c * 100.0)),
        if v.serves() {
            format!(
                "; {} request(s), {} failed, {} cut off",
                c.made(),
                c.failed(),
                c.cut_off()
            )
        } else {
            String::new()
        }
    );
}

/// Removes a directory on drop: the bench's temporary configs and interval
/// logs go whichever way `run` returns.
struct RemoveDir(PathBuf);

impl Drop for RemoveDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_cover_the_duration() {
        let o = Opts::try_parse_from(["cpcost", "--cpu", "0", "--duration", "25", "--slice", "10"])
            .unwrap();
        assert_eq!(slice_count(&o), 3);
        assert_eq!(
            (slice_len(&o, 0), slice_len(&o, 1), slice_len(&o, 2)),
            (10.0, 10.0, 5.0)
        );
        let o = Opts::try_parse_from(["cpcost", "--cpu", "0", "--duration", "60"]).unwrap();
        assert_eq!(slice_count(&o), 6);
        assert_eq!(slice_len(&o, 5), 10.0);
    }
}
