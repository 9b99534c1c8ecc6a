//! Engine benchmarks (criterion): one `Axis::step` in the middle of a homing
//! leg, and one whole cycle's compute (`Core::step` + `Core::fill`) for 1, 8,
//! 32 and 64 axes. Goals: ≤ 50 ns per axis step, ≤ 10 µs for a 64-axis
//! cycle. A summary table against the goals is printed at the end.
//!
//! A step is measured on fresh copies of the captured axis, a cycle's
//! worth (64) per timed batch, so the axis's state is in the cache as in
//! the cycle; `engine_step/seek_cold` streams its copies from memory
//! instead (criterion's growing `SmallInput` batches), which is what the
//! step measurements before issue 14 did: that figure is bounded by the
//! size of `Axis` over the memory bandwidth (≈ 1.2 KB per step).
//!
//! `cargo bench -p motion-bench --bench engine` (≈ 20 s of measuring).
//!
//! Instructions, not time (noise-free, for a shared or virtual machine
//! where `perf` has no counters): `-- --instructions N ID` runs the routine
//! of benchmark `ID` exactly N times in one function, without criterion, so
//! callgrind counts it alone:
//!
//! ```sh
//! valgrind --tool=callgrind --callgrind-out-file=engine.cg \
//!     --toggle-collect='engine::instructions::counted' \
//!     target/release/deps/engine-<hash> --instructions 10000 cycle/64
//! ```
//!
//! The total it prints (`Collected`) divided by N (and by the axis count for
//! a cycle) is the cost of one step; `callgrind_annotate engine.cg` shows
//! where it goes. IDs: `engine_step/seek`, `engine_step/torque_detect`,
//! `cycle/1`, `cycle/8`, `cycle/32`, `cycle/64`.

use criterion::{BatchSize, BenchmarkId, Criterion};
use motion_config::{MachineConfig, DEMO_TOML};
use motion_frames::{axis_to_command, feedback_to_axis, CommandFrame, FeedbackFrame};
use motion_homing::{Axis, Feedback, Phase, Request};
use motion_plant::Plant;
use motion_supervisor::core::Core;
use motion_supervisor::shared::Control;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

/// Axis counts of the cycle benchmark.
const AXES: [usize; 4] = [1, 8, 32, 64];
/// Cycles of real homing (against the plants) before a cycle is measured.
const CYCLE_WARMUP: u64 = 400;

fn demo() -> MachineConfig {
    motion_config::parse(DEMO_TOML).expect("the built-in demo machine parses")
}

/// The inputs of one real engine step, captured mid-homing.
struct Captured {
    axis: Axis,
    feedback: Feedback,
    now: u64,
    request: Request,
    cycle: u64,
}

/// Homes the demo axis `name` against its plant, cycle by cycle, until
/// `stop(axis, feedback)` holds before a step: returns that step's inputs.
fn home_until(name: &str, mut stop: impl FnMut(&Axis, &Feedback) -> bool) -> Captured {
    let m = demo();
    let a = m
        .axes
        .iter()
        .find(|a| a.name == name)
        .expect("demo axis exists");
    let mut axis = Axis::new(a.engine);
    let mut plant = Plant::new(a.sim);
    let dt_ns = m.supervisor.cycle_ns();
    let dt = dt_ns as f64 * 1e-9;
    let mut fb = plant.feedback();
    for k in 0..200_000u64 {
        let now = k * dt_ns;
        // the rung goes high in cycle 1: a rising edge
        let request = Request {
            home: k >= 1,
            ..Request::default()
        };
        if k > 1 && stop(&axis, &fb) {
            return Captured {
                axis,
                feedback: fb,
                now,
                request,
                cycle: k,
            };
        }
        let cmd = axis.step(now, Some(&fb), &request);
        fb = plant.step(&cmd, dt);
    }
    panic!("axis {name}: the state to benchmark was never reached");
}

/// Axis X (switch then marker) in the middle of its first leg: seeking the
/// switch at Home Speed, past acceleration.
fn seek_state() -> Captured {
    home_until("X", |a, fb| {
        a.status().phase == Phase::Seek && fb.position > -10.0
    })
}

