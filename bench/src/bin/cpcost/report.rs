//! The slices of each variant merged (`motion_bench::slice::Group`, with the
//! clients' counts), the verdict (missed deadlines above `MAX_MISS_RATIO`,
//! client requests that failed while the supervisor ran, a variant that
//! produced nothing; percentiles never fail the run), the printed report and
//! cpcost.json with the same figures.

use crate::cli::Opts;
use crate::clients::{Clients, Count};
use crate::slice::Done;
use crate::variant::Variant;
use motion_bench::outcome::{status, with, Bench};
use motion_bench::slice::{ratio_json, Group, MAX_MISS_RATIO};
use motion_bench::table::{
    line, ratio, ratio_cells, ratio_of, row, thousands, us_cells, Text, COLUMNS,
};
use motion_report::Percentiles;
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
        let attach_s =
            (!attach.is_empty()).then(|| attach.iter().sum::<f64>() / attach.len() as f64);
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
        let (name, g) = (self.variant.label(), &self.g);
        if !g.ran() {
            if !interrupted {
                failures.push(format!("{name}: no slice measured"));
            }
            return;
        }
        if let Some(r) = g.too_many_misses() {
            let (m, c) = (g.misses, g.cycles);
            failures.push(format!(
                "{name}: {m} of {c} cycles missed their deadline {r}"
            ));
        }
        if self.clients.failed() > 0 {
            let n = self.clients.failed();
            failures.push(format!(
                "{name}: {n} client request(s) failed while the supervisor ran"
            ));
        }
    }
}

fn pct(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{:.1} %", x * 100.0))
}

