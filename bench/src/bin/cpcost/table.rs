//! The printed report: the conditions (kernel, preemption, load), what each
//! variant runs, then per latency (wake-up, compute, I/O round trip) one row
//! per variant and the ratio (b)/(a); then cycles, deadline misses, late
//! replies and CPU use per variant; then the client requests. Same numbers
//! as cpcost.json, laid out to be quoted.

use crate::cli::Opts;
use crate::clients::Count;
use crate::summary::{ratio_of, ratios, Group, COLUMNS, MAX_MISS_RATIO};
use crate::variant::Variant;
use motion_bench::hist::{self, thousands, us, Pct};
use motion_bench::host::{Env, OtherRt};
use motion_bench::sys;

/// Everything the report shows besides the groups.
pub struct Notes<'a> {
    pub env: &'a Env,
    pub other_rt: &'a OtherRt,
    /// The supervisors' warnings (each once).
    pub warnings: &'a [String],
    /// Runs that left files in /dev/shm (cleaned by the bench), files left.
    pub leftovers: (usize, usize),
}

const NAME: usize = 26;

/// One latency of a variant.
type Pick = fn(&Group) -> &Pct;

fn head(name: &str) -> String {
    let mut s = format!("{name:<NAME$}");
    for (_, c) in COLUMNS {
        s += &format!("{c:>9}");
    }
    s
}

fn row(name: &str, p: &Pct) -> String {
    let v = p.values();
    let mut s = format!("  {name:<w$}", w = NAME - 2);
    for (i, _) in COLUMNS {
        s += &format!("{:>9}", us(v[i]));
    }
    s
}

fn ratio_row(name: &str, r: &[Option<f64>]) -> String {
    let mut s = format!("  {name:<w$}", w = NAME - 2);
    for x in r {
        s += &format!("{:>9}", hist::ratio(*x));
    }
    s
}

fn pct(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{:.1} %", x * 100.0))
}

/// One kind of request on one line.
fn requests(what: &str, c: &Count) -> String {
    let time = c.ms_p50_max().map_or(String::new(), |(p50, max)| {
        format!(", start → exit p50 {p50:.0} ms, max {max:.0} ms")
    });
    format!(
        "  {what:<34} {:>6} made, {} failed, {} cut off by a slice's end{time}",
        thousands(c.made),
        c.failed,
        c.cut_off
    )
}

/// The report's text; `groups[0]` is (a), `groups[1]` (b), then (c).
pub fn text(o: &Opts, groups: &[Group], n: &Notes) -> String {
    let mut t = String::new();
    let mut line = |s: String| {
        t.push_str(&s);
        t.push('\n');
    };
    let a = &groups[0];
    line(format!(
        "== cpcost: what the control plane costs the cycle — period {} µs ({:.0} Hz), SCHED_FIFO {} on CPU {}, \
         demo machine (4 axes) idle, {:.0} s per variant in {} slice(s) of ≤ {} s, variants alternating",
        o.period_us,
        1e6 / f64::from(o.period_us),
        o.priority,
        o.cpu,
        a.secs,
        a.slices,
        o.slice
    ));
    line(format!(
        "kernel {} | preemption: {} | {} CPUs | RT throttling {} | load {} before, {} after",
        n.env.kernel,
        n.env.preemption,
        n.env.cpus,
        n.env.throttling,
        n.env.load_before,
        sys::loadavg()
    ));
    if !n.env.is_rt {
        line(
            "not a PREEMPT_RT kernel: latencies are upper bounds; compare the rows (same machine, alternating slices)"
                .into(),
        );
    }
    for g in groups {
        line(format!(
            "{:<NAME$}{}",
            g.variant.label(),
            g.variant.describe(o)
        ));
    }
    line(String::new());

    let sections: [(&str, Pick); 3] = [
        ("wake-up latency (µs)", |g| &g.w),
        ("compute (µs)", |g| &g.c),
        ("I/O round trip (µs)", |g| &g.r),
    ];
    for (k, (title, f)) in sections.iter().enumerate() {
        line(head(title));
        for g in groups.iter().filter(|g| g.ran()) {
            line(row(g.variant.label(), f(g)));
        }
        for g in groups[1..].iter().filter(|g| g.ran() && a.ran()) {
            line(ratio_row(
                &format!("ratio ({})/(a)", g.variant.letter()),
                &ratios(f(g), f(a)),
            ));
        }
        if k + 1 < sections.len() {
            line(String::new());
        }
    }
    line(String::new());

    line(format!(
        "{:<NAME$}{:>10}{:>22}{:>14}{:>16}{:>15}",
        "", "cycles", "deadline misses", "late replies", "supervisor CPU", "motion-io CPU"
    ));
    for g in groups.iter().filter(|g| g.ran()) {
        line(format!(
            "  {:<w$}{:>10}{:>22}{:>14}{:>16}{:>15}",
            g.variant.label(),
            thousands(g.cycles),
            format!("{} ({:.3} %)", g.misses, g.miss_ratio * 100.0),
            g.late,
            pct(g.cpu),
            pct(g.io_cpu),
            w = NAME - 2
        ));
    }
    for g in groups[1..].iter().filter(|g| g.ran() && a.ran()) {
        line(format!(
            "  {:<w$}{:>10}{:>22}{:>14}{:>16}{:>15}",
            format!("ratio ({})/(a)", g.variant.letter()),
            "",
            "",
            "",
            hist::ratio(ratio_of(g.cpu, a.cpu)),
            hist::ratio(ratio_of(g.io_cpu, a.io_cpu)),
            w = NAME - 2
        ));
    }
    line(format!(
        "  (CPU: the process with all its threads, as a share of one core over each run; deadline-miss limit {:.0} %)",
        MAX_MISS_RATIO * 100.0
    ));
    line(String::new());

    for g in groups[1..].iter().filter(|g| g.ran()) {
        let c = &g.clients;
        line(format!(
            "client requests {} ({} made, {} failed, {} cut off; attached {:.2} s after each run's start):",
            g.variant.label(),
            thousands(c.made()),
            c.failed(),
            c.cut_off(),
            g.attach_s.unwrap_or(0.0)
        ));
        line(requests("status --watch (one per slice)", &c.watch));
        line(requests(
            &format!("status --json every {} ms", o.status_every_ms),
            &c.status,
        ));
        line(requests(
            &format!("stats --json every {} ms", o.stats_every_ms),
            &c.stats,
        ));
        if g.variant == Variant::Homing {
            line(requests("home X --json, back to back", &c.home));
        }
        for d in [&c.watch, &c.status, &c.stats, &c.home]
            .iter()
            .flat_map(|c| c.details.iter())
            .take(10)
        {
            line(format!("    {d}"));
        }
    }
    line(format!(
        "percentiles from the supervisors' interval logs ({} of {} cycles in (a)); min/max exact from their JSON reports",
        thousands(a.hlog_samples),
        thousands(a.cycles)
    ));
    if n.leftovers.0 > 0 {
        line(format!(
            "/dev/shm: {} run(s) left {} file(s) (a motionctl's node outlived the daemon's clean-up); cleaned by the bench",
            n.leftovers.0, n.leftovers.1
        ));
    }
    if !n.other_rt.is_empty() {
        line(format!(
            "WARNING: other real-time threads ran during the bench: {}",
            n.other_rt.list().join("; ")
        ));
    }
    for w in n.warnings {
        line(format!("supervisor warning: {w}"));
    }
    t
}