/// Axis Z (torque) pushing into its hard stop: torque over the threshold for
/// 5 cycles, the torque time (20 ms) not yet reached.
fn torque_state() -> Captured {
    let m = demo();
    let threshold = m
        .axes
        .iter()
        .find(|a| a.name == "Z")
        .expect("demo axis Z")
        .engine
        .home_torque_threshold;
    let mut over = 0;
    home_until("Z", move |a, fb| {
        if a.status().phase == Phase::Seek && fb.torque.abs() >= threshold {
            over += 1;
        }
        over > 5
    })
}

/// Checks that stepping a copy of `c` is real work in `phase`.
fn check(name: &str, c: &Captured, phase: Phase) {
    let mut a = c.axis.clone();
    let cmd = a.step(c.now, Some(&c.feedback), &c.request);
    assert_eq!(
        a.status().phase,
        phase,
        "{name}: not in {phase:?} after the step"
    );
    assert!(a.status().ip, "{name}: homing not in process");
    eprintln!(
        "{name}: cycle {} of a real homing, phase {}, position {:.3}, torque {:.1} %, command v {:.1}",
        c.cycle,
        a.status().phase.name(),
        c.feedback.position,
        c.feedback.torque,
        cmd.velocity
    );
}

/// Axes a cycle steps at most: the fresh copies of one timed batch of
/// `engine_step/*`, so that they sit in the cache as a cycle's axes do
/// (64 × `size_of::<Axis>()` ≈ 78 KB: in L2, between cycles too).
const CYCLE_AXES: u64 = 64;

fn engine_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("engine_step");
    for (name, state, phase) in [
        ("seek", seek_state(), Phase::Seek),
        ("torque_detect", torque_state(), Phase::Seek),
    ] {
        check(&format!("engine_step/{name}"), &state, phase);
        // Each iteration steps a fresh copy of the captured axis (the copy
        // is made outside the timed loop), with the feedback the plant gave.
        // The copies of a batch are as many as a cycle's axes: the step as
        // the cycle runs it, with the axis's state in the cache.
        let step = |axis: &mut Axis| {
            axis.step(
                black_box(state.now),
                Some(black_box(&state.feedback)),
                black_box(&state.request),
            )
        };
        g.bench_function(name, |b| {
            b.iter_batched_ref(
                || state.axis.clone(),
                step,
                BatchSize::NumIterations(CYCLE_AXES),
            )
        });
        if name == "seek" {
            // The same with criterion's `SmallInput` batches, which grow
            // with the iteration count (to tens of MB of copies): each step
            // then streams its copy from memory, and the figure is about
            // `size_of::<Axis>()` / memory bandwidth, not the step. Shown,
            // without a goal, because earlier measurements were made so.
            g.bench_function("seek_cold", |b| {
                b.iter_batched_ref(|| state.axis.clone(), step, BatchSize::SmallInput)
            });
        }
    }
    g.finish();
}

/// `n` axes: the demo axes repeated, starting with the moving ones
/// (X, C, Z, U, X, ...), names made unique.
fn machine(n: usize) -> MachineConfig {
    let d = demo();
    let axes = (0..n)
        .map(|i| {
            let mut a = d.axes[(i + 1) % d.axes.len()].clone();
            a.name = format!("{}{}", a.name, i);
            a
        })
        .collect();
    MachineConfig {
        supervisor: d.supervisor.clone(),
        ios: d.ios.clone(),
        axes,
        gantries: Vec::new(),
        warnings: Vec::new(),
    }
}

