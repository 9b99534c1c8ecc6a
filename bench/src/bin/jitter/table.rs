//! The printed report: one table of wake-up latency per variant side by
//! side with cyclictest (and their ratios), the deadline misses, the other
//! figures of the cycle, and everything that makes the numbers less than
//! representative (kernel, other real-time threads, supervisor warnings).
//! Same numbers as the JSON, laid out to be read in a CI log.

use crate::cli::Opts;
use crate::slices::Collected;
use crate::summary::{Summary, MAX_MISS_RATIO};
use motion_bench::hist::{self, thousands, us, Pct, COLUMNS};
use motion_bench::host::{Env, OtherRt};
use motion_bench::sys;

/// The report's text; `other_cpu` is where stress-ng ran (`--stress`).
pub fn text(
    o: &Opts,
    env: &Env,
    other_cpu: usize,
    m: &Summary,
    c: &Collected,
    other_rt: &OtherRt,
) -> String {
    let mut t = String::new();
    let line = |t: &mut String, s: String| {
        t.push_str(&s);
        t.push('\n');
    };
    line(
        &mut t,
        format!(
            "== jitter: period {} µs ({:.0} Hz), SCHED_FIFO {} on CPU {}, {:.1} s per tool in {} slice(s){}",
            o.period_us,
            1e6 / f64::from(o.period_us),
            o.priority,
            o.cpu,
            m.ours.secs,
            m.ours.slices,
            if o.stress {
                format!(", stress-ng --cpu 1 on CPU {other_cpu}")
            } else {
                ", no load".into()
            }
        ),
    );
    line(
        &mut t,
        format!(
            "kernel {} | preemption: {} | {} CPUs | RT throttling {} | load {}",
            env.kernel,
            env.preemption,
            env.cpus,
            env.throttling,
            sys::loadavg()
        ),
    );
    if !env.is_rt {
        line(
            &mut t,
            "not a PREEMPT_RT kernel: latencies are upper bounds, compare the two rows (same run, same noise)".into(),
        );
    }
    line(&mut t, String::new());
    let header = |name: &str| {
        let mut s = format!("{name:<22}");
        for c in COLUMNS {
            s += &format!("{c:>9}");
        }
        s
    };
    let row = |name: &str, p: &Pct, n: Option<u64>| {
        let mut s = format!("{name:<22}");
        for v in p.values() {
            s += &format!("{:>9}", us(v));
        }
        if let Some(n) = n {
            s += &format!("   {} samples", thousands(n));
        }
        s
    };
    line(&mut t, header("wake-up latency (µs)"));
    line(
        &mut t,
        row("ours, demo (idle)", &m.ours.w, Some(m.ours.w.count)),
    );
    if m.axes64.ran() {
        line(
            &mut t,
            row("ours, 64 axes homing", &m.axes64.w, Some(m.axes64.w.count)),
        );
    }
    if m.ecat.ran() {
        line(
            &mut t,
            row("ours, EtherCAT backend", &m.ecat.w, Some(m.ecat.w.count)),
        );
    }
    if m.ct.ran() {
        line(&mut t, row("cyclictest", &m.ct.w, Some(m.ct.w.count)));
        let mut s = format!("{:<22}", "ratio demo/cyclictest");
        for r in m.ours.w.ratio(&m.ct.w) {
            s += &format!("{:>9}", hist::ratio(r));
        }
        line(&mut t, s);
        if m.axes64.ran() {
            let mut s = format!("{:<22}", "ratio 64 axes/cyclic.");
            for r in m.axes64.w.ratio(&m.ct.w) {
                s += &format!("{:>9}", hist::ratio(r));
            }
            line(&mut t, s);
        }
        if m.ecat.ran() {
            let mut s = format!("{:<22}", "ratio EtherCAT/cyclic.");
            for r in m.ecat.w.ratio(&m.ct.w) {
                s += &format!("{:>9}", hist::ratio(r));
            }
            line(&mut t, s);
        }
    } else {
        line(&mut t, format!("{:<22}(not run)", "cyclictest"));
    }
    line(&mut t, String::new());
    line(
        &mut t,
        format!(
            "deadline misses   ours, demo: {} of {} cycles ({:.3} %, summed over {} slices; limit {:.0} %); wake-ups ≥ period: {}",
            m.ours.misses,
            thousands(m.ours.cycles),
            m.ours.miss_ratio * 100.0,
            m.ours.slices,
            MAX_MISS_RATIO * 100.0,
            m.ours.wakeups_ge(o.period_us)
        ),
    );
    if m.axes64.ran() {
        line(
            &mut t,
            format!(
                "                  ours, 64 axes homing: {} of {} cycles ({:.3} %); wake-ups ≥ period: {}",
                m.axes64.misses,
                thousands(m.axes64.cycles),
                m.axes64.miss_ratio * 100.0,
                m.axes64.wakeups_ge(o.period_us)
            ),
        );
    }
    if m.ecat.ran() {
        line(
            &mut t,
            format!(
                "                  EtherCAT backend: {} of {} cycles ({:.3} %); wake-ups ≥ period: {}",
                m.ecat.misses,
                thousands(m.ecat.cycles),
                m.ecat.miss_ratio * 100.0,
                m.ecat.wakeups_ge(o.period_us)
            ),
        );
    }
    if m.ct.ran() {
        line(
            &mut t,
            format!(
                "                  cyclictest: not counted (skips missed periods); samples ≥ period ({} µs): {}",
                o.period_us, m.ct.ge_period
            ),
        );
    }
    line(&mut t, String::new());
    line(&mut t, header("ours, other (µs)"));
    line(&mut t, row("compute, demo", &m.ours.c, None));
    line(&mut t, row("I/O round trip, demo", &m.ours.r, None));
    if m.axes64.ran() {
        line(&mut t, row("compute, 64 axes", &m.axes64.c, None));
        line(&mut t, row("round trip, 64 axes", &m.axes64.r, None));
    }
    if m.ecat.ran() {
        line(&mut t, row("compute, EtherCAT", &m.ecat.c, None));
        line(&mut t, row("round trip, EtherCAT", &m.ecat.r, None));
        match &m.bus {
            Some(b) => {
                let mut s = format!("{:<22}", "EtherCAT bus round trip");
                for v in [b.min, b.p50, b.p99, b.p999] {
                    s += &format!("{:>9}", us(v));
                }
                s += &format!("{:>9}{:>9}", "-", us(b.max));
                line(&mut t, s);
                line(
                    &mut t,
                    format!(
                        "  (motion-io's bus thread: frame out → inputs back over veth, {} bus cycles, {} lost frame(s); \
                         p50/p99/p99.9 = the highest of the {} slices)",
                        thousands(b.cycles),
                        b.lost,
                        c.bus_runs.len()
                    ),
                );
            }
            None => line(
                &mut t,
                "EtherCAT bus round trip: not reported by motion-io".into(),
            ),
        }
    }
    line(
        &mut t,
        format!(
            "late I/O replies (no answer within half a period): demo {} of {}{}{}",
            m.ours.late,
            thousands(m.ours.cycles),
            if m.axes64.ran() {
                format!(
                    "; 64 axes: {} of {}",
                    m.axes64.late,
                    thousands(m.axes64.cycles)
                )
            } else {
                String::new()
            },
            if m.ecat.ran() {
                format!(
                    "; EtherCAT backend: {} of {}",
                    m.ecat.late,
                    thousands(m.ecat.cycles)
                )
            } else {
                String::new()
            }
        ),
    );
    if m.axes64.ran() {
        line(&mut t, c.homing64.line(m.axes64.secs));
        for d in c.homing64.tally.details.iter().take(10) {
            line(&mut t, format!("  {d}"));
        }
    }
    line(
        &mut t,
        format!(
            "percentiles from the supervisor's interval logs ({} of {} cycles); min/max exact from its JSON",
            thousands(m.ours.wake.len()),
            thousands(m.ours.cycles)
        ),
    );
    if m.ct.ran() {
        line(
            &mut t,
            format!(
                "cyclictest: {} (1 µs bins, truncated; {} overflow(s) ≥ {} µs counted at its max)",
                c.ct_command, m.ct.total.overflows, o.hist_max_us
            ),
        );
    }
    if !other_rt.is_empty() {
        line(
            &mut t,
            format!(
                "WARNING: other real-time threads ran during the bench: {}",
                other_rt.list().join("; ")
            ),
        );
    }
    for w in &c.warnings {
        line(&mut t, format!("supervisor warning: {w}"));
    }
    t
}
