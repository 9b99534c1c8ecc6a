//! Property tests of the jerk-limited (S-curve) profiles, sampled as the
//! cycle samples them: random limits, random cycle times (0.25–4 ms),
//! random sample instants (each cycle late or early by up to a quarter),
//! random states — taken from the profiles themselves, re-planned at
//! random instants, as the engine re-plans a supersede or a stop.
//!
//! Between any samples (divided differences, which are weighted averages
//! of the continuous derivative over the samples' span):
//!
//! * the speed `|Δp/Δt|` stays within the cap (1e-9 relative);
//! * twice the second divided difference stays within `[-dec, +acc]` in
//!   the direction of motion (and the larger of the two across a
//!   reversal through rest);
//! * six times the third divided difference stays within `±jerk` — also
//!   across every re-plan, so nothing steps there: a step in position,
//!   velocity or acceleration would show as an unbounded difference;
//! * a re-plan's first sample is the state it was planned from, exactly.
//!
//! Each bound gets the rounding the samples carry (16 ulps of the largest
//! position, through the divided difference's weights) and no more.
//! Moves end bit for bit on their target at their duration, jogs cruise at
//! their velocity exactly, stops on a point never pass it, timed moves end
//! at their time; `jerk = 0` is the trapezoid, bit for bit; absurd limits
//! hold, finite inputs never give a NaN.

mod common;

use common::runner;
use motion_homing::profile::{reaches, stop_displacement, Kinematics, Profile, Ramp};
use proptest::prelude::*;
use std::cell::Cell;

/// The limits of one axis.
#[derive(Clone, Copy, Debug)]
struct Lim {
    vmax: f64,
    acc: f64,
    dec: f64,
    jerk: f64,
}

impl Lim {
    fn ramp(&self) -> Ramp {
        Ramp {
            accel: self.acc,
            decel: self.dec,
            jerk: self.jerk,
        }
    }
}

/// `10^x` for `x` in `[lo, hi]`: log-uniform.
fn log_range(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.log10()..hi.log10()).prop_map(|e| 10f64.powf(e))
}

/// Speed caps 0.5–50 units/s; acceleration and deceleration reaching the
/// cap in 5 ms–0.5 s; jerk reaching either in 0.5 ms–0.5 s.
fn limits() -> impl Strategy<Value = Lim> {
    (
        log_range(0.5, 50.0),
        log_range(2.0, 200.0),
        log_range(2.0, 200.0),
        log_range(2.0, 2000.0),
    )
        .prop_map(|(vmax, fa, fd, fj)| {
            let (acc, dec) = (vmax * fa, vmax * fd);
            Lim {
                vmax,
                acc,
                dec,
                jerk: acc.max(dec) * fj,
            }
        })
}

/// Cycle times 0.25–4 ms, in ns.
fn cycle() -> impl Strategy<Value = u64> {
    250_000u64..=4_000_000
}

/// Sample instants: one a cycle, each early or late by up to a quarter.
struct Clock {
    t: u64,
    cycle: u64,
    seed: u64,
}

impl Clock {
    fn next(&mut self) -> u64 {
        // xorshift: the jitter is part of the case (its seed is).
        self.seed ^= self.seed << 13;
        self.seed ^= self.seed >> 7;
        self.seed ^= self.seed << 17;
        let q = self.cycle / 4;
        let jitter = self.seed % (2 * q + 1);
        self.t += self.cycle - q + jitter;
        self.t
    }
}

/// A sample: instant (ns) and state.
type S = (u64, Kinematics);

/// What the samples of a run must keep to.
struct Bounds {
    vmax: f64,
    acc: f64,
    dec: f64,
    /// `None`: not checked (a stop braking beyond `dec`).
    jerk: Option<f64>,
    accel_checked: bool,
}

impl Bounds {
    fn of(l: &Lim) -> Self {
        Self {
            vmax: l.vmax,
            acc: l.acc,
            dec: l.dec,
            jerk: Some(l.jerk),
            accel_checked: true,
        }
    }
}

/// `m!` times the divided difference of order `m` of the window, and the
/// rounding it may carry from samples each off by `delta`.
fn divided(w: &[S], t0: u64, delta: f64) -> (f64, f64) {
    let t = |s: &S| (s.0 - t0) as f64 * 1e-9;
    let (mut d, mut err) = (0.0, 0.0);
    for (i, si) in w.iter().enumerate() {
        let mut den = 1.0;
        for (k, sk) in w.iter().enumerate() {
            if k != i {
                den *= t(si) - t(sk);
            }
        }
        d += si.1.p / den;
        err += delta / den.abs();
    }
    let fact = [1.0, 1.0, 2.0, 6.0][w.len() - 1];
    (d * fact, err * fact)
}

