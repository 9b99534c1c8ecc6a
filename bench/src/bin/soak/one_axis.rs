//! The one-axis part: `--homings` homings of the one-axis switch machine in
//! blocks of `--block`, a share of the blocks (`--stress-share`) with
//! stress-ng on the other CPU, spread evenly (a block is stressed if that
//! keeps the stressed share closest to the goal). Each block is one daemon
//! (`--via daemon`, see [`daemon_block`]) or one `motion-supervisor home`
//! per homing (`--via home`, [`home_block`]).

use crate::cli::{Opts, Via};
use crate::ctx::{sup, Ctx};
use crate::daemon_block;
use crate::figures::{count_home_run, Part};
use motion_bench::drive;
use motion_bench::machine;
use motion_bench::proc;
use std::process::Command;
use std::time::{Duration, Instant};

/// The one-axis part unloaded and stressed.
pub struct OneAxis {
    pub unloaded: Part,
    pub stressed: Part,
    pub interrupted: bool,
}

/// Runs the blocks. An `Err` is a block that could not be run.
pub fn run(o: &Opts, ctx: &mut Ctx) -> Result<OneAxis, String> {
    // --- one axis, in blocks; stressed blocks spread evenly
    let mut unloaded = Part::default();
    let mut stressed = Part::default();
    let blocks = o.homings.div_ceil(o.block);
    let mut interrupted = false;
    let mut stressed_so_far = 0u32;
    for k in 0..blocks {
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        let n = o.block.min(o.homings - k * o.block);
        // stress this block if that keeps the stressed share closest to the goal
        let want = ((f64::from(k + 1) * o.stress_share).round() as u32).min(k + 1);
        let loaded = stressed_so_far < want;
        if loaded {
            stressed_so_far += 1;
        }
        let part = if loaded { &mut stressed } else { &mut unloaded };
        let t = Instant::now();
        let _stress = if loaded {
            Some(drive::stress(
                ctx.other_cpu,
                Duration::from_secs_f64(f64::from(n) * (o.timeout + 10.0) + 60.0),
            )?)
        } else {
            None
        };
        let r = match o.via {
            Via::Daemon => daemon_block::run(o, ctx, n, part),
            Via::Home => home_block(o, ctx, n, part),
        };
        part.seconds += t.elapsed().as_secs_f64();
        eprintln!(
            "soak: block {}/{blocks} ({}): {} homings, {} ok, {} feedback lost, {} other errors, {} not homed, {} lost between, {} without result; {:.0} s",
            k + 1,
            if loaded { "stress-ng" } else { "no load" },
            n,
            part.tally.ok,
            part.tally.feedback_lost,
            part.tally.other_errors,
            part.tally.not_homed,
            part.tally.lost_between,
            part.tally.run_failures,
            t.elapsed().as_secs_f64()
        );
        match r {
            Ok(false) => {}
            Ok(true) => {
                interrupted = true;
                break;
            }
            Err(e) => return Err(format!("block {}: {e}", k + 1)),
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
        let (text, _) = machine::one_switch_axis_with(&sup(o, &prefix), ctx.tmp.to_str())?;
        let cfg = ctx.tmp.join(format!("{prefix}.toml"));
        std::fs::write(&cfg, text).map_err(|e| format!("{}: {e}", cfg.display()))?;
        let mut cmd = Command::new(&ctx.b.supervisor);
        cmd.arg("home")
            .arg("--config")
            .arg(&cfg)
            .args(["--json", "--timeout"])
            .arg(format!("{}", o.timeout))
            .args(["--service-prefix", &prefix]);
        let run = drive::home_run(
            &mut cmd,
            "motion-supervisor home",
            Duration::from_secs_f64(o.timeout + 60.0),
        )?;
        if run.ended.interrupted {
            return Ok(true);
        }
        count_home_run(part, &prefix, &run);
        ctx.check_leftovers(&prefix);
        let _ = std::fs::remove_file(&cfg);
    }
    Ok(false)
}
