//! The two parts. One axis: `--homings` homings of the one-axis switch
//! machine in blocks of `--block`, a share of the blocks (`--stress-share`)
//! with stress-ng on the other CPU, spread evenly (a block is stressed if
//! that keeps the stressed share closest to the goal); each block one daemon
//! (`--via daemon`, see [`daemon_block`]) or one `motion-supervisor home`
//! per homing (`--via home`). 64 axes: `--runs64` parallel homings, each a
//! fresh `motion-supervisor home --parallel --json` (with stress-ng for
//! `--stress64`).

use crate::cli::{Opts, Via};
use crate::daemon_block;
use crate::report::{count_home_run, Part};
use crate::Ctx;
use motion_bench::homing::{self, HomeRun};
use motion_bench::{machine, proc};
use motion_report::AxisResult;
use std::process::Command;
use std::time::{Duration, Instant};

/// The one-axis part unloaded and stressed.
pub struct OneAxis {
    pub unloaded: Part,
    pub stressed: Part,
    pub interrupted: bool,
}

/// stress-ng on the other CPU, bounded by its own timeout for `homings`.
fn stress(o: &Opts, ctx: &Ctx, homings: u32) -> Result<motion_bench::proc::Running, String> {
    let bound = f64::from(homings) * (o.timeout + 10.0) + 60.0;
    proc::stress(ctx.other_cpu, Duration::from_secs_f64(bound))
}

/// Runs the one-axis blocks. An `Err` is a block that could not be run.
pub fn one_axis(o: &Opts, ctx: &mut Ctx) -> Result<OneAxis, String> {
    let (mut unloaded, mut stressed) = (Part::default(), Part::default());
    let blocks = o.homings.div_ceil(o.block);
    let (mut interrupted, mut stressed_so_far) = (false, 0u32);
    for k in 0..blocks {
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        let n = o.block.min(o.homings - k * o.block);
        // stress this block if that keeps the stressed share closest to the goal
        let want = ((f64::from(k + 1) * o.stress_share).round() as u32).min(k + 1);
        let loaded = stressed_so_far < want;
        stressed_so_far += u32::from(loaded);
        let part = if loaded { &mut stressed } else { &mut unloaded };
        let t = Instant::now();
        let _stress = loaded.then(|| stress(o, ctx, n)).transpose()?;
        let r = match o.via {
            Via::Daemon => daemon_block::run(o, ctx, n, part),
            Via::Home => home_block(o, ctx, n, part),
        };
        part.seconds += t.elapsed().as_secs_f64();
        let y = &part.tally;
        eprintln!(
            "soak: block {}/{blocks} ({}): {n} homings, {} ok, {} feedback lost, {} other errors, {} not homed, {} lost between, {} without result; {:.0} s",
            k + 1,
            if loaded { "stress-ng" } else { "no load" },
            y.ok, y.feedback_lost, y.other_errors, y.not_homed, y.lost_between, y.run_failures,
            t.elapsed().as_secs_f64()
        );
        if r.map_err(|e| format!("block {}: {e}", k + 1))? {
            interrupted = true;
            break;
        }
    }
    Ok(OneAxis {
        unloaded,
        stressed,
        interrupted,
    })
}

/// `n` homings, each its own `motion-supervisor home --json`. Ok(true):
/// interrupted.
fn home_block(o: &Opts, ctx: &mut Ctx, n: u32, part: &mut Part) -> Result<bool, String> {
    for _ in 0..n {
        if proc::stop_requested() {
            return Ok(true);
        }
        let prefix = ctx.prefix("h");
        let (text, _) =
            machine::one_switch_axis_with(&o.cycle.supervisor(&prefix), ctx.tmp.to_str())?;
        if fresh_home(o, ctx, part, (&prefix, &prefix), &text, false)?.is_none() {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The 64-axis homings into `axes64`. Ok(true): interrupted.
pub fn axes64(o: &Opts, ctx: &mut Ctx, axes64: &mut Part) -> Result<bool, String> {
    let t = Instant::now();
    let _stress = o.stress64.then(|| stress(o, ctx, o.runs64)).transpose()?;
    let mut interrupted = false;
    for i in 0..o.runs64 {
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        let prefix = ctx.prefix("p");
        let (text, _) = machine::axes64_with(&o.cycle.supervisor(&prefix))?;
        let what = format!("64-axis run {}", i + 1);
        let Some(run) = fresh_home(o, ctx, axes64, (&prefix, &what), &text, true)? else {
            interrupted = true;
            break;
        };
        let count = |f: fn(&AxisResult) -> bool| run.rows.iter().filter(|r| f(r)).count();
        fn lost(r: &AxisResult) -> bool {
            r.er && r.err == 12 && r.exerr == 40
        }
        eprintln!(
            "soak: 64 axes, run {}/{}: {} of {} axes ok, {} feedback lost, {} other errors, {} not homed; {:.1} s",
            i + 1, o.runs64, count(AxisResult::succeeded), run.rows.len(), count(lost),
            count(|r| r.er && !lost(r)), count(|r| !r.homed), run.seconds
        );
    }
    axes64.seconds = t.elapsed().as_secs_f64();
    Ok(interrupted)
}

/// One fresh `motion-supervisor home --json [--parallel]` of the machine
/// `text` under `prefix`, counted into `part` as `what`, its leftovers
/// checked; None if it was interrupted.
fn fresh_home(
    o: &Opts,
    ctx: &mut Ctx,
    part: &mut Part,
    (prefix, what): (&str, &str),
    text: &str,
    parallel: bool,
) -> Result<Option<HomeRun>, String> {
    let cfg = ctx.config(prefix, text)?;
    let mut cmd = Command::new(&ctx.b.supervisor);
    cmd.args(["home", "--config"]).arg(&cfg);
    cmd.args(parallel.then_some("--parallel"));
    cmd.args(["--json", "--timeout", &o.timeout.to_string()]);
    cmd.args(["--service-prefix", prefix]);
    let limit = Duration::from_secs_f64(o.timeout + 60.0);
    let run = homing::home_run(&mut cmd, "motion-supervisor home", limit)?;
    if run.ended.interrupted {
        return Ok(None);
    }
    count_home_run(part, what, &run);
    ctx.check_leftovers(prefix);
    let _ = std::fs::remove_file(&cfg);
    Ok(Some(run))
}
