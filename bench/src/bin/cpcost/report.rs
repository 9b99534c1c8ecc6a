//! The slices of each variant merged (`motion_bench::slice::Group`, with the
//! clients' counts), the verdict (missed deadlines above `MAX_MISS_RATIO`,
//! client requests that failed while the supervisor ran, a variant that
//! produced nothing; percentiles never fail the run), the printed report and
//! cpcost.json with the same figures.

use crate::cli::Opts;
use crate::slice::Done;
use crate::variant::Variant;
use motion_bench::clients::{Clients, Count, HOME, STATS, STATUS, WATCH};
use motion_bench::outcome::{status, with, Bench};
use motion_bench::slice::{ratio_json, Group, MAX_MISS_RATIO};
use motion_bench::table::{line, ratio, ratio_cells, ratio_of, row, thousands, us_cells, Text};
use motion_report::{table::COLUMNS, Percentiles};
use serde_json::{json, Value};

/// The columns of the tables (p99.99 left out: a minute of cycles gives it
/// 6 samples).
const COLS: [usize; 5] = [0, 1, 2, 3, 5];

/// One variant's slices, merged.
pub struct Merged {
    pub variant: Variant,
    pub g: Group,
    /// Mean seconds from a run's start to its clients attached.
    pub attach_s: Option<f64>,
    pub clients: Clients,
}

impl Merged {
    /// The slices of `variant` among `done`.
    pub fn of(variant: Variant, done: &[Done]) -> Self {
        let done: Vec<&Done> = done.iter().filter(|d| d.variant == variant).collect();
        let mut clients = Clients::default();
        done.iter().for_each(|d| clients.merge(&d.clients));
        let attach: Vec<f64> = done.iter().filter_map(|d| d.attach_s).collect();
        let n = attach.len() as f64;
        let attach_s = (n > 0.0).then(|| attach.iter().sum::<f64>() / n);
        let g = Group::of(&done.iter().map(|d| &d.slice).collect::<Vec<_>>());
        Merged {
            variant,
            g,
            attach_s,
            clients,
        }
    }

    /// What fails the run in this variant's figures.
    pub fn judge(&self, interrupted: bool, failures: &mut Vec<String>) {
        let (name, g, failed) = (self.variant.label(), &self.g, self.clients.failed());
        if !g.ran() && !interrupted {
            failures.push(format!("{name}: no slice measured"));
        }
        if let Some(r) = g.too_many_misses() {
            let (m, c) = (g.misses, g.cycles);
            failures.push(format!(
                "{name}: {m} of {c} cycles missed their deadline {r}"
            ));
        }
        if failed > 0 {
            failures.push(format!(
                "{name}: {failed} client request(s) failed while the supervisor ran"
            ));
        }
    }
}

/// A share of one core, in %.
fn pct(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{:.1} %", x * 100.0))
}

/// The report's text; `groups[0]` is (a), then (b) and (c). `leftovers`:
/// runs that left files in /dev/shm, and the files.
pub fn text(
    o: &Opts,
    b: &Bench,
    groups: &[Merged],
    warnings: &[String],
    leftovers: (usize, usize),
) -> String {
    let (mut t, a, cy, h) = (Text::default(), &groups[0].g, &o.cycle, &b.host);
    t.line(format!(
        "== cpcost: what the control plane costs the cycle — period {} µs ({:.0} Hz), SCHED_FIFO {} on CPU {}, \
         demo machine (4 axes) idle, {:.0} s per variant in {} slice(s) of ≤ {} s, variants alternating",
        cy.period_us, 1e6 / f64::from(cy.period_us), cy.priority, cy.cpu, a.secs, a.slices, o.slicing.slice
    ));
    let (head, throttling, before, after) = (
        h.head(),
        &h.throttling,
        &h.load,
        motion_bench::host::loadavg(),
    );
    t.line(format!(
        "{head} | RT throttling {throttling} | load {before} before, {after} after"
    ));
    if !h.is_rt {
        t.line("not a PREEMPT_RT kernel: latencies are upper bounds; compare the rows (same machine, alternating slices)");
    }
    for m in groups {
        t.line(format!(
            "{:<26}{}",
            m.variant.label(),
            m.variant.describe(o)
        ));
    }
    latencies(&mut t, groups);
    cycles(&mut t, groups);
    for m in groups[1..].iter().filter(|m| m.g.ran()) {
        client_requests(&mut t, o, m);
    }
    t.line(format!(
        "percentiles from the supervisors' interval logs ({} of {} cycles in (a)); min/max exact from their JSON reports",
        thousands(a.wake.len()),
        thousands(a.cycles)
    ));
    if leftovers.0 > 0 {
        t.line(format!(
            "/dev/shm: {} run(s) left {} file(s) (a motionctl's node outlived the daemon's clean-up); cleaned by the bench",
            leftovers.0, leftovers.1
        ));
    }
    b.other_rt_warning(&mut t, "ran during the bench");
    warnings
        .iter()
        .for_each(|w| t.line(format!("supervisor warning: {w}")));
    t.0
}

