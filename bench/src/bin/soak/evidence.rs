//! What is kept of a failed homing so that it can be explained afterwards:
//! the homing recorded cycle by cycle (`--trace`), and its row, timing,
//! `motionctl status` and `stats` right after, in OUT/soak-evidence/.

use crate::cli::Opts;
use crate::ctx::Ctx;
use motion_bench::drive::{self, HomeRun};
use motion_bench::sys;
use motion_report::AxisResult;
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// One homing of X recorded by `motionctl trace X --home --out CSV`; its
/// result row from `motionctl status` once the trace has ended.
pub fn traced_home(
    motionctl: &Path,
    prefix: &str,
    csv: &Path,
    timeout: f64,
) -> Result<HomeRun, String> {
    let mut cmd = Command::new(motionctl);
    cmd.args([
        "--service-prefix",
        prefix,
        "trace",
        "X",
        "--home",
        "--json",
        "--out",
    ])
    .arg(csv)
    .args(["--timeout", &format!("{timeout}")]);
    let mut run = drive::home_run(
        &mut cmd,
        "motionctl trace",
        Duration::from_secs_f64(timeout + 30.0),
    )?;
    let status = drive::status(motionctl, prefix);
    let a = status.as_ref().and_then(|v| v.axes.first());
    run.rows = match a {
        Some(a) => vec![AxisResult {
            name: a.name.clone(),
            pc: a.pc,
            er: a.er,
            err: a.err,
            exerr: a.exerr,
            homed: a.homed,
            error: a.error.clone(),
            duration_s: Some(a.elapsed_s),
            ..AxisResult::default()
        }],
        _ => Vec::new(),
    };
    if let Some(st) = status {
        let trace = run.json.take();
        run.json = Some(json!({"trace": trace, "status": st}));
    }
    Ok(run)
}

/// Keeps what tells why homing `i` of `prefix` failed: its row, when it
/// happened, `motionctl status` and `stats` right after, and its trace.
pub fn keep_evidence(
    o: &Opts,
    ctx: &Ctx,
    prefix: &str,
    i: u32,
    t_block: Instant,
    run: &HomeRun,
    csv: &Path,
) {
    let dir = o.out.join("soak-evidence");
    if std::fs::create_dir_all(&dir).is_err() {
        return;
    }
    let stats = Command::new(&ctx.b.motionctl)
        .args(["--service-prefix", prefix, "stats", "--json"])
        .output()
        .ok()
        .and_then(|x| serde_json::from_slice::<Value>(&x.stdout).ok());
    let status = drive::status(&ctx.b.motionctl, prefix);
    let v = json!({
        "prefix": prefix,
        "homing": i,
        "seconds_into_block": t_block.elapsed().as_secs_f64(),
        "seconds_this_homing": run.seconds,
        "rows": run.rows,
        "output": run.json,
        "ended": run.ended.describe(),
        "stderr_tail": drive::tail(&run.ended.stderr, 20),
        "status_after": status,
        "stats_after": stats,
        "loadavg": sys::loadavg(),
    });
    let _ = std::fs::write(
        dir.join(format!("{prefix}-h{i}.json")),
        serde_json::to_string_pretty(&v).unwrap_or_default() + "\n",
    );
    if csv.exists() {
        let _ = std::fs::copy(csv, dir.join(format!("{prefix}-h{i}.csv")));
    }
}
