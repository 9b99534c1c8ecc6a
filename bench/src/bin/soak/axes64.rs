//! The 64-axis part: `--runs64` parallel homings of the 64-axis machine,
//! each a fresh `motion-supervisor home --parallel --json` (with stress-ng
//! on the other CPU for `--stress64`), counted like the one-axis homings.

use crate::cli::Opts;
use crate::ctx::{sup, Ctx};
use crate::figures::{count_home_run, Part};
use motion_bench::drive;
use motion_bench::machine;
use motion_bench::proc;
use std::process::Command;
use std::time::{Duration, Instant};

/// Runs the 64-axis homings into `axes64`. Ok(true): interrupted.
pub fn run(o: &Opts, ctx: &mut Ctx, axes64: &mut Part) -> Result<bool, String> {
    let mut interrupted = false;
    let t = Instant::now();
    let _stress = if o.stress64 {
        Some(drive::stress(
            ctx.other_cpu,
            Duration::from_secs_f64(f64::from(o.runs64) * (o.timeout + 10.0) + 60.0),
        )?)
    } else {
        None
    };
    for i in 0..o.runs64 {
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        let prefix = ctx.prefix("p");
        let (text, _) = machine::axes64_with(&sup(o, &prefix))?;
        let cfg = ctx.tmp.join(format!("{prefix}.toml"));
        std::fs::write(&cfg, text).map_err(|e| format!("{}: {e}", cfg.display()))?;
        let mut cmd = Command::new(&ctx.b.supervisor);
        cmd.arg("home")
            .arg("--config")
            .arg(&cfg)
            .args(["--parallel", "--json", "--timeout"])
            .arg(format!("{}", o.timeout))
            .args(["--service-prefix", &prefix]);
        let run = drive::home_run(
            &mut cmd,
            "motion-supervisor home",
            Duration::from_secs_f64(o.timeout + 60.0),
        )?;
        if run.ended.interrupted {
            interrupted = true;
            break;
        }
        count_home_run(axes64, &format!("64-axis run {}", i + 1), &run);
        ctx.check_leftovers(&prefix);
        let _ = std::fs::remove_file(&cfg);
        eprintln!(
            "soak: 64 axes, run {}/{}: {} of {} axes ok, {} feedback lost, {} other errors, {} not homed; {:.1} s",
            i + 1,
            o.runs64,
            run.rows.iter().filter(|r| r.succeeded()).count(),
            run.rows.len(),
            run.rows.iter().filter(|r| r.er && r.err == 12 && r.exerr == 40).count(),
            run.rows.iter().filter(|r| r.er && !(r.err == 12 && r.exerr == 40)).count(),
            run.rows.iter().filter(|r| !r.homed).count(),
            run.seconds
        );
    }
    axes64.seconds = t.elapsed().as_secs_f64();
    Ok(interrupted)
}
