//! Engine benchmarks (criterion): one `Axis::step` in the middle of a homing
//! leg, one cycle monitor's verdict on that step's command
//! (`engine_step/monitor`: `Monitor::check`, what the cycle adds per axis
//! between the engine and the frame), and one whole cycle's compute
//! (`Core::step` + `Core::fill`, the monitors included) for 1, 8, 32 and 64
//! axes. Goals: ≤ 50 ns per axis step, ≤ 50 ns per monitor check, ≤ 10 µs
//! for a 64-axis cycle. A summary table against the goals is printed at the
//! end.
//!
//! `profile/*`: what a jog or move costs the cycle, trapezoid against
//! S-curve — planning one (the step that asks for it: a move from a moving
//! state; a move that must turn back, which plans two ways and keeps the
//! faster; a stop that must end on a travel limit) and sampling one (every
//! step: the state at an instant in its last segment, the longest scan).
//!
//! A step is measured on fresh copies of the captured axis, a cycle's
//! worth (64) per timed batch, so the axis's state is in the cache as in
//! the cycle; `engine_step/seek_cold` streams its copies from memory
//! instead (criterion's growing `SmallInput` batches), which is what the
//! step measurements of the first benches did: that figure is bounded by the
//! size of `Axis` over the memory bandwidth (≈ 1.7 KB per step).
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
//! `engine_step/monitor`, `cycle/1`, `cycle/8`, `cycle/32`, `cycle/64`, and
//! `profile/*` (e.g. `profile/plan_scurve`).

use criterion::{BatchSize, BenchmarkId, Criterion};
use motion_bench::engine::{
    homing_core, phases, repeated_demo as machine, seek_state, torque_state, Captured,
};
use motion_homing::profile::{Kinematics, Profile, Ramp};
use motion_homing::{Axis, Command, Phase, Status};
use motion_monitor::{Cycle, Monitor};
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

/// Axis counts of the cycle benchmark.
const AXES: [usize; 4] = [1, 8, 32, 64];

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
/// (64 × `size_of::<Axis>()` ≈ 110 KB: in L2, between cycles too).
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

/// The moves of `profile/*`: 50 units at 100 u/s, acceleration 2000,
/// deceleration 1500 u/s², and for the S-curve a jerk of 40 000 u/s³.
fn ramp(jerk: f64) -> Ramp {
    Ramp {
        accel: 2000.0,
        decel: 1500.0,
        jerk,
    }
}

/// A jog's state 30 ms after it started from rest towards 80 u/s: moving,
/// accelerating (what a supersede re-plans from).
fn moving(jerk: f64) -> (u64, Kinematics) {
    let jog = Profile::jog_from(0, Kinematics::rest(0.0), 80.0, ramp(jerk));
    (30_000_000, jog.state(30_000_000))
}

/// The routines of `profile/*`, by name (also run by `--instructions`).
fn profile_routines() -> Vec<(String, Box<dyn FnMut()>)> {
    let mut all: Vec<(String, Box<dyn FnMut()>)> = Vec::new();
    for (kind, jerk) in [("trapezoid", 0.0), ("scurve", 4e4)] {
        let (now, from) = moving(jerk);
        all.push((
            format!("profile/plan_{kind}"),
            Box::new(move || {
                black_box(Profile::move_from(
                    black_box(now),
                    black_box(from),
                    50.0,
                    100.0,
                    ramp(jerk),
                ));
            }),
        ));
        // Moving at +80 towards -1: it must turn back.
        all.push((
            format!("profile/plan_turn_{kind}"),
            Box::new(move || {
                black_box(Profile::move_from(
                    black_box(now),
                    black_box(from),
                    -1.0,
                    100.0,
                    ramp(jerk),
                ));
            }),
        ));
        // A stop on a limit 1 ahead: harder than its deceleration.
        all.push((
            format!("profile/stop_at_{kind}"),
            Box::new(move || {
                black_box(Profile::stop_at_from(
                    black_box(now),
                    black_box(from),
                    from.p + 1.0,
                    jerk,
                ));
            }),
        ));
        let mv = Profile::move_from(now, from, 50.0, 100.0, ramp(jerk));
        let last = now + mv.duration_ns() - 1_000_000;
        all.push((
            format!("profile/sample_{kind}"),
            Box::new(move || {
                black_box(black_box(&mv).state(black_box(last)));
            }),
        ));
    }
    all
}

