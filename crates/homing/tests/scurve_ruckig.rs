//! The S-curve move and jog against Ruckig, the reference jerk-limited
//! trajectory generator (its Rust port `rsruckig`, a dev-dependency: the
//! engine never links it): for random starts, targets and limits, the
//! durations of both plans to rest on the target, and to a jog's velocity
//! (Ruckig's velocity interface).
//!
//! Ruckig is time-optimal, so ours is never shorter (1e-6 relative for
//! the rounding of our duration to whole ns). Where both are bound alike
//! ours is as short:
//!
//! * a move that keeps one direction (from rest, from a cruise, from any
//!   state sampled off a jog, a move or a reversing jog at a random
//!   instant, with room to stop before the target), Ruckig given our
//!   bounds for that direction: `+acc`/`-dec` along the motion;
//! * a move that turns back (moving away, overshooting, braking too hard
//!   to go on) with `acc = dec`.
//!
//! A move that turns back with `acc ≠ dec` brakes at `dec` and speeds up
//! at `acc` on either side of zero speed — bounds that change with the
//! direction of motion, which Ruckig's fixed signed bounds cannot say. It
//! is compared with Ruckig at `±max(acc, dec)`, a lower bound that is not
//! tight: printed, only `≥` asserted.
//!
//! Also measured here: whether planning allocates, ours and Ruckig's
//! (a counting allocator around each call).

use motion_homing::profile::{reaches, Kinematics, Profile, Ramp};
use rsruckig::prelude::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Allocations made by this thread (the tests run on threads of their
    /// own: one does not count the other's).
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|n| n.set(n.get() + 1));
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static A: Counting = Counting;

/// Allocations made by `f`.
fn allocations<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let before = ALLOCS.with(Cell::get);
    let r = f();
    (r, ALLOCS.with(Cell::get) - before)
}

/// xorshift64: the cases are the same on every run.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(self.range(lo.log10(), hi.log10()))
    }
}

#[derive(Clone, Copy, Debug)]
struct Case {
    from: Kinematics,
    target: f64,
    vmax: f64,
    acc: f64,
    dec: f64,
    jerk: f64,
}

/// Limits as in `scurve_properties.rs`: the cap 0.5–50 units/s, reached
/// in 5 ms–0.5 s, the acceleration reached in 0.5 ms–0.5 s.
fn limits(r: &mut Rng, same: bool) -> (f64, f64, f64, f64) {
    let vmax = r.log(0.5, 50.0);
    let acc = vmax * r.log(2.0, 200.0);
    let dec = if same { acc } else { vmax * r.log(2.0, 200.0) };
    (vmax, acc, dec, acc.max(dec) * r.log(2.0, 2000.0))
}

/// A state off one of our own plans (so within the limits): a jog or a
/// move from rest, or a jog reversing another, sampled at a random instant
/// of it.
fn sampled_state(r: &mut Rng, vmax: f64, ramp: Ramp) -> Kinematics {
    let at = |r: &mut Rng, p: &Profile| (p.duration_ns() as f64 * r.range(0.0, 1.1)) as u64;
    let rest = Kinematics::rest(0.0);
    let plan = match (r.unit() * 3.0) as u32 {
        0 => Profile::jog_from(0, rest, r.range(-1.0, 1.0) * vmax, ramp),
        1 => Profile::move_from(0, rest, r.range(-1.0, 1.0) * vmax, vmax, ramp),
        _ => {
            let w = r.range(-1.0, 1.0) * vmax;
            let first = Profile::jog_from(0, rest, w, ramp);
            let t = at(r, &first);
            let back = -w.signum() * r.range(0.0, 1.0) * vmax;
            Profile::jog_from(t, first.state(t), back, ramp)
        }
    };
    plan.state(at(r, &plan))
}

/// Ruckig's bounds on the acceleration: `(max, min)`.
#[derive(Clone, Copy)]
enum Bounds {
    /// Ours for a motion in direction `s` that never turns: speeding up in
    /// `s` at `acc`, braking at `dec`.
    Along(f64),
    /// `±max(acc, dec)`: looser than ours whichever way it moves.
    Loose,
}

/// Ruckig's duration, with the speed cap scaled by `relax`, and the
/// allocations its `calculate` made.
fn ruckig(otg: &mut Ruckig<1, ThrowErrorHandler>, c: &Case, b: Bounds, relax: f64) -> (f64, usize) {
    ruckig_to(otg, c, b, relax, None)
}

