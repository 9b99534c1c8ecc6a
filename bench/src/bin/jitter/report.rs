//! The slices merged per variant (demo, 64 axes, EtherCAT, cyclictest), the
//! verdict (missed deadlines above `MAX_MISS_RATIO`, or a variant asked for
//! that produced nothing; percentiles never fail the run), and the printed
//! report: wake-up latency per variant side by side with cyclictest, the
//! deadline misses, the cycle's other figures, and what makes the numbers
//! less than representative. Same numbers as the JSON, laid out for a CI log.

use crate::bus::BusRun;
use crate::cli::Opts;
use crate::slices::{Collected, Names, Variant};
use hdrhistogram::Histogram;
use motion_bench::outcome::Bench;
use motion_bench::slice::{Group, MAX_MISS_RATIO};
use motion_bench::table::{ratio_cells, row, thousands, us, us_cells, Text, COLUMNS};
use motion_bench::{histogram, hlog, percentiles};
use motion_report::Percentiles;

/// Every column of [`Percentiles::values`].
const ALL: [usize; 6] = [0, 1, 2, 3, 4, 5];

/// cyclictest's slices, merged.
pub struct CtGroup {
    /// Its 1 µs bins as one HdrHistogram.
    pub hdr: Histogram<u64>,
    pub w: Percentiles,
    pub overflows: u64,
    /// Samples at or above one period (cyclictest does not count misses).
    pub ge_period: u64,
    pub secs: f64,
    pub slices: usize,
}

impl CtGroup {
    pub fn ran(&self) -> bool {
        self.slices > 0
    }
}

/// Every variant, merged.
pub struct Summary {
    /// Per variant (`Variant as usize`).
    pub ours: [Group; 3],
    /// The EtherCAT slices' bus round trips in one row (`BusRun::merge`).
    pub bus: Option<BusRun>,
    pub ct: CtGroup,
}

impl Summary {
    pub fn of(c: &Collected, period_us: u32) -> Self {
        let mut hdr = histogram();
        c.ct.iter().for_each(|s| hlog::merge(&mut hdr, &s.hdr));
        let ge = |s: &crate::slices::CtSlice| s.hist.at_or_above(u64::from(period_us));
        let ct = CtGroup {
            w: percentiles(&hdr),
            hdr,
            overflows: c.ct.iter().map(|s| s.hist.overflows).sum(),
            ge_period: c.ct.iter().map(ge).sum(),
            secs: c.ct.iter().map(|s| s.len.as_secs_f64()).sum(),
            slices: c.ct.len(),
        };
        let bus = c.bus_runs.iter().copied().reduce(|a, b| a.merge(&b));
        let ours = (c.ours.each_ref()).map(|v| Group::of(&v.iter().collect::<Vec<_>>()));
        Summary { ours, bus, ct }
    }

    pub fn group(&self, v: Variant) -> &Group {
        &self.ours[v as usize]
    }

    /// Adds the run's failures: too many missed deadlines, or (if nothing
    /// else failed and the bench was not interrupted) a variant that was
    /// asked for but produced nothing.
    pub fn judge(&self, o: &Opts, cyclictest: bool, interrupted: bool, failures: &mut Vec<String>) {
        for v in [Variant::Demo, Variant::Ethercat, Variant::Axes64] {
            let (g, who) = (self.group(v), v.names().who);
            if let Some(r) = g.too_many_misses() {
                let (m, c) = (g.misses, g.cycles);
                failures.push(format!("{who} missed {m} of {c} deadlines {r}"));
            }
        }
        let nothing = [
            (
                o.axes64,
                self.group(Variant::Axes64).ran(),
                "the 64-axis machine produced no slice",
            ),
            (
                o.ethercat,
                self.group(Variant::Ethercat).ran(),
                "the EtherCAT backend produced no slice",
            ),
            (cyclictest, self.ct.ran(), "cyclictest produced no samples"),
        ];
        for (asked, ran, what) in nothing {
            if asked && !ran && failures.is_empty() && !interrupted {
                failures.push(what.into());
            }
        }
    }

    /// The variants that produced slices, with their names.
    fn ran(&self) -> impl Iterator<Item = (&Group, &'static Names)> {
        (self.ours.iter().zip(Variant::ALL))
            .filter(|(g, _)| g.ran())
            .map(|(g, v)| (g, v.names()))
    }
}

/// The report's text.
pub fn text(o: &Opts, b: &Bench, m: &Summary, c: &Collected) -> String {
    let (cy, demo, env) = (&o.cycle, m.group(Variant::Demo), &b.host);
    let mut t = Text::default();
    let load = match o.stress {
        true => format!(", stress-ng --cpu 1 on CPU {}", cy.other_cpu()),
        false => ", no load".into(),
    };
    t.line(format!(
        "== jitter: period {} µs ({:.0} Hz), SCHED_FIFO {} on CPU {}, {:.1} s per tool in {} slice(s){load}",
        cy.period_us, 1e6 / f64::from(cy.period_us), cy.priority, cy.cpu, demo.secs, demo.slices
    ));
    let (head, throttling, load) = (env.head(), &env.throttling, motion_bench::host::loadavg());
    t.line(format!("{head} | RT throttling {throttling} | load {load}"));
    if !env.is_rt {
        t.line("not a PREEMPT_RT kernel: latencies are upper bounds, compare the two rows (same run, same noise)");
    }
    t.line("");
    wakeups(&mut t, m);
    t.line("");
    misses(&mut t, o, m);
    t.line("");
    others(&mut t, m, c);
    notes(&mut t, o, b, m, c);
    t.0
}

