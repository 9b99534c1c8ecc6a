//! The printed report: per mode min / p50 / p99 / p99.9 / max and late
//! answers, each motion-io mode next to the bare echo of the same kind with
//! their ratio per percentile, and what could make the numbers wrong (other
//! real-time threads, shared memory left behind).

use crate::bare::{PING, PONG};
use crate::cli::Opts;
use crate::measure::Measured;
use crate::mode::Mode;
use hdrhistogram::Histogram;
use motion_bench::hist::{self, thousands, us};
use motion_bench::sys::{self, RtTask};

/// Prints the report of `results`; `others` are the other real-time
/// threads seen at the start, `leftovers` what the modes left in /dev/shm.
pub fn print(o: &Opts, results: &[(Mode, Measured)], others: &[RtTask], leftovers: &[String]) {
    println!(
        "== ipc: round trip command → feedback, {} messages per mode, one per {} µs; \
         measuring thread SCHED_FIFO {} on CPU {}, peer on CPU {}",
        thousands(o.count),
        o.period_us,
        o.priority,
        o.cpu,
        o.peer_cpu()
    );
    println!(
        "kernel {} | {} | {} CPUs | payload {PING} B → {PONG} B (CommandFrame → FeedbackFrame; bare: [u8; {PING}] → [u8; {PONG}])",
        sys::kernel(),
        sys::preemption().0,
        sys::cpus()
    );
    println!(
        "event peers: SCHED_FIFO {} on CPU {}, ppoll on the listener fd; spinning peers: SCHED_OTHER on CPU {}; /dev/cpu_dma_latency {}",
        o.priority - 10,
        o.peer_cpu(),
        o.peer_cpu(),
        if o.cpu_dma_latency >= 0 {
            format!("held at {} µs", o.cpu_dma_latency)
        } else {
            "not held".to_string()
        }
    );
    println!();
    let cols = ["min", "p50", "p99", "p99.9", "max"];
    let mut head = format!("{:<26}", "round trip (µs)");
    for c in cols {
        head += &format!("{c:>9}");
    }
    head += &format!("{:>9}", "late");
    println!("{head}");
    let vals = |h: &Histogram<u64>| -> [f64; 5] {
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
    };
    let find = |m: Mode| results.iter().find(|r| r.0 == m).map(|r| &r.1);
    for (ours, bare) in [
        (Mode::IoEvent, Mode::BareEvent),
        (Mode::IoSpin, Mode::BareSpin),
    ] {
        let (a, b) = (find(ours), find(bare));
        for (mode, m) in [(ours, a), (bare, b)] {
            if let Some(m) = m {
                let mut s = format!("{:<26}", mode.label());
                for v in vals(&m.hist) {
                    s += &format!("{:>9}", us(v));
                }
                s += &format!("{:>9}", m.late);
                println!("{s}");
            }
        }
        if let (Some(a), Some(b)) = (a, b) {
            let (va, vb) = (vals(&a.hist), vals(&b.hist));
            let mut s = format!("{:<26}", "  ratio motion-io / bare");
            for i in 0..5 {
                s += &format!("{:>9}", hist::ratio((vb[i] > 0.0).then(|| va[i] / vb[i])));
            }
            println!("{s}");
        }
    }
    println!(
        "late = no answer within half a period (not in the percentiles); sent per mode: {}",
        results
            .iter()
            .map(|(m, r)| format!("{} {}", m.key(), r.sent))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if !others.is_empty() {
        println!(
            "WARNING: other real-time threads were running: {}",
            others
                .iter()
                .map(|t| t.to_string())
                .collect::<Vec<_>>()
                .join("; ")
        );
    }
    if leftovers.is_empty() {
        println!("/dev/shm: nothing left behind");
    } else {
        println!("/dev/shm: LEFT BEHIND: {}", leftovers.join("; "));
    }
}