/// As [`ruckig`]; with `Some(w)`, Ruckig's velocity interface to
/// velocity `w` (a jog) instead of the position `c.target`.
fn ruckig_to(
    otg: &mut Ruckig<1, ThrowErrorHandler>,
    c: &Case,
    b: Bounds,
    relax: f64,
    velocity: Option<f64>,
) -> (f64, usize) {
    let mut input = InputParameter::new(None);
    if let Some(w) = velocity {
        input.control_interface = ControlInterface::Velocity;
        input.target_velocity[0] = w;
    }
    input.current_position[0] = c.from.p;
    input.current_velocity[0] = c.from.v;
    input.current_acceleration[0] = c.from.a;
    input.target_position[0] = c.target;
    input.max_velocity[0] = c.vmax * relax;
    input.max_jerk[0] = c.jerk;
    let (max, min) = match b {
        Bounds::Along(s) if s > 0.0 => (c.acc, -c.dec),
        Bounds::Along(_) => (c.dec, -c.acc),
        Bounds::Loose => (c.acc.max(c.dec), -c.acc.max(c.dec)),
    };
    input.max_acceleration[0] = max;
    input.min_acceleration = Some(daov_stack![min]);
    let mut traj = Trajectory::new(None);
    let (r, n) = allocations(|| otg.calculate(&input, &mut traj));
    r.expect("ruckig plans it");
    (traj.get_duration(), n)
}

fn ours(c: &Case) -> f64 {
    let ramp = Ramp {
        accel: c.acc,
        decel: c.dec,
        jerk: c.jerk,
    };
    let p = Profile::move_from(0, c.from, c.target, c.vmax, ramp);
    p.duration_ns() as f64 * 1e-9
}

/// Duration ratios ours / Ruckig's of one kind of case, and how many
/// were the same duration.
#[derive(Default)]
struct Kind {
    ratios: Vec<f64>,
    same: usize,
}

impl Kind {
    fn add(&mut self, ours: f64, theirs: f64) {
        self.ratios.push(ours / theirs);
        self.same += usize::from((ours - theirs).abs() <= theirs * ROUNDING + NS);
    }

    /// Prints the distribution; true if every case was the same.
    fn report(&mut self, name: &str) -> bool {
        let r = &mut self.ratios;
        r.sort_by(f64::total_cmp);
        let q = |f: f64| r[((r.len() - 1) as f64 * f).round() as usize];
        eprintln!(
            "{name:<52} n {:>5}  min {:.6}  median {:.6}  p90 {:.6}  p99 {:.6}  max {:.6}  same {:>5.1} %",
            r.len(),
            q(0.0),
            q(0.5),
            q(0.9),
            q(0.99),
            q(1.0),
            100.0 * self.same as f64 / r.len() as f64
        );
        self.same == r.len()
    }
}

/// Tolerances of a comparison: relative, and our duration's rounding up
/// to whole ns.
const ROUNDING: f64 = 1e-6;
const NS: f64 = 2e-9;

