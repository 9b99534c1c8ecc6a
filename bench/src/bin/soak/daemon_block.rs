//! One block of one-axis homings through one daemon (`--via daemon`): one
//! `motion-supervisor run`, then `--block` homings of X through motionctl
//! (or `motionctl trace` with `--trace`), each after the first preceded by
//! a status check that X is still homed (counted as "lost between"). With
//! `--spy` a spy records the block's frames; a block with a failure keeps
//! them, and the daemon's output, as evidence.

use crate::cli::Opts;
use crate::ctx::{sup, Ctx};
use crate::evidence::{keep_evidence, traced_home};
use crate::figures::Part;
use motion_bench::drive;
use motion_bench::machine;
use motion_bench::proc;
use motion_bench::spy::Spy;
use std::time::{Duration, Instant};

/// `n` homings of X through one daemon. Ok(true): interrupted.
pub fn run(o: &Opts, ctx: &mut Ctx, n: u32, part: &mut Part) -> Result<bool, String> {
    let prefix = ctx.prefix("d");
    let (text, _) = machine::one_switch_axis_with(&sup(o, &prefix), ctx.tmp.to_str())?;
    let cfg = ctx.tmp.join(format!("{prefix}.toml"));
    std::fs::write(&cfg, text).map_err(|e| format!("{}: {e}", cfg.display()))?;
    let mut daemon = drive::spawn_run(&ctx.b, &cfg, &prefix, None, None)?;
    if let Err(e) = drive::wait_until_ready(
        &ctx.b.motionctl,
        &prefix,
        &mut daemon,
        Duration::from_secs(20),
    ) {
        let ended = drive::stop_run(daemon, Duration::from_secs(20));
        if ended.interrupted || proc::stop_requested() {
            return Ok(true);
        }
        return Err(format!(
            "{e} ({}; {})",
            ended.describe(),
            drive::tail(&ended.stderr, 5)
        ));
    }
    let mut spy = if o.spy {
        match Spy::start(&prefix, "io", ctx.other_cpu, 70, 400_000, |_| {}) {
            Ok(s) => Some(s),
            Err(e) => {
                part.tally.note(format!("{prefix}: {e}"));
                None
            }
        }
    } else {
        None
    };
    let mut interrupted = false;
    let mut failed_in_block = false;
    let t_block = Instant::now();
    for i in 0..n {
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        if i > 0 {
            // still homed since the last homing?
            match drive::status(&ctx.b.motionctl, &prefix) {
                Some(v) => {
                    let a = v.axes.first().cloned().unwrap_or_default();
                    if !a.homed && part.tally.details.len() < 1000 {
                        part.tally.lost_between += 1;
                        part.tally.note(format!(
                            "{prefix} before homing {}: X not homed any more (err {}/{}, {})",
                            i + 1,
                            a.err,
                            a.exerr,
                            a.error.as_deref().unwrap_or("")
                        ));
                    }
                }
                None => part
                    .tally
                    .note(format!("{prefix} before homing {}: no status", i + 1)),
            }
        }
        let csv = ctx.tmp.join(format!("{prefix}-{}.csv", i + 1));
        let run = if o.trace {
            traced_home(&ctx.b.motionctl, &prefix, &csv, o.timeout)?
        } else {
            drive::ctl_home(&ctx.b.motionctl, &prefix, &["X"], false, o.timeout)?
        };
        if run.ended.interrupted {
            interrupted = true;
            break;
        }
        let what = format!("{prefix} homing {}", i + 1);
        if !part.tally.add(&what, &run) {
            failed_in_block = true;
            keep_evidence(o, ctx, &prefix, i + 1, t_block, &run, &csv);
            if !daemon.running() {
                part.tally.note(format!("{prefix}: the daemon ended"));
                break;
            }
        }
        let _ = std::fs::remove_file(&csv);
    }
    let frames = spy.as_mut().map(Spy::finish);
    drop(spy);
    let ended = drive::stop_run(daemon, Duration::from_secs(30));
    if failed_in_block {
        let dir = o.out.join("soak-evidence");
        if let Some(r) = &frames {
            let _ = std::fs::create_dir_all(&dir);
            if let Err(e) = r.write_csv(&dir.join(format!("{prefix}.frames.csv"))) {
                eprintln!("soak: cannot write the spy's frames: {e}");
            }
        }
        let _ = std::fs::write(dir.join(format!("{prefix}.stderr")), &ended.stderr);
        let _ = std::fs::write(dir.join(format!("{prefix}.run.json")), &ended.stdout);
    }
    match drive::last_json(&ended.stdout) {
        Some(v) => {
            part.figures.add(&v);
            for w in v["warnings"].as_array().into_iter().flatten() {
                if let Some(w) = w.as_str() {
                    if !part.figures.warnings.iter().any(|x| x == w) {
                        part.figures.warnings.push(w.to_string());
                    }
                }
            }
        }
        None => part.tally.note(format!(
            "{prefix}: the daemon printed no report ({}; {})",
            ended.describe(),
            drive::tail(&ended.stderr, 5)
        )),
    }
    ctx.check_leftovers(&prefix);
    let _ = std::fs::remove_file(&cfg);
    Ok(interrupted)
}