/// One latency of a variant.
type Pick = fn(&Group) -> &Percentiles;

/// Per latency one row per variant, and the ratios to (a).
fn latencies(t: &mut Text, groups: &[Merged]) {
    let a = &groups[0].g;
    let sections: [(&str, Pick); 3] = [
        ("wake-up latency (µs)", |g| &g.w),
        ("compute (µs)", |g| &g.c),
        ("I/O round trip (µs)", |g| &g.r),
    ];
    for (title, f) in sections {
        t.line("");
        t.line(row(title, 26, COLS.map(|i| COLUMNS[i])));
        for m in groups.iter().filter(|m| m.g.ran()) {
            let name = format!("  {}", m.variant.label());
            t.line(row(&name, 26, us_cells(f(&m.g), &COLS)));
        }
        for m in groups[1..].iter().filter(|m| m.g.ran() && a.ran()) {
            let name = format!("  ratio ({})/(a)", m.variant.letter());
            t.line(row(&name, 26, ratio_cells(f(&m.g), f(a), &COLS)));
        }
    }
    t.line("");
}

/// Cycles, deadline misses, late replies and CPU use per variant.
fn cycles(t: &mut Text, groups: &[Merged]) {
    const WIDTHS: [i32; 6] = [-26, 10, 22, 14, 16, 15];
    let a = &groups[0].g;
    let head = "|cycles|deadline misses|late replies|supervisor CPU|motion-io CPU";
    t.line(line(&WIDTHS, head.split('|')));
    for m in groups.iter().filter(|m| m.g.ran()) {
        let g = &m.g;
        let (name, misses) = (
            format!("  {}", m.variant.label()),
            format!("{} ({:.3} %)", g.misses, g.miss_ratio * 100.0),
        );
        let cells = [
            name,
            thousands(g.cycles),
            misses,
            g.late.to_string(),
            pct(g.cpu),
            pct(g.io_cpu),
        ];
        t.line(line(&WIDTHS, cells));
    }
    for m in groups[1..].iter().filter(|m| m.g.ran() && a.ran()) {
        let (g, name) = (&m.g, format!("  ratio ({})/(a)", m.variant.letter()));
        let [s, i] = [ratio_of(g.cpu, a.cpu), ratio_of(g.io_cpu, a.io_cpu)].map(ratio);
        t.line(line(
            &WIDTHS,
            [name, String::new(), String::new(), String::new(), s, i],
        ));
    }
    let max = MAX_MISS_RATIO * 100.0;
    t.line(format!(
        "  (CPU: the process with all its threads, as a share of one core over each run; deadline-miss limit {max:.0} %)"
    ));
    t.line("");
}