const REL: f64 = 1e-9;

fn check(xs: &[S], b: &Bounds) -> Result<(), String> {
    let Some(first) = xs.first() else {
        return Ok(());
    };
    let t0 = first.0;
    let big = xs.iter().fold(1.0f64, |m, s| m.max(s.1.p.abs()));
    let delta = 16.0 * f64::EPSILON * big;
    for (k, s) in xs.iter().enumerate() {
        let k_ok = s.1.p.is_finite() && s.1.v.is_finite() && s.1.a.is_finite();
        if !k_ok {
            return Err(format!("sample {k} not finite: {s:?}"));
        }
    }
    for w in xs.windows(2) {
        let (v, e) = divided(w, t0, delta);
        if v.abs() > b.vmax * (1.0 + REL) + e {
            return Err(format!("speed {v} > {} at {}", b.vmax, w[0].0));
        }
    }
    if b.accel_checked {
        for w in xs.windows(3) {
            let (a, e) = divided(w, t0, delta);
            let (lo, hi) = if w.iter().all(|s| s.1.v >= 0.0) {
                (-b.dec, b.acc)
            } else if w.iter().all(|s| s.1.v <= 0.0) {
                (-b.acc, b.dec)
            } else {
                let m = b.acc.max(b.dec);
                (-m, m)
            };
            if a < lo * (1.0 + REL) - e || a > hi * (1.0 + REL) + e {
                return Err(format!(
                    "acceleration {a} outside [{lo}, {hi}] ± {e} at {}",
                    w[0].0
                ));
            }
        }
    }
    if let Some(j) = b.jerk {
        for w in xs.windows(4) {
            let (d3, e) = divided(w, t0, delta);
            if d3.abs() > j * (1.0 + REL) + e {
                return Err(format!("jerk {d3} > {j} ± {e} at {} ({:?})", w[0].0, &w));
            }
        }
    }
    Ok(())
}

/// A re-plan of the chain.
#[derive(Clone, Copy, Debug)]
enum Op {
    /// Jog at this fraction of the cap (sign: direction).
    Jog(f64),
    /// Move by this many seconds of travel at the cap.
    Move(f64),
    Stop,
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        (-1.0..1.0f64).prop_map(Op::Jog),
        Just(Op::Jog(0.0)),
        (-1.5..1.5f64).prop_map(Op::Move),
        Just(Op::Stop),
    ]
}

fn plan(op: Op, now: u64, from: Kinematics, l: &Lim) -> Profile {
    match op {
        Op::Jog(f) => Profile::jog_from(now, from, f * l.vmax, l.ramp()),
        Op::Move(s) => Profile::move_from(now, from, from.p + s * l.vmax, l.vmax, l.ramp()),
        Op::Stop => Profile::stop_from(now, from, l.dec, l.jerk),
    }
}

/// Samples `p` from the clock's next instant on until `until` (or the
/// profile is done `extra` cycles), appending to `xs`.
fn run(p: &Profile, now: u64, clock: &mut Clock, until: Option<u64>, xs: &mut Vec<S>) {
    let mut after_done = 0;
    loop {
        let t = clock.next();
        xs.push((t, p.state(t)));
        if until.is_some_and(|u| t >= u) {
            return;
        }
        if p.is_done(t) || (until.is_none() && t > now + p.duration_ns()) {
            after_done += 1;
            if after_done > 4 {
                return;
            }
        }
    }
}

#[derive(Clone, Debug)]
struct Chain {
    lim: Lim,
    cycle: u64,
    seed: u64,
    p0: f64,
    /// Each re-plan and how far into the previous one it comes (a fraction
    /// of the previous one's duration, up to a bit past its end).
    ops: Vec<(Op, f64)>,
}

fn chain() -> impl Strategy<Value = Chain> {
    (
        limits(),
        cycle(),
        any::<u64>(),
        -100.0..100.0f64,
        prop::collection::vec((op(), 0.0..1.2f64), 1..5),
    )
        .prop_map(|(lim, cycle, seed, p0, ops)| Chain {
            lim,
            cycle,
            seed: seed | 1,
            p0,
            ops,
        })
}