/// One kind of request on one line.
fn requests(what: &str, c: &Count) -> String {
    let time = c.ms_p50_max().map_or(String::new(), |(p50, max)| {
        format!(", start → exit p50 {p50:.0} ms, max {max:.0} ms")
    });
    let (made, failed, cut) = (thousands(c.made), c.failed, c.cut_off);
    format!("  {what:<34} {made:>6} made, {failed} failed, {cut} cut off by a slice's end{time}")
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
    let (mut t, a, cy, env) = (Text::default(), &groups[0].g, &o.cycle, &b.host);
    t.line(format!(
        "== cpcost: what the control plane costs the cycle — period {} µs ({:.0} Hz), SCHED_FIFO {} on CPU {}, \
         demo machine (4 axes) idle, {:.0} s per variant in {} slice(s) of ≤ {} s, variants alternating",
        cy.period_us, 1e6 / f64::from(cy.period_us), cy.priority, cy.cpu, a.secs, a.slices, o.slicing.slice
    ));
    let (head, throttling, before) = (env.head(), &env.throttling, &env.load);
    let after = motion_bench::host::loadavg();
    t.line(format!(
        "{head} | RT throttling {throttling} | load {before} before, {after} after"
    ));
    if !env.is_rt {
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
    for w in warnings {
        t.line(format!("supervisor warning: {w}"));
    }
    t.0
}

/// One latency of a variant.
type Pick = fn(&Group) -> &Percentiles;

/// Per latency one row per variant, and the ratios to (a).
fn latencies(t: &mut Text, groups: &[Merged]) {
    let a = &groups[0].g;
    let names = COLS.map(|i| COLUMNS[i]);
    let sections: [(&str, Pick); 3] = [
        ("wake-up latency (µs)", |g| &g.w),
        ("compute (µs)", |g| &g.c),
        ("I/O round trip (µs)", |g| &g.r),
    ];
    for (title, f) in sections {
        t.line("");
        t.line(row(title, 26, names));
        for m in groups.iter().filter(|m| m.g.ran()) {
            t.line(row(
                &format!("  {}", m.variant.label()),
                26,
                us_cells(f(&m.g), &COLS),
            ));
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
    const WIDTHS: [i32; 7] = [2, -24, 10, 22, 14, 16, 15];
    let a = &groups[0].g;
    let head = [
        "",
        "",
        "cycles",
        "deadline misses",
        "late replies",
        "supervisor CPU",
        "motion-io CPU",
    ];
    t.line(line(&WIDTHS, head));
    for m in groups.iter().filter(|m| m.g.ran()) {
        let g = &m.g;
        let misses = format!("{} ({:.3} %)", g.misses, g.miss_ratio * 100.0);
        let (cycles, late) = (thousands(g.cycles), g.late.to_string());
        let cells = [
            "",
            m.variant.label(),
            &cycles,
            &misses,
            &late,
            &pct(g.cpu),
            &pct(g.io_cpu),
        ];
        t.line(line(&WIDTHS, cells));
    }
    for m in groups[1..].iter().filter(|m| m.g.ran() && a.ran()) {
        let (g, name) = (&m.g, format!("ratio ({})/(a)", m.variant.letter()));
        let [s, i] = [ratio_of(g.cpu, a.cpu), ratio_of(g.io_cpu, a.io_cpu)].map(ratio);
        t.line(line(&WIDTHS, ["", &name, "", "", "", &s, &i]));
    }
    let max = MAX_MISS_RATIO * 100.0;
    t.line(format!(
        "  (CPU: the process with all its threads, as a share of one core over each run; deadline-miss limit {max:.0} %)"
    ));
    t.line("");
}

/// A variant's client requests per kind.
fn client_requests(t: &mut Text, o: &Opts, m: &Merged) {
    let c = &m.clients;
    t.line(format!(
        "client requests {} ({} made, {} failed, {} cut off; attached {:.2} s after each run's start):",
        m.variant.label(),
        thousands(c.made()),
        c.failed(),
        c.cut_off(),
        m.attach_s.unwrap_or(0.0)
    ));
    t.line(requests("status --watch (one per slice)", &c.watch));
    t.line(requests(
        &format!("status --json every {} ms", o.status_every_ms),
        &c.status,
    ));
    t.line(requests(
        &format!("stats --json every {} ms", o.stats_every_ms),
        &c.stats,
    ));
    if m.variant == Variant::Homing {
        t.line(requests("home X --json, back to back", &c.home));
    }
    for d in c.details().take(10) {
        t.line(format!("    {d}"));
    }
}

fn round2(x: f64) -> f64 {
    motion_report::round(x, 2)
}

fn group_json(o: &Opts, m: &Merged) -> Value {
    let (g, c) = (&m.g, &m.clients);
    if !g.ran() {
        return json!({ "ran": false });
    }
    with(
        g.json(),
        json!({
            "ran": true,
            "what": m.variant.describe(o),
            "hlog_samples": g.wake.len(),
            "supervisor_cpu_share": g.cpu,
            "motion_io_cpu_share": g.io_cpu,
            "clients_attached_after_s": m.attach_s,
            "clients": if m.variant.serves() { json!({
                "made": c.made(),
                "failed": c.failed(),
                "cut_off": c.cut_off(),
                "watch": c.watch,
                "status": c.status,
                "status_request_ms_p50_max": c.status.ms_p50_max(),
                "stats": c.stats,
                "stats_request_ms_p50_max": c.stats.ms_p50_max(),
                "home": c.home,
                "home_request_ms_p50_max": c.home.ms_p50_max(),
            }) } else { Value::Null },
        }),
    )
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
    let a = &groups[0];
    let mut variants = serde_json::Map::new();
    let mut ratios = serde_json::Map::new();
    for m in groups {
        variants.insert(m.variant.key().into(), group_json(o, m));
        let (g, ga) = (&m.g, &a.g);
        if m.variant != a.variant && g.ran() && ga.ran() {
            ratios.insert(
                format!("{}_over_a", m.variant.letter()),
                json!({
                    "wakeup_us": ratio_json(&g.w, &ga.w),
                    "compute_us": ratio_json(&g.c, &ga.c),
                    "io_roundtrip_us": ratio_json(&g.r, &ga.r),
                    "supervisor_cpu": ratio_of(g.cpu, ga.cpu).map(round2),
                    "motion_io_cpu": ratio_of(g.io_cpu, ga.io_cpu).map(round2),
                }),
            );
        }
    }
    let cy = &o.cycle;
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
        "environment": with(b.environment(), json!({
            "load_before": b.host.load,
            "load_after": motion_bench::host::loadavg(),
        })),
        "variants": variants,
        "ratios": ratios,
        "warnings": warnings,
        "status": status(interrupted, failures),
    })
}