/// A variant's client requests per kind.
fn client_requests(t: &mut Text, o: &Opts, m: &Merged) {
    let (c, attach) = (&m.clients, m.attach_s.unwrap_or(0.0));
    t.line(format!(
        "client requests {} ({} made, {} failed, {} cut off; attached {attach:.2} s after each run's start):",
        m.variant.label(),
        thousands(c.made()),
        c.failed(),
        c.cut_off()
    ));
    let kinds = [
        ("status --watch (one per slice)".to_string(), WATCH),
        (
            format!("status --json every {} ms", o.status_every_ms),
            STATUS,
        ),
        (format!("stats --json every {} ms", o.stats_every_ms), STATS),
        ("home X --json, back to back".into(), HOME),
    ];
    let shown = if m.variant == Variant::Homing { 4 } else { 3 };
    for (what, k) in &kinds[..shown] {
        t.line(requests(what, &c.0[*k]));
    }
    c.details()
        .take(10)
        .for_each(|d| t.line(format!("    {d}")));
}

/// One kind of request on one line.
fn requests(what: &str, c: &Count) -> String {
    let time = c.ms_p50_max().map_or(String::new(), |(p50, max)| {
        format!(", start → exit p50 {p50:.0} ms, max {max:.0} ms")
    });
    let (made, failed, cut) = (thousands(c.made), c.failed, c.cut_off);
    format!("  {what:<34} {made:>6} made, {failed} failed, {cut} cut off by a slice's end{time}")
}

/// A variant's object in cpcost.json.
fn group_json(o: &Opts, m: &Merged) -> Value {
    let (g, c) = (&m.g, &m.clients);
    if !g.ran() {
        return json!({ "ran": false });
    }
    let ms = |k: usize| c.0[k].ms_p50_max();
    let clients = json!({
        "made": c.made(),
        "failed": c.failed(),
        "cut_off": c.cut_off(),
        "watch": c.0[WATCH],
        "status": c.0[STATUS],
        "status_request_ms_p50_max": ms(STATUS),
        "stats": c.0[STATS],
        "stats_request_ms_p50_max": ms(STATS),
        "home": c.0[HOME],
        "home_request_ms_p50_max": ms(HOME),
    });
    let more = json!({
        "ran": true,
        "what": m.variant.describe(o),
        "hlog_samples": g.wake.len(),
        "supervisor_cpu_share": g.cpu,
        "motion_io_cpu_share": g.io_cpu,
        "clients_attached_after_s": m.attach_s,
        "clients": if m.variant.serves() { clients } else { Value::Null },
    });
    with(g.json(), more)
}

/// cpcost.json; `status`: interrupted, and the run's failures so far.
pub fn json(
    o: &Opts,
    b: &Bench,
    wall_s: f64,
    groups: &[Merged],
    warnings: &[String],
    (interrupted, failures): (bool, &[String]),
) -> Value {
    let (a, round2) = (&groups[0].g, |x: f64| motion_report::round(x, 2));
    let variants: serde_json::Map<String, Value> = groups
        .iter()
        .map(|m| (m.variant.key().into(), group_json(o, m)))
        .collect();
    let ratios: serde_json::Map<String, Value> = (groups[1..].iter())
        .filter(|m| m.g.ran() && a.ran())
        .map(|m| {
            let g = &m.g;
            let r = json!({
                "wakeup_us": ratio_json(&g.w, &a.w),
                "compute_us": ratio_json(&g.c, &a.c),
                "io_roundtrip_us": ratio_json(&g.r, &a.r),
                "supervisor_cpu": ratio_of(g.cpu, a.cpu).map(round2),
                "motion_io_cpu": ratio_of(g.io_cpu, a.io_cpu).map(round2),
            });
            (format!("{}_over_a", m.variant.letter()), r)
        })
        .collect();
    let cy = &o.cycle;
    let load = json!({"load_before": b.host.load, "load_after": motion_bench::host::loadavg()});
    json!({
        "bench": "cpcost",
        "machine": "demo (deploy/demo.toml, 4 axes, idle)",
        "period_us": cy.period_us,
        "priority": cy.priority,
        "cpu": cy.cpu,
        "duration_s_per_variant": o.slicing.duration,
        "slice_s": o.slicing.slice,
        "status_every_ms": o.status_every_ms,
        "stats_every_ms": o.stats_every_ms,
        "wall_s": wall_s,
        "environment": with(b.environment(), load),
        "variants": variants,
        "ratios": ratios,
        "warnings": warnings,
        "status": status(interrupted, failures),
    })
}