/// Runs a chain: each op planned at a sample instant from the state the
/// profile before it had there; checks each op's own promises as it goes.
fn run_chain(c: &Chain) -> Result<Vec<S>, String> {
    let l = &c.lim;
    let mut clock = Clock {
        t: 1_000_000_000,
        cycle: c.cycle,
        seed: c.seed,
    };
    let mut xs: Vec<S> = vec![(clock.t, Kinematics::rest(c.p0))];
    let mut from = Kinematics::rest(c.p0);
    for (i, &(op, frac)) in c.ops.iter().enumerate() {
        let now = xs.last().unwrap().0;
        let p = plan(op, now, from, l);
        let first = p.state(now);
        if first.p != from.p || first.v != from.v || first.a != from.a {
            return Err(format!("op {i} {op:?} starts at {first:?}, not {from:?}"));
        }
        if let Op::Move(s) = op {
            let target = from.p + s * l.vmax;
            check_move_end(&p, now, target)?;
            if reaches(from, target, l.dec, l.jerk) {
                check_no_reversal(&p, now, from.p, target, c.cycle)?;
            }
        }
        let last = i + 1 == c.ops.len();
        let span = p.duration_ns().max(c.cycle);
        let until = if last {
            None
        } else {
            Some(now + (span as f64 * frac) as u64)
        };
        let mut seg = Vec::new();
        run(&p, now, &mut clock, until, &mut seg);
        if let Op::Jog(f) = op {
            if let Some((t, k)) = seg.last().filter(|(t, _)| *t >= now + p.duration_ns()) {
                if k.v != f * l.vmax || k.a != 0.0 {
                    return Err(format!("jog {f} not cruising at {t}: {k:?}"));
                }
            }
        }
        from = seg.last().map_or(from, |s| s.1);
        xs.extend(seg);
    }
    Ok(xs)
}

/// Done at its duration, exactly on the target, and at rest from then on.
fn check_move_end(p: &Profile, now: u64, target: f64) -> Result<(), String> {
    let end = now + p.duration_ns();
    for t in [end, end + 1, end + 1_000_000_000] {
        if p.sample(t) != (target, 0.0) || !p.is_done(t) {
            return Err(format!("move not on {target} at {t}: {:?}", p.sample(t)));
        }
    }
    if p.duration_ns() > 0 && p.is_done(end - 1) {
        return Err("move done before its duration".into());
    }
    Ok(())
}

/// Never moves away from the target nor passes it.
fn check_no_reversal(
    p: &Profile,
    now: u64,
    p0: f64,
    target: f64,
    cycle: u64,
) -> Result<(), String> {
    let s = if target >= p0 { 1.0 } else { -1.0 };
    let mut prev = p0;
    let mut t = now;
    while t <= now + p.duration_ns() + cycle {
        let x = p.sample(t).0;
        let tol = 16.0 * f64::EPSILON * (1.0 + x.abs());
        if (x - prev) * s < -tol || (x - target) * s > tol {
            return Err(format!("reverses at {t}: {prev} → {x} (target {target})"));
        }
        prev = x;
        t += cycle;
    }
    Ok(())
}

/// Jogs, moves and stops re-planned from each other's sampled state at
/// random instants: every bound holds over the whole chain.
#[test]
fn chains_of_replans_keep_every_bound() {
    let samples = Cell::new(0usize);
    runner(1000)
        .run(&chain(), |c| {
            let xs = run_chain(&c).map_err(|e| TestCaseError::fail(format!("{e}\n{c:?}")))?;
            samples.set(samples.get() + xs.len());
            check(&xs, &Bounds::of(&c.lim)).map_err(|e| TestCaseError::fail(format!("{e}\n{c:?}")))
        })
        .unwrap();
    eprintln!("chains: {} samples checked", samples.get());
}

