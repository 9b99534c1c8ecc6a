//! The following error of the sim plant streaming a circle on two axes: a
//! stream at the cycle rate of `x = r (cos θ − 1)`, `y = r sin θ` (it starts
//! where the axes stand), θ run up from rest to ω over the first
//! [`RAMP_S`] (a constant angular acceleration: the setpoints stay within
//! the axes' stream_acceleration), sampled from the 100 Hz status once at
//! speed: per axis the following error (command − actual, the supervisor's
//! own view: the actual position is the answer to the previous cycle's
//! command), and the contour error (the actual point's distance from the
//! circle − r).

use crate::Opts;
use motion_bench::bins::Binaries;
use motion_bench::drive;
use motion_bench::machine::{streamed_names, streamed_with};
use motion_bench::outcome::Bench;
use motion_bench::stream::{home_and_enable, Streamer};
use motion_control::Client;
use motion_report::nearest_rank as pct;
use serde::Serialize;
use std::time::{Duration, Instant};

/// Seconds of the run-up to full angular speed (not measured).
pub const RAMP_S: f64 = 1.0;

/// θ at `t`: constant angular acceleration to `w` over [`RAMP_S`], then `w`.
fn angle(t: f64, w: f64) -> f64 {
    if t < RAMP_S {
        w * t * t / (2.0 * RAMP_S)
    } else {
        w * (t - RAMP_S / 2.0)
    }
}

/// What the circle measured.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Circle {
    pub radius: f64,
    pub hz: f64,
    /// Path speed, units/s.
    pub speed: f64,
    pub samples: usize,
    /// |command − actual| per axis, units.
    pub following_p50: [Option<f64>; 2],
    pub following_p99: [Option<f64>; 2],
    pub following_max: [Option<f64>; 2],
    /// |distance from the centre − r| of the actual point, units.
    pub contour_p99: Option<f64>,
    pub contour_max: Option<f64>,
}

pub fn run(o: &Opts, b: &Binaries, bench: &Bench) -> Result<Circle, String> {
    let prefix = format!("mbs{}o", std::process::id());
    let sup = o.cycle.supervisor(&prefix);
    let d = drive::start_machine(b, &bench.tmp, &prefix, &streamed_with(&sup, 2))?;
    let result = measure(o, &prefix);
    let _ = drive::stop_run(d, Duration::from_secs(20));
    let _ = drive::clean_leftovers(&prefix);
    result
}

fn measure(o: &Opts, prefix: &str) -> Result<Circle, String> {
    home_and_enable(prefix, 2)?;
    let (r, hz) = (o.radius, o.hz);
    let w = 2.0 * std::f64::consts::PI * hz;
    let period = u64::from(o.cycle.period_us) * 1000;
    let dt = period as f64 * 1e-9;
    let streamer = Streamer::start(
        prefix,
        streamed_names(2),
        period,
        (o.cycle.other_cpu(), o.client_priority),
        Box::new(move |k| {
            let a = angle(k as f64 * dt, w);
            vec![r * (a.cos() - 1.0), r * a.sin()]
        }),
    );
    let mut c = Client::connect(prefix, None).map_err(|e| e.to_string())?;
    let (mut fe, mut contour) = ([Vec::new(), Vec::new()], Vec::new());
    std::thread::sleep(Duration::from_secs_f64(RAMP_S + 0.1));
    let until = Instant::now() + Duration::from_secs_f64(o.seconds);
    let mut last = 0;
    while Instant::now() < until {
        std::thread::sleep(Duration::from_millis(10));
        let st = c
            .status(Duration::from_secs(2))
            .map_err(|e| e.to_string())?;
        if st.sequence == last {
            continue;
        }
        last = st.sequence;
        // (command, actual) of an axis while it streams.
        let pair = |e: &motion_control::AxisStatusEntry| {
            e.cmd_position().zip(e.position()).filter(|_| e.streaming())
        };
        let (Some((c0, p0)), Some((c1, p1))) = (pair(&st.axes()[0]), pair(&st.axes()[1])) else {
            continue;
        };
        fe[0].push((c0 - p0).abs());
        fe[1].push((c1 - p1).abs());
        let (x, y) = (p0 + r, p1);
        contour.push(((x * x + y * y).sqrt() - r).abs());
    }
    streamer.finish()?;
    for v in fe.iter_mut().chain([&mut contour]) {
        v.sort_by(f64::total_cmp);
    }
    Ok(Circle {
        radius: r,
        hz,
        speed: w * r,
        samples: contour.len(),
        following_p50: [pct(&fe[0], 0.5), pct(&fe[1], 0.5)],
        following_p99: [pct(&fe[0], 0.99), pct(&fe[1], 0.99)],
        following_max: [fe[0].last().copied(), fe[1].last().copied()],
        contour_p99: pct(&contour, 0.99),
        contour_max: contour.last().copied(),
    })
}
