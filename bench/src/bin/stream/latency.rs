//! Setpoint latency: from the program publishing a setpoint to the command
//! frame that carries it, in cycles (and µs), at the stream's own rate.
//!
//! One axis streams a ramp (1 unit/s, one setpoint per cycle, program time
//! `k × period`): setpoint `k` is `k × speed × period`, a position no other
//! setpoint has. A spy subscriber on the I/O process's command topic records
//! every command frame with the supervisor's send time; the frame carrying
//! setpoint `k` is the first whose position set-point is `k`'s (in counts).
//! Latency in cycles = the command frames published after the publish,
//! up to and including that one (1 = the very next frame); in µs = its send
//! time − the publish time (both `CLOCK_MONOTONIC`, system-wide). A
//! setpoint overtaken in the same cycle by the next one (the program woke
//! twice between two cycles) is never commanded exactly: counted apart.

use crate::Opts;
use motion_bench::bins::Binaries;
use motion_bench::drive;
use motion_bench::machine::{streamed_names, streamed_with, STREAMED_COUNTS_PER_UNIT};
use motion_bench::outcome::Bench;
use motion_bench::spy::Spy;
use motion_bench::stream::{home_and_enable, Streamer};
use motion_report::nearest_rank as pct;
use serde::Serialize;
use std::time::Duration;

/// What one rate measured.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Latency {
    pub period_us: u32,
    pub setpoints: usize,
    /// Carried by a command frame (the rest were overtaken).
    pub carried: usize,
    pub overtaken: usize,
    pub cycles_p50: Option<f64>,
    pub cycles_p99: Option<f64>,
    pub cycles_max: Option<f64>,
    pub us_p50: Option<f64>,
    pub us_p99: Option<f64>,
    pub us_max: Option<f64>,
    pub spy_missed: u64,
}

/// Runs one rate: a daemon at `period_us`, the spy, the ramp for `secs`.
pub fn run(o: &Opts, b: &Binaries, bench: &Bench, period_us: u32) -> Result<Latency, String> {
    let prefix = format!("mbs{}l{period_us}", std::process::id());
    let sup = motion_bench::machine::Supervisor {
        cycle_us: period_us,
        ..o.cycle.supervisor(&prefix)
    };
    let d = drive::start_machine(b, &bench.tmp, &prefix, &streamed_with(&sup, 1))?;
    let result = measure(o, &prefix, period_us);
    let ended = drive::stop_run(d, Duration::from_secs(20));
    let _ = drive::clean_leftovers(&prefix);
    let r = result?;
    if !ended.success() {
        return Err(format!("{prefix}: {}", ended.describe()));
    }
    Ok(r)
}

fn measure(o: &Opts, prefix: &str, period_us: u32) -> Result<Latency, String> {
    home_and_enable(prefix, 1)?;
    let period = u64::from(period_us) * 1000;
    let step = 1.0 * period as f64 * 1e-9; // 1 unit/s
    let cap = (o.seconds * 1e6 / f64::from(period_us)) as usize * 2 + 1000;
    let mut spy = Spy::start(prefix, "io", o.cycle.other_cpu(), 70, cap, |_| {})?;
    let streamer = Streamer::start(
        prefix,
        streamed_names(1),
        period,
        (o.cycle.other_cpu(), o.client_priority),
        Box::new(move |k| vec![k as f64 * step]),
    );
    std::thread::sleep(Duration::from_secs_f64(o.seconds));
    let sent = streamer.finish()?;
    std::thread::sleep(Duration::from_millis(20));
    let rec = spy.finish();
    if let Some(e) = rec.error {
        return Err(format!("spy: {e}"));
    }
    let counts = |k: usize| ((k as f64 + 1.0) * step * STREAMED_COUNTS_PER_UNIT).round() as i64;
    let (mut cycles, mut us, mut overtaken) = (Vec::new(), Vec::new(), 0);
    for (k, &t) in sent.iter().enumerate() {
        let after = rec.cmds.partition_point(|c| c.ts < t);
        match rec.cmds[after..]
            .iter()
            .position(|c| c.position == counts(k))
        {
            Some(j) if j < 64 => {
                cycles.push((j + 1) as f64);
                us.push((rec.cmds[after + j].ts - t) as f64 / 1e3);
            }
            _ => overtaken += 1,
        }
    }
    cycles.sort_by(f64::total_cmp);
    us.sort_by(f64::total_cmp);
    let missed = rec
        .cmds
        .windows(2)
        .map(|w| w[1].seq.saturating_sub(w[0].seq + 1))
        .sum();
    Ok(Latency {
        period_us,
        setpoints: sent.len(),
        carried: cycles.len(),
        overtaken,
        cycles_p50: pct(&cycles, 0.5),
        cycles_p99: pct(&cycles, 0.99),
        cycles_max: cycles.last().copied(),
        us_p50: pct(&us, 0.5),
        us_p99: pct(&us, 0.99),
        us_max: us.last().copied(),
        spy_missed: missed,
    })
}
