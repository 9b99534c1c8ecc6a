//! The JSON report (`.json`): everything the table prints, plus per-tool
//! sample counts, the environment and the run's status, for programs that
//! read a run's results (no parsing of the text).

use crate::cli::Opts;
use crate::slices::Collected;
use crate::summary::Summary;
use motion_bench::hist::Pct;
use motion_bench::host::{Env, OtherRt};
use serde_json::{json, Value};
use std::path::Path;
use std::time::Duration;

/// Writes the report to `path`; `hlog` and `svg` are the other files,
/// `failures` the run's so far (its status).
#[allow(clippy::too_many_arguments)]
pub fn write(
    path: &Path,
    o: &Opts,
    env: &Env,
    wall: Duration,
    m: &Summary,
    c: &Collected,
    other_rt: &OtherRt,
    (hlog, svg): (&Path, &Path),
    failures: &[String],
) -> Result<(), String> {
    let report = json!({
        "period_us": o.period_us,
        "priority": o.priority,
        "cpu": o.cpu,
        "duration_s_per_tool": o.duration,
        "slice_s": o.slice,
        "stress": o.stress,
        "wall_s": wall.as_secs_f64(),
        "environment": {
            "kernel": env.kernel,
            "preemption": env.preemption,
            "preempt_rt": env.is_rt,
            "cpus": env.cpus,
            "rt_throttling": env.throttling,
            "other_rt_threads": other_rt.list(),
        },
        "ours": {
            "machine": "demo (deploy/demo.toml, 4 axes, idle)",
            "seconds": m.ours.secs,
            "slices": m.ours.slices,
            "cycles": m.ours.cycles,
            "deadline_misses": m.ours.misses,
            "deadline_miss_ratio": m.ours.miss_ratio,
            "late_replies": m.ours.late,
            "hlog_samples": m.ours.wake.len(),
            "wakeup_us": serde_json::to_value(m.ours.w).unwrap_or_default(),
            "compute_us": serde_json::to_value(m.ours.c).unwrap_or_default(),
            "io_roundtrip_us": serde_json::to_value(m.ours.r).unwrap_or_default(),
            "warnings": c.warnings.iter().cloned().collect::<Vec<_>>(),
        },
        "ours_axes64": if m.axes64.ran() { json!({
            "machine": "64 axes (motion_bench::machine::axes64_with), motionctl home --parallel again and again",
            "seconds": m.axes64.secs,
            "slices": m.axes64.slices,
            "cycles": m.axes64.cycles,
            "deadline_misses": m.axes64.misses,
            "deadline_miss_ratio": m.axes64.miss_ratio,
            "late_replies": m.axes64.late,
            "hlog_samples": m.axes64.wake.len(),
            "wakeup_us": serde_json::to_value(m.axes64.w).unwrap_or_default(),
            "compute_us": serde_json::to_value(m.axes64.c).unwrap_or_default(),
            "io_roundtrip_us": serde_json::to_value(m.axes64.r).unwrap_or_default(),
            "homing": c.homing64.json(),
        }) } else { json!({"skipped": true}) },
        "ours_ethercat": if m.ecat.ran() { json!({
            "seconds": m.ecat.secs,
            "slices": m.ecat.slices,
            "cycles": m.ecat.cycles,
            "deadline_misses": m.ecat.misses,
            "deadline_miss_ratio": m.ecat.miss_ratio,
            "late_replies": m.ecat.late,
            "wakeup_us": serde_json::to_value(m.ecat.w).unwrap_or_default(),
            "compute_us": serde_json::to_value(m.ecat.c).unwrap_or_default(),
            "io_roundtrip_us": serde_json::to_value(m.ecat.r).unwrap_or_default(),
            "bus_roundtrip_us_per_slice": c.bus_runs.iter().map(|b| json!({
                "cycles": b.cycles, "min": b.min, "p50": b.p50, "p99": b.p99,
                "p999": b.p999, "max": b.max, "lost_frames": b.lost,
            })).collect::<Vec<_>>(),
        }) } else { json!({"skipped": true}) },
        "cyclictest": if m.ct.ran() { json!({
            "command": c.ct_command,
            "seconds": m.ct.secs,
            "slices": m.ct.slices,
            "wakeup_us": serde_json::to_value(m.ct.w).unwrap_or_default(),
            "deadline_misses": Value::Null,
            "deadline_misses_note": "not counted (cyclictest skips missed periods)",
            "samples_at_or_above_period": m.ct.ge_period,
            "histogram_overflows": m.ct.total.overflows,
        }) } else { json!({"skipped": true}) },
        "ratio_ours_over_cyclictest": if m.ct.ran() { ratio_json(&m.ours.w, &m.ct.w) } else { Value::Null },
        "ratio_axes64_over_cyclictest": if m.ct.ran() && m.axes64.ran() { ratio_json(&m.axes64.w, &m.ct.w) } else { Value::Null },
        "files": { "hlog": hlog, "svg": svg },
        "status": {
            "ok": failures.is_empty() && !c.interrupted,
            "interrupted": c.interrupted,
            "failures": failures,
        },
    });
    std::fs::write(
        path,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    )
    .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// `a / b` per column, two decimals; null where `b` is 0.
fn ratio_json(a: &Pct, b: &Pct) -> Value {
    let r = a.ratio(b);
    let keys = ["min", "p50", "p99", "p999", "p9999", "max"];
    let mut m = serde_json::Map::new();
    for (k, v) in keys.iter().zip(r) {
        m.insert(
            k.to_string(),
            v.map_or(Value::Null, |x| json!((x * 100.0).round() / 100.0)),
        );
    }
    Value::Object(m)
}