/// A core homing every axis against its plant for [`CYCLE_WARMUP`] cycles:
/// the core, the last feedback frame, a command frame and the next cycle's
/// time.
fn homing_core(m: &MachineConfig) -> (Core, FeedbackFrame, CommandFrame, u64) {
    let mut core = Core::new(m);
    let mut plants: Vec<Plant> = m.axes.iter().map(|a| Plant::new(a.sim)).collect();
    let mut fb = FeedbackFrame::default();
    let mut cmd = CommandFrame::default();
    let dt_ns = m.supervisor.cycle_ns();
    let dt = dt_ns as f64 * 1e-9;
    fb.header.axis_count = m.axes.len() as u32;
    for (i, (a, p)) in m.axes.iter().zip(&plants).enumerate() {
        fb.axes[i] = feedback_to_axis(&p.feedback(), a.engine.counts_per_unit);
    }
    fb.header.origin = 1;
    for k in 0..CYCLE_WARMUP {
        if k == 10 {
            core.control(
                Control::Home {
                    id: 1,
                    mask: u64::MAX >> (64 - m.axes.len()),
                    parallel: true,
                    timeout_ns: 0,
                },
                k * dt_ns,
            );
        }
        core.step(k * dt_ns, false, &[(k > 0).then_some(&fb)]);
        core.fill(0, &mut cmd);
        core.sent(0, k + 1, k * dt_ns);
        fb.answers_sequence = k + 1;
        for (i, (a, p)) in m.axes.iter().zip(plants.iter_mut()).enumerate() {
            let c = axis_to_command(&cmd.axes[i], a.engine.counts_per_unit);
            let f = p.step(&c, dt);
            fb.axes[i] = feedback_to_axis(&f, a.engine.counts_per_unit);
        }
    }
    (core, fb, cmd, CYCLE_WARMUP * dt_ns)
}

fn phases(core: &Core) -> String {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for a in core.axes() {
        let n = a.status().phase.name();
        match counts.iter_mut().find(|c| c.0 == n) {
            Some(c) => c.1 += 1,
            None => counts.push((n, 1)),
        }
    }
    counts
        .iter()
        .map(|(n, k)| format!("{k} {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn cycle(c: &mut Criterion) {
    let mut g = c.benchmark_group("cycle");
    for n in AXES {
        let m = machine(n);
        let (mut core, fb, mut cmd, now) = homing_core(&m);
        let before = phases(&core);
        assert!(
            core.axes().iter().all(|a| a.status().ip),
            "cycle/{n}: every axis should be homing: {before}"
        );
        // The same cycle over and over: same time, same feedback. Every
        // engine runs its full step (validation, event checks, profile
        // sample) and stays where it is, so every iteration does the same
        // real work; the frame conversion runs for every axis.
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                core.step(black_box(now), false, &[Some(black_box(&fb))]);
                core.fill(0, black_box(&mut cmd));
            })
        });
        let after = phases(&core);
        eprintln!("cycle/{n}: axes {before}; after the run: {after}");
        assert_eq!(before, after, "cycle/{n}: the state moved during the run");
    }
    g.finish();
}

/// Where criterion writes its reports: $CRITERION_HOME, else
/// `<target>/criterion` of the target directory this bench was built in.
fn criterion_dir() -> PathBuf {
    if let Some(h) = std::env::var_os("CRITERION_HOME") {
        return PathBuf::from(h);
    }
    std::env::current_exe()
        .ok()
        .and_then(|e| {
            let deps = e.parent()?;
            (deps.file_name()? == "deps").then(|| deps.parent()?.parent().map(Path::to_path_buf))?
        })
        .map_or_else(
            || PathBuf::from("target/criterion"),
            |t| t.join("criterion"),
        )
}

/// Criterion's estimate (slope, else mean) and median, ns, if measured
/// after `since`.
fn estimate(dir: &Path, id: &str, since: SystemTime) -> Option<(f64, f64)> {
    let p = dir.join(id).join("new").join("estimates.json");
    let fresh = std::fs::metadata(&p).ok()?.modified().ok()? >= since;
    if !fresh {
        return None;
    }
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).ok()?).ok()?;
    let point = |k: &str| v.get(k)?.get("point_estimate")?.as_f64();
    Some((point("slope").or_else(|| point("mean"))?, point("median")?))
}

fn fmt_ns(ns: f64) -> String {
    if ns >= 1000.0 {
        format!("{:.2} µs", ns / 1000.0)
    } else {
        format!("{ns:.1} ns")
    }
}

