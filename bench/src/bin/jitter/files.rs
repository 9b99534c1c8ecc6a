//! The files written to `--out`: the interval log (every slice's wake-up
//! histogram in ns, tagged by variant and timed from the bench's start, for
//! HdrHistogram's tools), the latency plot of every variant and cyclictest
//! on the same axes, and the JSON report (everything printed, plus sample
//! counts, the environment and the run's status).

use crate::cli::Opts;
use crate::report::Summary;
use crate::slices::{Collected, Variant};
use motion_bench::hlog;
use motion_bench::outcome::{status, with, write_json, Bench};
use motion_bench::plot::{latency::Series, RGBColor};
use motion_bench::slice::{ratio_json, Group};
use serde_json::{json, Value};
use std::path::Path;
use std::time::{Duration, SystemTime};

/// Writes the slices of `c` to `path` in the order they ran; `t0_wall` is
/// the bench's start.
pub fn hlog(
    path: &Path,
    o: &Opts,
    b: &Bench,
    t0_wall: SystemTime,
    c: &Collected,
) -> Result<(), String> {
    let ours = Variant::ALL.iter().flat_map(|&v| {
        let tag = v.names().tag;
        c.ours[v as usize]
            .iter()
            .map(move |s| (tag, s.start, Duration::from_secs_f64(s.len), &s.m.wakeup))
    });
    let mut iv: Vec<hlog::Interval> = ours.collect();
    iv.extend(c.ct.iter().map(|s| ("cyclictest", s.start, s.len, &s.hdr)));
    iv.sort_by_key(|i| i.1);
    let cy = &o.cycle;
    let comments = [
        &format!(
            "motion-bench jitter: wake-up latency, ns; period {} us, SCHED_FIFO {} on CPU {}",
            cy.period_us, cy.priority, cy.cpu
        ),
        "tags: ours = motion-supervisor run (wake-up), demo machine idle; ours_axes64 = the same with 64 axes homing in parallel again and again; ours_ethercat = the same with motion-io --backend ethercat (--ethercat), cyclictest = cyclictest (1 us bins, recorded at the bin's lower edge)",
        &format!("kernel {} ({})", b.host.kernel, b.host.preemption),
    ];
    hlog::write(path, &comments, t0_wall, &iv)
}

/// The plot of `m` in `path`.
pub fn svg(path: &Path, o: &Opts, b: &Bench, m: &Summary) -> Result<(), String> {
    let (cy, env) = (&o.cycle, &b.host);
    let title = format!(
        "Wake-up latency, period {} µs: motion-supervisor vs cyclictest, {:.0} s each",
        cy.period_us,
        m.group(Variant::Demo).secs
    );
    let sub1 = format!(
        "Linux {} · {} · {} CPUs",
        env.kernel, env.preemption, env.cpus
    );
    let load = if o.stress {
        "stress-ng on the other CPU"
    } else {
        "no load"
    };
    let ct = if m.ct.ran() {
        "cyclictest in 1 µs bins"
    } else {
        "cyclictest not run"
    };
    let sub2 = format!(
        "both SCHED_FIFO {} on CPU {} · {load} · {ct}",
        cy.priority, cy.cpu
    );
    let mut series: Vec<Series> = (m.ours.iter().zip(Variant::ALL))
        .filter(|(g, _)| g.ran())
        .map(|(g, v)| Series {
            name: v.names().curve,
            colour: v.names().colour,
            hist: &g.wake,
        })
        .collect();
    if m.ct.ran() {
        let colour = RGBColor(214, 39, 40);
        series.push(Series {
            name: "cyclictest",
            colour,
            hist: &m.ct.hdr,
        });
    }
    let period = f64::from(cy.period_us);
    motion_bench::plot::latency::draw(path, &title, &[&sub1, &sub2], &series, period)
}

/// The JSON report in `path`; `files` are the other two, `failures` the
/// run's so far (its status).
pub fn json(
    path: &Path,
    (o, b, m, c): (&Opts, &Bench, &Summary, &Collected),
    wall_s: f64,
    files: [&Path; 2],
    failures: &[String],
) -> Result<(), String> {
    let skipped = || json!({"skipped": true});
    let (demo, a64, ecat) = (
        m.group(Variant::Demo),
        m.group(Variant::Axes64),
        m.group(Variant::Ethercat),
    );
    let (ct_ran, h) = (m.ct.ran(), &c.homing64);
    let bus: Vec<Value> = (c.bus_runs.iter())
        .map(|b| json!({"cycles": b.cycles, "min": b.min, "p50": b.p50, "p99": b.p99, "p999": b.p999, "max": b.max, "lost_frames": b.lost}))
        .collect();
    let report = json!({
        "period_us": o.cycle.period_us,
        "priority": o.cycle.priority,
        "cpu": o.cycle.cpu,
        "duration_s_per_tool": o.slicing.duration,
        "slice_s": o.slicing.slice,
        "stress": o.stress,
        "wall_s": wall_s,
        "environment": b.environment(),
        "ours": with(Group::json(demo), json!({
            "machine": "demo (deploy/demo.toml, 4 axes, idle)",
            "hlog_samples": demo.wake.len(),
            "warnings": c.warnings,
        })),
        "ours_axes64": if a64.ran() { with(Group::json(a64), json!({
            "machine": "64 axes (motion_bench::machine::axes64_with), motionctl home --parallel again and again",
            "hlog_samples": a64.wake.len(),
            "homing": {
                "started": h.started,
                "all_homed": h.ok,
                "with_failed_axis": h.failed,
                "cut_off_by_slice_end": h.cut_off,
                "axes": h.tally,
                "mean_duration_s": h.mean_s(),
            },
        })) } else { skipped() },
        "ours_ethercat": if ecat.ran() {
            with(Group::json(ecat), json!({ "bus_roundtrip_us_per_slice": bus }))
        } else { skipped() },
        "cyclictest": if ct_ran { json!({
            "command": c.ct_command,
            "seconds": m.ct.secs,
            "slices": m.ct.slices,
            "wakeup_us": m.ct.w,
            "deadline_misses": Value::Null,
            "deadline_misses_note": "not counted (cyclictest skips missed periods)",
            "samples_at_or_above_period": m.ct.ge_period,
            "histogram_overflows": m.ct.overflows,
        }) } else { skipped() },
        "ratio_ours_over_cyclictest": if ct_ran { ratio_json(&demo.w, &m.ct.w) } else { Value::Null },
        "ratio_axes64_over_cyclictest": if ct_ran && a64.ran() { ratio_json(&a64.w, &m.ct.w) } else { Value::Null },
        "files": { "hlog": files[0], "svg": files[1] },
        "status": status(c.interrupted, failures),
    });
    write_json(path, &report)
}
