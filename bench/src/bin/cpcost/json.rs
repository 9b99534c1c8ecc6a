//! OUT/cpcost.json: everything the table prints, plus the environment, the
//! settings and the run's status, for programs that read the results (no
//! parsing of the text).

use crate::cli::Opts;
use crate::summary::{ratio_of, Group};
use motion_bench::hist::Pct;
use motion_bench::host::{Env, OtherRt};
use serde_json::{json, Value};
use std::path::Path;

/// Writes the report to `path`; `failures` are the run's so far.
#[allow(clippy::too_many_arguments)]
pub fn write(
    path: &Path,
    o: &Opts,
    env: &Env,
    wall_s: f64,
    groups: &[Group],
    other_rt: &OtherRt,
    warnings: &[String],
    interrupted: bool,
    failures: &[String],
) -> Result<(), String> {
    let a = &groups[0];
    let mut variants = serde_json::Map::new();
    let mut ratio = serde_json::Map::new();
    for g in groups {
        variants.insert(g.variant.key().into(), group_json(o, g));
        if g.variant != a.variant && g.ran() && a.ran() {
            ratio.insert(
                format!("{}_over_a", g.variant.letter()),
                json!({
                    "wakeup_us": ratio_json(&g.w, &a.w),
                    "compute_us": ratio_json(&g.c, &a.c),
                    "io_roundtrip_us": ratio_json(&g.r, &a.r),
                    "supervisor_cpu": ratio_of(g.cpu, a.cpu).map(round2),
                    "motion_io_cpu": ratio_of(g.io_cpu, a.io_cpu).map(round2),
                }),
            );
        }
    }
    let report = json!({
        "bench": "cpcost",
        "machine": "demo (deploy/demo.toml, 4 axes, idle)",
        "period_us": o.period_us,
        "priority": o.priority,
        "cpu": o.cpu,
        "duration_s_per_variant": o.duration,
        "slice_s": o.slice,
        "status_every_ms": o.status_every_ms,
        "stats_every_ms": o.stats_every_ms,
        "wall_s": wall_s,
        "environment": {
            "kernel": env.kernel,
            "preemption": env.preemption,
            "preempt_rt": env.is_rt,
            "cpus": env.cpus,
            "rt_throttling": env.throttling,
            "load_before": env.load_before,
            "load_after": motion_bench::sys::loadavg(),
            "other_rt_threads": other_rt.list(),
        },
        "variants": variants,
        "ratios": ratio,
        "warnings": warnings,
        "status": {
            "ok": failures.is_empty() && !interrupted,
            "interrupted": interrupted,
            "failures": failures,
        },
    });
    std::fs::write(
        path,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    )
    .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

fn group_json(o: &Opts, g: &Group) -> Value {
    if !g.ran() {
        return json!({ "ran": false });
    }
    let (status_ms, stats_ms) = (g.clients.status.ms_p50_max(), g.clients.stats.ms_p50_max());
    json!({
        "ran": true,
        "what": g.variant.describe(o),
        "seconds": g.secs,
        "slices": g.slices,
        "cycles": g.cycles,
        "deadline_misses": g.misses,
        "deadline_miss_ratio": g.miss_ratio,
        "late_replies": g.late,
        "hlog_samples": g.hlog_samples,
        "wakeup_us": g.w,
        "compute_us": g.c,
        "io_roundtrip_us": g.r,
        "supervisor_cpu_share": g.cpu,
        "motion_io_cpu_share": g.io_cpu,
        "clients_attached_after_s": g.attach_s,
        "clients": if g.variant.serves() { json!({
            "made": g.clients.made(),
            "failed": g.clients.failed(),
            "cut_off": g.clients.cut_off(),
            "watch": g.clients.watch,
            "status": g.clients.status,
            "status_request_ms_p50_max": status_ms,
            "stats": g.clients.stats,
            "stats_request_ms_p50_max": stats_ms,
            "home": g.clients.home,
            "home_request_ms_p50_max": g.clients.home.ms_p50_max(),
        }) } else { Value::Null },
    })
}

fn round2(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

/// `a / b` per column, two decimals; null where `b` is 0.
fn ratio_json(a: &Pct, b: &Pct) -> Value {
    let keys = ["min", "p50", "p99", "p999", "p9999", "max"];
    let mut m = serde_json::Map::new();
    for (k, v) in keys.iter().zip(a.ratio(b)) {
        m.insert(k.to_string(), v.map_or(Value::Null, |x| json!(round2(x))));
    }
    Value::Object(m)
}