fn summary(dir: &Path, since: SystemTime) {
    println!(
        "\n== engine benchmarks vs goals (criterion estimates; reports in {})",
        dir.display()
    );
    println!(
        "{:<26}{:>12}{:>12}{:>12}   {:<22}verdict",
        "benchmark", "time", "median", "per axis", "goal"
    );
    let mut rows: Vec<(String, usize, Option<f64>)> = vec![
        ("engine_step/seek".into(), 1, Some(50.0)),
        ("engine_step/torque_detect".into(), 1, Some(50.0)),
        ("engine_step/seek_cold".into(), 1, None),
    ];
    for n in AXES {
        rows.push((format!("cycle/{n}"), n, (n == 64).then_some(10_000.0)));
    }
    for (id, n, goal) in rows {
        let Some((t, med)) = estimate(dir, &id, since) else {
            println!("{id:<26}{:>12}", "(not measured in this run)");
            continue;
        };
        let (goal_txt, verdict) = match goal {
            Some(g) if n == 1 && id.starts_with("engine") => (
                "≤ 50 ns per axis".to_string(),
                if t <= g { "ok" } else { "MISSED" },
            ),
            Some(g) => (
                format!("≤ {} per cycle", fmt_ns(g)),
                if t <= g { "ok" } else { "MISSED" },
            ),
            None => ("-".to_string(), ""),
        };
        println!(
            "{id:<26}{:>12}{:>12}{:>12}   {goal_txt:<22}{verdict}",
            fmt_ns(t),
            fmt_ns(med),
            fmt_ns(t / n as f64)
        );
    }
    println!(
        "engine_step/* = one Axis::step on a copy in the cache (64 copies per batch, as a cycle's axes); \
         seek_cold: copies streamed from memory"
    );
    println!(
        "cycle/N = Core::step + Core::fill for N homing axes (engine steps + counts↔units for every axis)"
    );
}

/// `--instructions N ID`: the routine of benchmark `ID` run `N` times in
/// [`instructions::counted`], without criterion (see the top of this file).
mod instructions {
    use super::*;

    /// What callgrind counts (`--toggle-collect`): the states are prepared
    /// outside it.
    #[inline(never)]
    pub fn counted(n: u64, routine: &mut dyn FnMut()) {
        for _ in 0..n {
            routine();
        }
    }

    pub fn run(n: u64, id: &str) {
        let step = |state: Captured, phase| {
            check(id, &state, phase);
            let mut axes: Vec<Axis> = (0..n).map(|_| state.axis.clone()).collect();
            let mut next = axes.iter_mut();
            counted(n, &mut || {
                if let Some(a) = next.next() {
                    black_box(a.step(
                        black_box(state.now),
                        Some(black_box(&state.feedback)),
                        black_box(&state.request),
                    ));
                }
            });
        };
        match id {
            "engine_step/seek" => step(seek_state(), Phase::Seek),
            "engine_step/torque_detect" => step(torque_state(), Phase::Seek),
            _ => {
                let k = id
                    .strip_prefix("cycle/")
                    .and_then(|k| k.parse().ok())
                    .filter(|k| AXES.contains(k))
                    .expect("ID: engine_step/seek, engine_step/torque_detect or cycle/{1,8,32,64}");
                let (mut core, fb, mut cmd, now) = homing_core(&machine(k));
                counted(n, &mut || {
                    core.step(black_box(now), false, &[Some(black_box(&fb))]);
                    core.fill(0, black_box(&mut cmd));
                });
            }
        }
        eprintln!("{id}: ran {n} times in engine::instructions::counted");
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(p) = args.iter().position(|a| a == "--instructions") {
        let n = args
            .get(p + 1)
            .and_then(|v| v.parse().ok())
            .expect("--instructions N ID: a number of runs");
        instructions::run(n, args.get(p + 2).map_or("", String::as_str));
        return;
    }
    let since = SystemTime::now() - Duration::from_secs(1);
    let dir = criterion_dir();
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_millis(1500))
        .sample_size(50)
        .without_plots()
        .output_directory(&dir)
        .configure_from_args();
    engine_step(&mut c);
    cycle(&mut c);
    c.final_summary();
    if !args.iter().any(|a| a == "--list" || a == "--test") {
        summary(&dir, since);
    }
}