/// Wake-up latency per variant and cyclictest, and their ratios.
fn wakeups(t: &mut Text, m: &Summary) {
    let samples = |p: &Percentiles| format!("   {} samples", thousands(p.count));
    t.line(row("wake-up latency (µs)", 22, COLUMNS));
    for (g, n) in m.ran() {
        t.line(row(n.row, 22, us_cells(&g.w, &ALL)) + &samples(&g.w));
    }
    if !m.ct.ran() {
        return t.line(format!("{:<22}(not run)", "cyclictest"));
    }
    t.line(row("cyclictest", 22, us_cells(&m.ct.w, &ALL)) + &samples(&m.ct.w));
    for (g, n) in m.ran() {
        t.line(row(n.ratio, 22, ratio_cells(&g.w, &m.ct.w, &ALL)));
    }
}

/// Deadline misses per variant; cyclictest's samples beyond the period.
fn misses(t: &mut Text, o: &Opts, m: &Summary) {
    let period = o.cycle.period_us;
    for (k, (g, n)) in m.ran().enumerate() {
        let (head, more) = match k {
            0 => {
                let (slices, max) = (g.slices, MAX_MISS_RATIO * 100.0);
                let more = format!(", summed over {slices} slices; limit {max:.0} %");
                ("deadline misses   ", more)
            }
            _ => ("                  ", String::new()),
        };
        t.line(format!(
            "{head}{}: {} of {} cycles ({:.3} %{more}); wake-ups ≥ period: {}",
            n.misses,
            g.misses,
            thousands(g.cycles),
            g.miss_ratio * 100.0,
            g.wakeups_ge(period)
        ));
    }
    if m.ct.ran() {
        t.line(format!(
            "                  cyclictest: not counted (skips missed periods); samples ≥ period ({period} µs): {}",
            m.ct.ge_period
        ));
    }
}

/// Compute, I/O round trip, the EtherCAT bus, late replies, the homings.
fn others(t: &mut Text, m: &Summary, c: &Collected) {
    t.line(row("ours, other (µs)", 22, COLUMNS));
    for (g, n) in m.ran() {
        t.line(row(n.compute, 22, us_cells(&g.c, &ALL)));
        t.line(row(n.roundtrip, 22, us_cells(&g.r, &ALL)));
    }
    match (m.group(Variant::Ethercat).ran(), &m.bus) {
        (false, _) => {}
        (true, Some(b)) => {
            let cells = [
                us(b.min),
                us(b.p50),
                us(b.p99),
                us(b.p999),
                "-".into(),
                us(b.max),
            ];
            t.line(row("EtherCAT bus round trip", 22, cells));
            t.line(format!(
                "  (motion-io's bus thread: frame out → inputs back over veth, {} bus cycles, {} lost frame(s); \
                 p50/p99/p99.9 = the highest of the {} slices)",
                thousands(b.cycles), b.lost, c.bus_runs.len()
            ));
        }
        (true, None) => t.line("EtherCAT bus round trip: not reported by motion-io"),
    }
    let late: Vec<String> = (m.ran())
        .map(|(g, n)| format!("{} {} of {}", n.late, g.late, thousands(g.cycles)))
        .collect();
    let late = late.join("; ");
    t.line(format!(
        "late I/O replies (no answer within half a period): {late}"
    ));
    let a64 = m.group(Variant::Axes64);
    if a64.ran() {
        let (h, y) = (&c.homing64, &c.homing64.tally);
        t.line(format!(
            "64 axes: {} parallel homing(s) in {:.0} s ({:.1} s each): {} all homed, {} with a failed axis, {} cut off by a slice's end; \
             axis homings {}: {} ok, {} ERR 12/40 (feedback lost), {} other error(s), {} not homed",
            h.started, a64.secs, h.mean_s(), h.ok, h.failed, h.cut_off, y.axis_homings, y.ok, y.feedback_lost, y.other_errors, y.not_homed
        ));
        for d in c.homing64.tally.details.iter().take(10) {
            t.line(format!("  {d}"));
        }
    }
}

/// Where the figures come from, and the warnings.
fn notes(t: &mut Text, o: &Opts, b: &Bench, m: &Summary, c: &Collected) {
    let demo = m.group(Variant::Demo);
    t.line(format!(
        "percentiles from the supervisor's interval logs ({} of {} cycles); min/max exact from its JSON",
        thousands(demo.wake.len()),
        thousands(demo.cycles)
    ));
    if m.ct.ran() {
        t.line(format!(
            "cyclictest: {} (1 µs bins, truncated; {} overflow(s) ≥ {} µs counted at its max)",
            c.ct_command, m.ct.overflows, o.hist_max_us
        ));
    }
    b.other_rt_warning(t, "ran during the bench");
    for w in &c.warnings {
        t.line(format!("supervisor warning: {w}"));
    }
}
