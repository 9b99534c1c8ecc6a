//! Soak bench: spurious homing failures. Many one-axis switch homings at the
//! supervisor's default settings (part of them with stress-ng on the other
//! CPU), then parallel homings of a 64-axis machine; counts every result
//! that failed with ERR 12 / EXERR 40 (feedback lost) or anything else, and
//! every axis that ended not homed. See `bench/README.md`.
//!
//! This file is the sequence — checks, stage, the one-axis part, the
//! 64-axis part, the report — and the modules are its steps: [`cli`] the
//! command line, [`ctx`] what every homing shares, [`one_axis`] (with
//! [`daemon_block`] and [`evidence`]) and [`axes64`] the parts, [`figures`]
//! what a part counts, [`report`] the table and soak.json.

mod axes64;
mod cli;
mod ctx;
mod daemon_block;
mod evidence;
mod figures;
mod one_axis;
mod report;

use clap::Parser;
use cli::{Opts, Which};
use ctx::{sup, Ctx};
use figures::Part;
use motion_bench::drive::Binaries;
use motion_bench::machine;
use motion_bench::proc;
use motion_bench::sys;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let o = Opts::parse();
    std::process::exit(match real_main(&o) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("soak: FAILED: {e}");
            1
        }
    });
}

fn real_main(o: &Opts) -> Result<i32, String> {
    if o.cpu >= sys::cpus() {
        eprintln!(
            "soak: --cpu {}: this machine has {} CPUs",
            o.cpu,
            sys::cpus()
        );
        return Ok(2);
    }
    if !(0.0..=1.0).contains(&o.stress_share) || o.block == 0 {
        eprintln!("soak: --stress-share must be within 0..=1 and --block at least 1");
        return Ok(2);
    }
    let state = std::env::temp_dir().join(format!("motion-bench-soak-{}", std::process::id()));
    if let Some(w) = o.print_config {
        let s = sup(o, "mbsoak");
        let (text, _) = match w {
            Which::One => machine::one_switch_axis_with(&s, state.to_str())?,
            Which::Axes64 => machine::axes64_with(&s)?,
        };
        print!("{text}");
        return Ok(0);
    }
    proc::install_stop_handler();
    let b = Binaries::find(o.supervisor.as_deref())?;
    let other_cpu = if o.cpu == 0 { 1 } else { 0 };
    let stressed_blocks_needed = o.stress_share > 0.0 || o.stress64;
    if stressed_blocks_needed && (sys::cpus() < 2 || sys::find_in_path("stress-ng").is_none()) {
        return Err(
            "stress-ng (apt-get install -y stress-ng) and a second CPU are needed \
                    (or --stress-share 0)"
                .into(),
        );
    }
    std::fs::create_dir_all(&state).map_err(|e| format!("{}: {e}", state.display()))?;
    let _rm = RemoveDir(state.clone());
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out.display()))?;
    let mut ctx = Ctx::new(b, state.clone(), other_cpu);
    let (preemption, _) = sys::preemption();
    eprintln!(
        "soak: {} one-axis homings via {:?} in blocks of {} ({:.0} % with stress-ng on CPU {other_cpu}), \
         {} parallel homings of 64 axes{}; {} µs cycle, SCHED_FIFO {} on CPU {}; kernel {} ({preemption}); load {}",
        o.homings,
        o.via,
        o.block,
        o.stress_share * 100.0,
        o.runs64,
        if o.stress64 { " with stress-ng" } else { "" },
        o.period_us,
        o.priority,
        o.cpu,
        sys::kernel(),
        sys::loadavg()
    );
    for t in sys::other_rt_tasks() {
        eprintln!("soak: WARNING: another real-time thread is running: {t}");
    }
    let t0 = Instant::now();
    let load_before = sys::loadavg();

    let one = one_axis::run(o, &mut ctx)?;
    let mut interrupted = one.interrupted;

    // --- 64 axes in parallel, each a fresh `home`
    let mut axes64 = Part::default();
    if !interrupted && o.runs64 > 0 && axes64::run(o, &mut ctx, &mut axes64)? {
        interrupted = true;
    }
    let wall = t0.elapsed().as_secs_f64();
    if proc::stop_requested() {
        interrupted = true;
    }

    let out = report::Outcome {
        unloaded: one.unloaded,
        stressed: one.stressed,
        axes64,
        interrupted,
        wall,
        load_before,
        preemption,
        other_cpu,
    };
    print!("{}", report::text(o, &ctx, &out));
    let report = report::json(o, &ctx, &out);
    let path = o.out.join("soak.json");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    )
    .map_err(|e| format!("{}: {e}", path.display()))?;
    println!("files: {}", path.display());
    if interrupted {
        eprintln!("soak: interrupted: the counts above are partial");
        return Ok(130);
    }
    Ok(0)
}

/// Removes a directory on drop.
struct RemoveDir(PathBuf);

impl Drop for RemoveDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