/// The checker sees what it is there for: a trapezoid's steps of
/// acceleration break the jerk bound, a re-plan that forgets the
/// acceleration breaks it too, a jog over its cap breaks the speed.
#[test]
fn the_checker_can_fail() {
    let l = Lim {
        vmax: 10.0,
        acc: 100.0,
        dec: 100.0,
        jerk: 1000.0,
    };
    let sample = |p: &Profile, from: u64, to: u64| -> Vec<S> {
        (from..to)
            .step_by(1_000_000)
            .map(|t| (t, p.state(t)))
            .collect()
    };
    let trapezoid = Profile::move_from(
        0,
        Kinematics::rest(0.0),
        5.0,
        10.0,
        Ramp::trapezoid(100.0, 100.0),
    );
    let xs = sample(&trapezoid, 0, 1_000_000_000);
    assert!(check(
        &xs,
        &Bounds {
            jerk: None,
            ..Bounds::of(&l)
        }
    )
    .is_ok());
    assert!(check(&xs, &Bounds::of(&l)).unwrap_err().contains("jerk"));
    // An S-curve jog re-planned at 50 ms from (p, v) only: the acceleration
    // drops from 50 to 0 at once.
    let jog = Profile::jog_from(0, Kinematics::rest(0.0), 10.0, l.ramp());
    let mut xs = sample(&jog, 0, 50_000_000);
    let k = jog.state(50_000_000);
    let replan = Profile::jog_from(50_000_000, Kinematics { a: 0.0, ..k }, 10.0, l.ramp());
    xs.extend(sample(&replan, 50_000_000, 400_000_000));
    assert!(check(&xs, &Bounds::of(&l)).unwrap_err().contains("jerk"));
    let fast = Profile::jog_from(0, Kinematics::rest(0.0), 10.5, l.ramp());
    let xs = sample(&fast, 0, 400_000_000);
    assert!(check(&xs, &Bounds::of(&l)).unwrap_err().contains("speed"));
}

/// A stop that must end on a point ahead (a travel limit), from a jog's
/// state at any instant, the point anywhere from just ahead to beyond the
/// plain stop: never beyond it, exactly on it at its end, never back;
/// jerk-limited wherever a jerk-limited stop can end there (then braking
/// no harder than the shortest stop at this jerk needs), else uniformly
/// at `v²/2x`.
#[test]
fn stops_on_a_point_never_pass_it() {
    let kept = Cell::new(0);
    let dropped = Cell::new(0);
    let case = (
        limits(),
        cycle(),
        any::<u64>(),
        0.2..1.0f64,
        0.0..1.0f64,
        0.01..1.5f64,
    );
    runner(1000)
        .run(&case, |(l, cycle, seed, f, when, frac)| {
            let mut clock = Clock {
                t: 0,
                cycle,
                seed: seed | 1,
            };
            let dir = if seed & 2 == 0 { 1.0 } else { -1.0 };
            let jog = Profile::jog_from(0, Kinematics::rest(0.0), dir * f * l.vmax, l.ramp());
            let mut xs = Vec::new();
            let until = (jog.duration_ns() as f64 * when * 1.5) as u64;
            run(&jog, 0, &mut clock, Some(until), &mut xs);
            let (now, from) = *xs.last().unwrap();
            let plain = stop_displacement(from.v, from.a, l.dec, l.jerk);
            let target = from.p + plain * frac;
            let p = Profile::stop_at_from(now, from, target, l.jerk);
            let shortest = stop_displacement(from.v, from.a, 1e300, l.jerk);
            let jerk_kept = (target - from.p).abs() >= shortest.abs() * (1.0 + 1e-9);
            let bound = if jerk_kept {
                kept.set(kept.get() + 1);
                let hardest = (l.jerk * from.v.abs() + 0.5 * from.a * from.a).sqrt() + from.a.abs();
                Bounds {
                    dec: if frac >= 1.0 {
                        l.dec
                    } else {
                        hardest.max(l.dec)
                    },
                    ..Bounds::of(&l)
                }
            } else {
                dropped.set(dropped.get() + 1);
                let uniform = from.v * from.v / (2.0 * (target - from.p).abs());
                // The acceleration steps once, from the jog's to -v²/2x.
                Bounds {
                    dec: uniform.max(l.dec),
                    acc: l.acc.max(uniform),
                    jerk: None,
                    ..Bounds::of(&l)
                }
            };
            let start = xs.len() - 1;
            run(&p, now, &mut clock, None, &mut xs);
            let fail = |e: String| TestCaseError::fail(format!("{e}: {l:?} {from:?} → {target}"));
            // Before the stop: the jog's; across and after: the stop's.
            check(&xs[..=start], &Bounds::of(&l)).map_err(fail)?;
            let tail = &xs[start.saturating_sub(3)..];
            let b = Bounds {
                jerk: bound.jerk.filter(|_| start >= 3),
                ..bound
            };
            check(if jerk_kept { tail } else { &xs[start..] }, &b).map_err(fail)?;
            let s = dir;
            for (t, k) in &xs[start..] {
                prop_assert!((k.p - target) * s <= 0.0, "beyond {target} at {t}: {k:?}");
            }
            prop_assert!(xs[start..]
                .windows(2)
                .all(|w| (w[1].1.p - w[0].1.p) * s >= 0.0));
            let end = now + p.duration_ns();
            prop_assert_eq!(p.sample(end), (target, 0.0));
            prop_assert!(p.is_done(end));
            Ok(())
        })
        .unwrap();
    eprintln!(
        "stops on a point: {} jerk-limited, {} uniform",
        kept.get(),
        dropped.get()
    );
    assert!(kept.get() > 100 && dropped.get() > 100);
}

