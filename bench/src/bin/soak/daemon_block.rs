//! One block of one-axis homings through one daemon (`--via daemon`): one
//! `motion-supervisor run`, then `--block` homings of X through motionctl
//! (or `motionctl trace` with `--trace`), each after the first preceded by
//! a status check that X is still homed (counted as "lost between"). With
//! `--spy` a spy records the block's frames. A failed homing keeps, in
//! OUT/soak-evidence/, what tells why: its row, timing, `motionctl status`
//! and `stats` right after, its trace; the block's frames and the daemon's
//! output.

use crate::cli::Opts;
use crate::report::Part;
use crate::Ctx;
use motion_bench::drive;
use motion_bench::homing::{self, HomeRun};
use motion_bench::proc::Ended;
use motion_bench::spy::{Recording, Spy};
use motion_bench::{host, machine, proc};
use motion_report::RunReport;
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// `n` homings of X through one daemon. Ok(true): interrupted.
pub fn run(o: &Opts, ctx: &mut Ctx, n: u32, part: &mut Part) -> Result<bool, String> {
    let prefix = ctx.prefix("d");
    let (text, _) = machine::one_switch_axis_with(&o.cycle.supervisor(&prefix), ctx.tmp.to_str())?;
    let cfg = ctx.config(&prefix, &text)?;
    let mut daemon = match drive::start_run(&ctx.b, &cfg, &prefix, Duration::from_secs(20)) {
        Ok(d) => d,
        Err(_) if proc::stop_requested() => return Ok(true),
        Err(e) => return Err(e),
    };
    let mut spy = None;
    if o.spy {
        match Spy::start(&prefix, "io", ctx.other_cpu, 70, 400_000, |_| {}) {
            Ok(s) => spy = Some(s),
            Err(e) => part.tally.note(format!("{prefix}: {e}")),
        }
    }
    let (mut interrupted, mut failed_in_block, t_block) = (false, false, Instant::now());
    for i in 1..=n {
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        if i > 1 {
            still_homed(ctx, &prefix, i, part);
        }
        let csv = ctx.tmp.join(format!("{prefix}-{i}.csv"));
        let run = match o.trace {
            true => homing::traced_home(&ctx.b.motionctl, &prefix, "X", &csv, o.timeout)?,
            false => homing::ctl_home(&ctx.b.motionctl, &prefix, &["X"], false, o.timeout)?,
        };
        if run.ended.interrupted {
            interrupted = true;
            break;
        }
        if !part.tally.add(&format!("{prefix} homing {i}"), &run) {
            failed_in_block = true;
            keep_evidence(ctx, &prefix, i, t_block, &run, &csv);
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
        keep_block(ctx, &prefix, frames.as_ref(), &ended);
    }
    let report =
        homing::last_json(&ended.stdout).and_then(|v| serde_json::from_value::<RunReport>(v).ok());
    match report {
        Some(r) => part.figures.add(&r),
        None => part.tally.note(format!(
            "{prefix}: the daemon printed no report ({}; {})",
            ended.describe(),
            proc::tail(&ended.stderr, 5)
        )),
    }
    ctx.check_leftovers(&prefix);
    let _ = std::fs::remove_file(&cfg);
    Ok(interrupted)
}

/// Before homing `i`: is X still homed since the last one?
fn still_homed(ctx: &Ctx, prefix: &str, i: u32, part: &mut Part) {
    let Some(st) = drive::status(&ctx.b.motionctl, prefix) else {
        return part
            .tally
            .note(format!("{prefix} before homing {i}: no status"));
    };
    let a = st.axes.first().cloned().unwrap_or_default();
    if !a.homed && part.tally.details.len() < 1000 {
        part.tally.lost_between += 1;
        let error = a.error.as_deref().unwrap_or("");
        part.tally.note(format!(
            "{prefix} before homing {i}: X not homed any more (err {}/{}, {error})",
            a.err, a.exerr
        ));
    }
}

/// Keeps what tells why homing `i` of `prefix` failed: its row, when it
/// happened, `motionctl status` and `stats` right after, and its trace.
fn keep_evidence(ctx: &Ctx, prefix: &str, i: u32, t_block: Instant, run: &HomeRun, csv: &Path) {
    if std::fs::create_dir_all(&ctx.evidence).is_err() {
        return;
    }
    let stats = Command::new(&ctx.b.motionctl)
        .args(["--service-prefix", prefix, "stats", "--json"])
        .output()
        .ok()
        .and_then(|x| serde_json::from_slice::<Value>(&x.stdout).ok());
    let v = json!({
        "prefix": prefix,
        "homing": i,
        "seconds_into_block": t_block.elapsed().as_secs_f64(),
        "seconds_this_homing": run.seconds,
        "rows": run.rows,
        "output": run.json,
        "ended": run.ended.describe(),
        "stderr_tail": proc::tail(&run.ended.stderr, 20),
        "status_after": drive::status(&ctx.b.motionctl, prefix),
        "stats_after": stats,
        "loadavg": host::loadavg(),
    });
    let _ =
        motion_bench::outcome::write_json(&ctx.evidence.join(format!("{prefix}-h{i}.json")), &v);
    if csv.exists() {
        let _ = std::fs::copy(csv, ctx.evidence.join(format!("{prefix}-h{i}.csv")));
    }
}

/// Keeps the block's frames (`--spy`) and the daemon's output, after a
/// homing of the block failed.
fn keep_block(ctx: &Ctx, prefix: &str, frames: Option<&Recording>, ended: &Ended) {
    let file = |ext: &str| ctx.evidence.join(format!("{prefix}.{ext}"));
    if let Some(r) = frames {
        let _ = std::fs::create_dir_all(&ctx.evidence);
        if let Err(e) = r.write_csv(&file("frames.csv")) {
            eprintln!("soak: cannot write the spy's frames: {e}");
        }
    }
    let _ = std::fs::write(file("stderr"), &ended.stderr);
    let _ = std::fs::write(file("run.json"), &ended.stdout);
}