#[test]
fn moves_against_ruckig() {
    assert_eq!(allocations(|| vec![1u8]).1, 1, "the counter counts");
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
    let mut rng = Rng(0x5eed_cafe_f00d_0001);
    let mut kinds: [Kind; 4] = Default::default();
    let (mut our_allocs, mut their_allocs, mut plans, mut ruckig_missed) = (0, 0, 0, 0);
    for i in 0..6000 {
        let (vmax, acc, dec, jerk) = limits(&mut rng, i % 2 == 0);
        let ramp = Ramp {
            accel: acc,
            decel: dec,
            jerk,
        };
        let from = match i % 6 {
            0 | 1 => Kinematics::rest(0.0),
            2 | 3 => Kinematics::moving(0.0, rng.range(-1.0, 1.0) * vmax),
            _ => sampled_state(&mut rng, vmax, ramp),
        };
        let target = from.p + rng.range(-1.5, 1.5) * vmax;
        let c = Case {
            from,
            target,
            vmax,
            acc,
            dec,
            jerk,
        };
        let one_way = reaches(from, target, dec, jerk);
        let bounds = if one_way {
            Bounds::Along((target - from.p).signum())
        } else {
            Bounds::Loose
        };
        let (t_ours, n_ours) = allocations(|| ours(&c));
        let (exact, n_theirs) = ruckig(&mut otg, &c, bounds, 1.0);
        // A start on the cap (sampled off a jog at the cap) can make
        // Ruckig miss its optimum: the same with the cap 1e-9 higher (a
        // relaxation, so still a lower bound) finds it.
        let (relaxed, _) = ruckig(&mut otg, &c, bounds, 1.0 + 1e-9);
        if exact > relaxed * (1.0 + ROUNDING) {
            ruckig_missed += 1;
        }
        let t_theirs = exact.min(relaxed);
        our_allocs += n_ours;
        their_allocs += n_theirs;
        plans += 1;
        assert!(
            t_ours >= t_theirs * (1.0 - ROUNDING) - NS,
            "shorter than the optimum: {t_ours} < {t_theirs}: {c:?}"
        );
        kinds[usize::from(!one_way) * 2 + usize::from(acc != dec)].add(t_ours, t_theirs);
    }
    eprintln!("duration ours / Ruckig's, 6000 random moves:");
    let names = [
        "one way (rest, cruise, a state with room), acc = dec",
        "one way, acc != dec (Ruckig's signed bounds = ours)",
        "turning back (moving away, overshooting), acc = dec",
        "turning back, acc != dec: Ruckig at ±max(acc, dec)",
    ];
    let same: Vec<bool> = kinds
        .iter_mut()
        .zip(names)
        .map(|(k, n)| k.report(n))
        .collect();
    eprintln!(
        "allocations in {plans} plans: ours {our_allocs}, Ruckig's calculate {their_allocs} \
         (Ruckig::new, InputParameter::new and Trajectory::new are not counted); Ruckig's plan \
         at the exact cap missed its optimum in {ruckig_missed} cases"
    );
    assert_eq!(our_allocs, 0, "our planning allocates");
    // Time-optimal wherever the constraints are the same as Ruckig's.
    for k in [0, 1, 2] {
        assert!(same[k], "{}: not all the same", names[k]);
    }
}

/// The jog (a velocity change and a cruise) against Ruckig's velocity
/// interface: the time to reach the jog's velocity at zero acceleration,
/// from states sampled off our plans. The same (1e-6) wherever both are
/// bound alike: a change that keeps one direction, and one that turns
/// with `acc = dec`.
#[test]
fn jogs_against_ruckig() {
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
    let mut rng = Rng(0x5eed_cafe_f00d_0002);
    let mut kinds: [Kind; 4] = Default::default();
    for i in 0..4000 {
        let (vmax, acc, dec, jerk) = limits(&mut rng, i % 2 == 0);
        let ramp = Ramp {
            accel: acc,
            decel: dec,
            jerk,
        };
        let from = if i % 4 == 0 {
            Kinematics::rest(0.0)
        } else {
            sampled_state(&mut rng, vmax, ramp)
        };
        let w = rng.range(-1.0, 1.0) * vmax;
        let c = Case {
            from,
            target: 0.0,
            vmax,
            acc,
            dec,
            jerk,
        };
        let v_r = from.v + from.a * from.a.abs() / (2.0 * jerk);
        let one_way = from.v * w >= 0.0 && v_r * w >= 0.0;
        let bounds = if one_way {
            Bounds::Along(w.signum())
        } else {
            Bounds::Loose
        };
        let jog = Profile::jog_from(0, from, w, ramp);
        let t_ours = jog.duration_ns() as f64 * 1e-9;
        let (t_theirs, _) = ruckig_to(&mut otg, &c, bounds, 1.0, Some(w));
        assert!(
            t_ours >= t_theirs * (1.0 - ROUNDING) - NS,
            "shorter than the optimum: {t_ours} < {t_theirs}: {c:?} to {w}"
        );
        kinds[usize::from(!one_way) * 2 + usize::from(acc != dec)].add(t_ours, t_theirs);
    }
    eprintln!("jog: time to its velocity, ours / Ruckig's, 4000 random jogs:");
    let names = [
        "one way (rest or any state), acc = dec",
        "one way, acc != dec (Ruckig's signed bounds = ours)",
        "turning (against the motion), acc = dec",
        "turning, acc != dec: Ruckig at ±max(acc, dec)",
    ];
    let same: Vec<bool> = kinds
        .iter_mut()
        .zip(names)
        .map(|(k, n)| k.report(n))
        .collect();
    for k in [0, 1, 2] {
        assert!(same[k], "{}: not all the same", names[k]);
    }
}