fn profile(c: &mut Criterion) {
    let mut g = c.benchmark_group("profile");
    for (name, mut routine) in profile_routines() {
        let id = name.strip_prefix("profile/").unwrap_or(&name).to_string();
        g.bench_function(id, |b| b.iter(&mut routine));
    }
    g.finish();
}

/// A monitor that has judged the captured seek for three cycles, and the
/// fourth cycle's inputs: the engine's command and status of that step.
struct Judged {
    monitor: Monitor,
    state: Captured,
    command: Command,
    status: Status,
}

/// The seek of `seek_state()` stepped on for three cycles with the monitor
/// judging each (a homing in its seek: the monitor's history, mode and
/// speed bound in place), then a fourth step whose command is measured.
fn judged() -> Judged {
    let state = seek_state();
    let mut axis = state.axis.clone();
    let mut monitor = Monitor::new(axis.config());
    let step = |axis: &mut Axis, now: u64| {
        let command = axis.step(now, Some(&state.feedback), &state.request);
        (command, *axis.status())
    };
    for k in 0..3 {
        let now = state.now + k * 1_000_000;
        let (command, status) = step(&mut axis, now);
        let out = monitor.check(&cycle_of(&state, now, &command, &status));
        assert_eq!(out, command, "the monitor passes a normal seek");
    }
    let (command, status) = step(&mut axis, state.now + 3_000_000);
    Judged {
        monitor,
        state,
        command,
        status,
    }
}

fn cycle_of<'a>(s: &'a Captured, now: u64, command: &'a Command, status: &'a Status) -> Cycle<'a> {
    Cycle {
        now_ns: now,
        feedback: Some(&s.feedback),
        request: &s.request,
        status,
        reference: None,
        command,
        io_restarted: false,
    }
}

fn monitor_check(c: &mut Criterion) {
    let j = judged();
    let now = j.state.now + 3_000_000;
    let cycle = cycle_of(&j.state, now, &j.command, &j.status);
    assert_eq!(j.monitor.clone().check(&cycle), j.command);
    let mut g = c.benchmark_group("engine_step");
    // a fresh copy of the monitor per check, a cycle's worth per batch
    g.bench_function("monitor", |b| {
        b.iter_batched_ref(
            || j.monitor.clone(),
            |m| m.check(black_box(&cycle)),
            BatchSize::NumIterations(CYCLE_AXES),
        )
    });
    g.finish();
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
        ("engine_step/monitor".into(), 1, Some(50.0)),
    ];
    for what in ["plan", "plan_turn", "stop_at", "sample"] {
        for kind in ["trapezoid", "scurve"] {
            rows.push((format!("profile/{what}_{kind}"), 1, None));
        }
    }
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
                format!("≤ {g} ns per axis"),
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
    println!("engine_step/monitor = one Monitor::check on the command of a seek step");
    println!(
        "profile/* = planning a move (from a moving state; turning back; a stop on a limit) and sampling one, \
         trapezoid against S-curve"
    );
    println!(
        "cycle/N = Core::step + Core::fill for N homing axes (engine steps, monitors, counts↔units \
         for every axis)"
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
        let mut profiles = profile_routines();
        match id {
            "engine_step/monitor" => {
                let j = judged();
                let cycle = cycle_of(&j.state, j.state.now + 3_000_000, &j.command, &j.status);
                let mut ms: Vec<Monitor> = (0..n).map(|_| j.monitor.clone()).collect();
                let mut next = ms.iter_mut();
                counted(n, &mut || {
                    if let Some(m) = next.next() {
                        black_box(m.check(black_box(&cycle)));
                    }
                });
            }
            "engine_step/seek" => step(seek_state(), Phase::Seek),
            "engine_step/torque_detect" => step(torque_state(), Phase::Seek),
            _ if id.starts_with("profile/") => {
                let (_, routine) = profiles
                    .iter_mut()
                    .find(|(name, _)| name == id)
                    .expect("ID: a profile/* benchmark");
                counted(n, routine.as_mut());
            }
            _ => {
                let k = id
                    .strip_prefix("cycle/")
                    .and_then(|k| k.parse().ok())
                    .filter(|k| AXES.contains(k))
                    .expect(
                        "ID: engine_step/seek, engine_step/torque_detect, engine_step/monitor or \
                         cycle/{1,8,32,64}",
                    );
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
    profile(&mut c);
    monitor_check(&mut c);
    cycle(&mut c);
    c.final_summary();
    if !args.iter().any(|a| a == "--list" || a == "--test") {
        summary(&dir, since);
    }
}
