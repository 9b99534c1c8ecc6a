//! What the stream costs the cycle: wake-up and compute of a 64-axis
//! machine with a 1 kHz stream of all 64 axes against none, in alternating
//! slices of one run (every slice a `motion-supervisor run --duration`
//! read back as the other slice benches read theirs; both variants home and
//! enable the axes the same way, only the stream differs), as ratios.

use crate::Opts;
use motion_bench::bins::Binaries;
use motion_bench::machine::{streamed_names, streamed_with};
use motion_bench::outcome::Bench;
use motion_bench::slice::{Group, Slice};
use motion_bench::stream::{home_and_enable, Streamer};
use motion_bench::{drive, runs};
use serde_json::{json, Value};
use std::time::Duration;

/// Axes streamed.
pub const AXES: usize = 64;

/// The two variants' groups and their ratios.
pub struct Cost {
    pub none: Group,
    pub stream: Group,
}

impl Cost {
    pub fn json(&self) -> Value {
        let r = |a: f64, b: f64| (b > 0.0).then(|| motion_report::round(a / b, 2));
        json!({
            "axes": AXES,
            "none": self.none.json(),
            "stream": self.stream.json(),
            "compute_p99_ratio": r(self.stream.c.p99, self.none.c.p99),
            "wakeup_p99_ratio": r(self.stream.w.p99, self.none.w.p99),
            "compute_p50_ratio": r(self.stream.c.p50, self.none.c.p50),
        })
    }
}

pub fn run(o: &Opts, b: &Binaries, bench: &Bench) -> Result<Cost, String> {
    let (mut none, mut stream) = (Vec::new(), Vec::new());
    for i in 0..o.slicing.count() {
        for with_stream in [false, true] {
            if motion_bench::proc::stop_requested() {
                break;
            }
            let len = o.slicing.len(i);
            let s = one(o, b, bench, i, with_stream, len)?;
            if with_stream { &mut stream } else { &mut none }.push(s);
        }
    }
    Ok(Cost {
        none: Group::of(&none.iter().collect::<Vec<_>>()),
        stream: Group::of(&stream.iter().collect::<Vec<_>>()),
    })
}

/// One slice of `len` s, streaming or not.
fn one(
    o: &Opts,
    b: &Binaries,
    bench: &Bench,
    i: usize,
    with_stream: bool,
    len: f64,
) -> Result<Slice, String> {
    let tag = format!("mbs{}c{i}{}", std::process::id(), u8::from(with_stream));
    let sup = o.cycle.supervisor(&tag);
    let toml = streamed_with(&sup, AXES);
    let start = bench.t0.elapsed();
    let (mut d, hlog) = runs::start(b, &bench.tmp, (&tag, &toml, &tag), len, &[])?;
    if let Err(e) = drive::wait_until_ready(&b.motionctl, &tag, &mut d, Duration::from_secs(20)) {
        let ended = drive::stop_run(d, Duration::from_secs(20));
        let _ = drive::clean_leftovers(&tag);
        return Err(format!("{tag}: {e} ({})", ended.describe()));
    }
    home_and_enable(&tag, AXES)?;
    if with_stream {
        let names = streamed_names(AXES);
        let streamer = Streamer::start(
            &tag,
            names,
            1_000_000,
            (o.cycle.other_cpu(), o.client_priority),
            Box::new(|k| {
                let t = k as f64 * 1e-3;
                (0..AXES)
                    .map(|a| (t * 6.0 + a as f64).sin() * 0.5 - (a as f64).sin() * 0.5)
                    .collect()
            }),
        );
        // stream until shortly before the run ends
        let left = len - bench.t0.elapsed().saturating_sub(start).as_secs_f64() - 0.3;
        std::thread::sleep(Duration::from_secs_f64(left.max(0.0)));
        streamer.finish()?;
    }
    let ended = d.wait(Duration::from_secs_f64(len + 30.0), Duration::from_secs(5));
    let _ = drive::clean_leftovers(&tag);
    let (m, _) = runs::read(&ended, &hlog)?;
    Ok(Slice { start, len, m })
}