/// A timed move from rest (a gantry side's final move): exactly on its
/// target at exactly its time (not done before), within every bound,
/// never reversing; asked faster than it can, the fastest move.
#[test]
fn timed_moves_end_at_their_time() {
    let case = (limits(), cycle(), any::<u64>(), -1.5..1.5f64, 0.5..3.0f64);
    runner(1000)
        .run(&case, |(l, cycle, seed, dist, stretch)| {
            let target = 3.0 + dist * l.vmax;
            let fastest = Profile::move_from(0, Kinematics::rest(3.0), target, l.vmax, l.ramp());
            let ns = (fastest.duration_ns() as f64 * stretch) as u64;
            let p = Profile::move_in(0, 3.0, target, ns, l.vmax, l.ramp());
            if ns <= fastest.duration_ns() {
                prop_assert_eq!(p, fastest);
                return Ok(());
            }
            // The duration is the time in s rounded up to ns: the ns asked,
            // or one more where `ns · 1e-9 · 1e9` rounds above it.
            prop_assert!(p.duration_ns() - ns <= 1);
            prop_assert_eq!(p.sample(ns), (target, 0.0));
            prop_assert!(p.is_done(ns) && !p.is_done(ns - 1));
            let mut clock = Clock {
                t: 0,
                cycle,
                seed: seed | 1,
            };
            let mut xs = vec![(0, p.state(0))];
            run(&p, 0, &mut clock, None, &mut xs);
            check(&xs, &Bounds::of(&l)).map_err(TestCaseError::fail)?;
            check_no_reversal(&p, 0, 3.0, target, cycle).map_err(TestCaseError::fail)?;
            Ok(())
        })
        .unwrap();
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e3..1e3f64,
        Just(0.0),
        Just(-1.0),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(1e-300),
        Just(1e300),
    ]
}

/// `jerk = 0` plans exactly the trapezoid of before (the same profile,
/// field for field), whatever the acceleration of the state.
#[test]
fn zero_jerk_is_the_trapezoid() {
    let case = (
        (
            -100.0..100.0f64,
            -50.0..50.0f64,
            -500.0..500.0f64,
            -100.0..100.0f64,
        ),
        (
            0.1..60.0f64,
            1.0..5000.0f64,
            1.0..5000.0f64,
            0u64..5_000_000_000,
        ),
    );
    runner(2000)
        .run(&case, |((p, v, a, target), (vmax, acc, dec, ns))| {
            let from = Kinematics { p, v, a };
            let r = Ramp::trapezoid(acc, dec);
            prop_assert_eq!(
                Profile::jog_from(7, from, target / 2.0, r),
                Profile::jog(7, p, v, target / 2.0, acc, dec)
            );
            prop_assert_eq!(
                Profile::stop_from(7, from, dec, 0.0),
                Profile::stop(7, p, v, dec)
            );
            prop_assert_eq!(
                Profile::stop_at_from(7, from, target, 0.0),
                Profile::stop_at(7, p, v, target)
            );
            prop_assert_eq!(
                Profile::move_from(7, from, target, vmax, r),
                Profile::move_to(7, p, v, target, vmax, acc, dec)
            );
            prop_assert_eq!(
                Profile::move_in(7, p, target, ns, vmax, r),
                Profile::move_to_in(7, p, target, ns, vmax, acc, dec)
            );
            prop_assert_eq!(
                reaches(from, target, dec, 0.0),
                motion_homing::profile::reaches_without_reversing(p, v, target, dec)
            );
            prop_assert_eq!(stop_displacement(v, a, dec, 0.0), v * v.abs() / (2.0 * dec));
            Ok(())
        })
        .unwrap();
}

