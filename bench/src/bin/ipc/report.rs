//! The printed report: per mode min / p50 / p99 / p99.9 / max and late
//! answers, each motion-io mode next to the bare echo of the same kind with
//! their ratio per percentile, and what could make the numbers wrong (other
//! real-time threads, shared memory left behind).

use crate::bare::{PING, PONG};
use crate::cli::Opts;
use crate::measure::Measured;
use crate::mode::Mode;
use hdrhistogram::Histogram;
use motion_bench::outcome::Bench;
use motion_bench::table::{ratio, row, thousands, us, Text};

/// min, p50, p99, p99.9, max of `h`, µs.
fn values(h: &Histogram<u64>) -> [f64; 5] {
    if h.is_empty() {
        return [0.0; 5];
    }
    let q = |x: f64| h.value_at_quantile(x) as f64 / 1000.0;
    [
        h.min() as f64 / 1000.0,
        q(0.5),
        q(0.99),
        q(0.999),
        h.max() as f64 / 1000.0,
    ]
}

/// Prints the report of `results`; `leftovers` are what the modes left in
/// /dev/shm.
pub fn print(o: &Opts, b: &Bench, results: &[(Mode, Measured)], leftovers: &[String]) {
    let (mut t, cy, peer) = (Text::default(), &o.cycle, o.peer_cpu());
    t.line(format!(
        "== ipc: round trip command → feedback, {} messages per mode, one per {} µs; \
         measuring thread SCHED_FIFO {} on CPU {}, peer on CPU {peer}",
        thousands(o.count),
        cy.period_us,
        cy.priority,
        cy.cpu
    ));
    let env = &b.env;
    t.line(format!(
        "kernel {} | {} | {} CPUs | payload {PING} B → {PONG} B (CommandFrame → FeedbackFrame; bare: [u8; {PING}] → [u8; {PONG}])",
        env.kernel, env.preemption, env.cpus
    ));
    let dma = match o.cpu_dma_latency {
        us if us >= 0 => format!("held at {us} µs"),
        _ => "not held".into(),
    };
    t.line(format!(
        "event peers: SCHED_FIFO {} on CPU {peer}, ppoll on the listener fd; spinning peers: SCHED_OTHER on CPU {peer}; /dev/cpu_dma_latency {dma}",
        cy.priority - 10
    ));
    t.line("");
    t.line(row(
        "round trip (µs)",
        26,
        ["min", "p50", "p99", "p99.9", "max", "late"],
    ));
    let find = |m: Mode| results.iter().find(|r| r.0 == m).map(|r| &r.1);
    for (ours, bare) in [
        (Mode::IoEvent, Mode::BareEvent),
        (Mode::IoSpin, Mode::BareSpin),
    ] {
        for (mode, m) in [(ours, find(ours)), (bare, find(bare))] {
            if let Some(m) = m {
                t.line(row(mode.label(), 26, values(&m.hist).map(us)) + &format!("{:>9}", m.late));
            }
        }
        if let (Some(a), Some(b)) = (find(ours), find(bare)) {
            let (va, vb) = (values(&a.hist), values(&b.hist));
            let r = std::array::from_fn::<_, 5, _>(|i| ratio((vb[i] > 0.0).then(|| va[i] / vb[i])));
            t.line(row("  ratio motion-io / bare", 26, r));
        }
    }
    let sent: Vec<String> = results
        .iter()
        .map(|(m, r)| format!("{} {}", m.key(), r.sent))
        .collect();
    t.line(format!(
        "late = no answer within half a period (not in the percentiles); sent per mode: {}",
        sent.join(", ")
    ));
    if !b.other_rt.is_empty() {
        let list = b.other_rt.list().join("; ");
        t.line(format!(
            "WARNING: other real-time threads were running: {list}"
        ));
    }
    t.line(match leftovers.is_empty() {
        true => "/dev/shm: nothing left behind".into(),
        false => format!("/dev/shm: LEFT BEHIND: {}", leftovers.join("; ")),
    });
    print!("{}", t.0);
}
