//! The printed report: per mode min / p50 / p99 / p99.9 / max and late
//! answers, each motion-io mode next to the bare echo of the same kind with
//! their ratio per percentile, and what could make the numbers wrong (other
//! real-time threads, shared memory left behind).

use crate::cli::Opts;
use crate::measure::Measured;
use crate::mode::Mode;
use motion_bench::bare::{PING, PONG};
use motion_bench::outcome::Bench;
use motion_bench::percentiles;
use motion_bench::table::{ratio_cells, row, thousands, us_cells, Text};

/// The columns: min, p50, p99, p99.9, max.
const COLS: [usize; 5] = [0, 1, 2, 3, 5];

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
    let env = &b.host;
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
    let find = |m: Mode| {
        let r = results.iter().find(|r| r.0 == m)?;
        Some((percentiles(&r.1.hist), r.1.late))
    };
    for (ours, bare) in [
        (Mode::IoEvent, Mode::BareEvent),
        (Mode::IoSpin, Mode::BareSpin),
    ] {
        let (a, b) = (find(ours), find(bare));
        for (mode, m) in [(ours, &a), (bare, &b)] {
            if let Some((p, late)) = m {
                t.line(row(mode.label(), 26, us_cells(p, &COLS)) + &format!("{late:>9}"));
            }
        }
        if let (Some((a, _)), Some((b, _))) = (&a, &b) {
            t.line(row(
                "  ratio motion-io / bare",
                26,
                ratio_cells(a, b, &COLS),
            ));
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
    b.other_rt_warning(&mut t, "were running");
    t.line(match leftovers.is_empty() {
        true => "/dev/shm: nothing left behind".into(),
        false => format!("/dev/shm: LEFT BEHIND: {}", leftovers.join("; ")),
    });
    print!("{}", t.0);
}