/// Any inputs at all: no panic; an unusable limit (zero, negative, NaN,
/// infinite) or state holds where it is; finite usable inputs — however
/// extreme — never give a NaN.
#[test]
fn absurd_inputs_hold_and_nothing_is_ever_nan() {
    let case = (
        (any_f64(), any_f64(), any_f64(), any_f64()),
        (any_f64(), any_f64(), any_f64(), any_f64(), any_f64()),
        0u64..u64::MAX,
    );
    runner(2000)
        .run(
            &case,
            |((p, v, a, target), (vmax, acc, dec, jerk, vel), ns)| {
                let from = Kinematics { p, v, a };
                let r = Ramp {
                    accel: acc,
                    decel: dec,
                    jerk,
                };
                let usable = |x: f64| x.is_finite() && x > 0.0;
                let jerk_ok = jerk == 0.0 || usable(jerk);
                let ramp_ok = usable(acc) && usable(dec) && jerk_ok;
                let (state, aim) = (from.is_finite(), from.is_finite() && target.is_finite());
                // Each plan, and whether its inputs are finite and usable.
                let plans = [
                    (
                        Profile::jog_from(5, from, vel, r),
                        state && vel.is_finite() && ramp_ok,
                    ),
                    (
                        Profile::stop_from(5, from, dec, jerk),
                        state && usable(dec) && jerk_ok,
                    ),
                    (
                        Profile::move_from(5, from, target, vmax, r),
                        aim && usable(vmax) && ramp_ok,
                    ),
                    (Profile::stop_at_from(5, from, target, jerk), aim && jerk_ok),
                    (
                        Profile::move_in(5, p, target, ns % 10_000_000_000, vmax, r),
                        p.is_finite() && target.is_finite() && usable(vmax) && ramp_ok,
                    ),
                ];
                for (i, (plan, valid)) in plans.iter().enumerate() {
                    for t in [0, 5, 6, 1_000_005, ns / 3, ns, u64::MAX] {
                        let k = plan.state(t);
                        if !valid {
                            prop_assert_eq!(
                                (k.v, k.a),
                                (0.0, 0.0),
                                "plan {} not a hold at {}",
                                i,
                                t
                            );
                            prop_assert!(k.p == p || (p.is_nan() && k.p.is_nan()));
                        } else {
                            // 1e300 units/s for 1e10 s is beyond the floats:
                            // infinite then, but never NaN.
                            prop_assert!(
                                !(k.p.is_nan() || k.v.is_nan() || k.a.is_nan()),
                                "plan {} at {}: {:?}",
                                i,
                                t,
                                k
                            );
                        }
                    }
                }
                let _ = reaches(from, target, dec, jerk);
                let d = stop_displacement(v, a, dec, jerk);
                prop_assert!(!(d.is_nan() && v.is_finite() && a.is_finite()));
                Ok(())
            },
        )
        .unwrap();
}

/// Extreme but physical inputs (positions to ±1e6, speeds to 1e4,
/// accelerations to 1e7, limits from 1e-3 to 1e9, jerk to 1e12, any
/// instant within a day): every plan's every sample is finite.
#[test]
fn physical_inputs_give_finite_samples() {
    let lim = || log_range(1e-3, 1e9);
    let case = (
        (
            -1e6..1e6f64,
            -1e4..1e4f64,
            -1e7..1e7f64,
            -1e6..1e6f64,
            -1e4..1e4f64,
        ),
        (lim(), lim(), lim(), log_range(1e-3, 1e12)),
        (0u64..86_400_000_000_000, 0u64..100_000_000_000),
    );
    runner(5000)
        .run(
            &case,
            |((p, v, a, target, vel), (vmax, acc, dec, jerk), (t, ns))| {
                let from = Kinematics { p, v, a };
                let r = Ramp {
                    accel: acc,
                    decel: dec,
                    jerk,
                };
                let plans = [
                    Profile::jog_from(0, from, vel, r),
                    Profile::stop_from(0, from, dec, jerk),
                    Profile::move_from(0, from, target, vmax, r),
                    Profile::stop_at_from(0, from, target, jerk),
                    Profile::move_in(0, p, target, ns, vmax, r),
                ];
                for (i, plan) in plans.iter().enumerate() {
                    for t in [0, 1, t / 7, t, plan.duration_ns()] {
                        let k = plan.state(t);
                        prop_assert!(k.is_finite(), "plan {} at {}: {:?}", i, t, k);
                    }
                }
                prop_assert!(stop_displacement(v, a, dec, jerk).is_finite());
                Ok(())
            },
        )
        .unwrap();
}
