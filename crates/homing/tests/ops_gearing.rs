//! MAG against the plant: a master and a slave, each an engine with its own
//! plant, stepped as the cycle does (the master first, then the slave with
//! the master's news of that step). Ratio of either sign, commanded and
//! actual position, the clutch's ramp and what it does not make up, the
//! speed cap and acceleration bounds, the slave's travel limit, and every
//! end: a stop or disable of either axis, a fault of either.

mod common;

use common::*;
use motion_homing::codes::*;
use motion_homing::*;

const CYCLE_S: f64 = 0.001;
const MASTER: u16 = 0;

/// A master and a slave, both enabled and homed at 0 (`op_axis()` unless
/// given).
struct Pair {
    m: Rig,
    s: Rig,
    /// The master was stopped (or disabled) in this step.
    stopped: bool,
    /// Hand the slave the master's news (the cycle does while it is geared).
    feed: bool,
    /// The master's actual position after each step (NaN: none).
    m_actual: Vec<f64>,
}

impl Pair {
    fn new(slave: AxisConfig) -> Self {
        let mut s = Rig::new(slave, op_plant(0.0));
        s.enable_and_home();
        Self::with(s)
    }

    /// A master enabled and homed at 0, and slave `s`.
    fn with(mut s: Rig) -> Self {
        let mut m = Rig::at(0.0);
        m.enable_and_home();
        // Both rigs on one clock.
        let k = m.k.max(s.k);
        m.k = k;
        s.k = k;
        Pair {
            m,
            s,
            stopped: false,
            feed: true,
            m_actual: vec![f64::NAN; k as usize],
        }
    }

    fn standard() -> Self {
        Self::new(op_axis())
    }

    /// What the cycle hands the slave of the master after the master's step.
    fn master_feed(&self) -> MasterFeed {
        MasterFeed {
            commanded: self.m.axis.last_command().position,
            actual: self.m.axis.raw_position(),
            accel: self.m.axis.acceleration_bound(),
            stopped: self.stopped,
            faulted: self.m.axis.status().faulted,
        }
    }

    /// One cycle: the master with `mreq`, then the slave with `sreq` and
    /// the master's news.
    fn step(&mut self, mreq: Request, mut sreq: Request) {
        self.m.step(mreq);
        (self.m_actual).push(self.m.axis.raw_position().unwrap_or(f64::NAN));
        if self.feed {
            sreq.master = Some(self.master_feed());
        }
        self.s.step(sreq);
        self.stopped = false;
    }

    fn run(&mut self, n: u64) {
        for _ in 0..n {
            self.step(Request::default(), Request::default());
        }
    }

    /// One cycle with `op` for the master.
    fn master_op(&mut self, op: Operation) {
        let before = self.m.axis.status().op.id;
        self.stopped = matches!(op, Operation::Stop | Operation::Disable);
        self.step(
            Request {
                op: Some(op),
                ..Request::default()
            },
            Request::default(),
        );
        assert_ne!(self.m.axis.status().op.id, before, "master refused {op:?}");
    }

    /// One cycle with `op` for the slave: accepted (its id) or refused.
    fn slave_op(&mut self, op: Operation) -> Result<u32, (u16, u16)> {
        let before = self.s.axis.status().op.id;
        self.step(
            Request::default(),
            Request {
                op: Some(op),
                ..Request::default()
            },
        );
        let st = self.s.axis.status().op;
        if st.id != before {
            Ok(st.id)
        } else {
            Err(st.refused.expect("neither accepted nor refused"))
        }
    }

    fn gear(&mut self, spec: GearSpec) -> Result<u32, (u16, u16)> {
        self.slave_op(Operation::Gear(spec))
    }

    /// Step index of the next step.
    fn k(&self) -> usize {
        self.m.cmds.len()
    }
}

/// `n` cycles of the master's jog renewed.
fn renew(p: &mut Pair, n: u64) {
    for _ in 0..n {
        p.step(
            Request {
                jog_renew: true,
                ..Request::default()
            },
            Request::default(),
        );
    }
}

/// As [`renew`], until the slave shows ER (at most `n` cycles).
fn renew_until_er(p: &mut Pair, n: u64) {
    for _ in 0..n {
        renew(p, 1);
        if p.s.axis.status().er {
            break;
        }
    }
}

/// A master jog at `speed` for `n` cycles, renewed.
fn jog_master(p: &mut Pair, speed: f64, n: u64) {
    p.master_op(jog(speed));
    renew(p, n);
}

fn gear_spec(ratio: f64) -> GearSpec {
    GearSpec::to(MASTER, ratio)
}

/// Every slave command from step `from` (the gear's) is `ratio` × the
/// master's change of `master_pos` since that step, from where the slave
/// stood.
fn follows_exactly(p: &Pair, from: usize, ratio: f64, master_pos: &[f64]) {
    let s0 = p.s.cmds[from].position;
    let m0 = master_pos[from];
    assert_eq!(p.s.cmds.len(), master_pos.len());
    for (k, (c, m)) in p.s.cmds.iter().zip(master_pos).enumerate().skip(from) {
        let want = s0 + ratio * (m - m0);
        let got = c.position;
        assert!((got - want).abs() < 1e-9, "step {k}: {got} vs {want}");
    }
}

fn master_cmds(p: &Pair) -> Vec<f64> {
    p.m.cmds.iter().map(|c| c.position).collect()
}

fn geared_fault(p: &Pair, exerr: u16) {
    let s = p.s.axis.status();
    assert_eq!((s.er, s.err, s.exerr), (true, ERR_GEARING, exerr), "{s:?}");
    assert!(s.faulted && !s.gearing, "{s:?}");
    assert_eq!(s.last_stop, StopCause::Gearing);
}

#[test]
fn a_positive_ratio_follows_the_masters_command_change_exactly() {
    let mut p = Pair::standard();
    let from = p.k();
    p.gear(gear_spec(2.0)).unwrap();
    assert!(p.s.axis.status().gearing && p.s.axis.status().op.ip);
    assert_eq!(p.s.axis.gear_master(), Some(MASTER));
    jog_master(&mut p, 2.0, 300);
    follows_exactly(&p, from, 2.0, &master_cmds(&p));
    // Moved: the master by about 0.55, the slave twice that.
    let dm = p.m.cmds.last().unwrap().position;
    assert!(dm > 0.5, "{dm}");
    assert!(p.s.axis.status().gearing);
    assert!((p.s.cmds.last().unwrap().velocity - 2.0 * 2.0).abs() < 1e-9);
}

#[test]
fn a_negative_ratio_runs_the_opposite_way() {
    let mut p = Pair::standard();
    let from = p.k();
    p.gear(gear_spec(-0.5)).unwrap();
    jog_master(&mut p, 4.0, 300);
    follows_exactly(&p, from, -0.5, &master_cmds(&p));
    assert!(p.s.cmds.last().unwrap().position < -0.5);
}

#[test]
fn with_actual_the_slave_follows_the_masters_actual_position() {
    let mut p = Pair::standard();
    let from = p.k();
    let mut spec = gear_spec(1.0);
    spec.actual = true;
    p.gear(spec).unwrap();
    jog_master(&mut p, 3.0, 200);
    follows_exactly(&p, from, 1.0, &p.m_actual);
    // The plant's actual position trails the command by a cycle: so does
    // the slave, which proves it followed the actual and not the command.
    let (m_cmd, s_cmd) = (
        p.m.cmds.last().unwrap().position,
        p.s.cmds.last().unwrap().position,
    );
    assert!(
        (m_cmd - s_cmd - 3.0 * CYCLE_S).abs() < 1e-9,
        "{m_cmd} {s_cmd}"
    );
}

#[test]
fn a_clutch_ramps_in_at_its_acceleration_and_does_not_make_up_the_lost_distance() {
    let mut p = Pair::standard();
    // The master runs at 5 u/s.
    jog_master(&mut p, 5.0, 50);
    let from = p.k();
    let mut spec = gear_spec(1.0);
    spec.clutch = Some(100.0);
    p.gear(spec).unwrap();
    renew(&mut p, 100);
    let cmds = p.s.since(from as u64);
    // At most 100 u/s² (the clutch), never faster than the master.
    assert!(max_accel(cmds, CYCLE_S) <= 100.0 * (1.0 + 1e-6) + 1e-6);
    // 5 u/s at 100 u/s²: 50 ms of ramp, locked after it at the master's
    // velocity, 0.125 behind (v²/2a), which stays behind.
    let gap = |k: usize| p.m.cmds[k].position - p.s.cmds[k].position;
    let end = p.k() - 1;
    let lost = gap(end);
    assert!((lost - gap(from) - 0.125).abs() < 0.01, "{lost}");
    for k in from + 60..=end {
        assert!((gap(k) - lost).abs() < 1e-9, "step {k}: {}", gap(k));
    }
    assert!(p.s.axis.status().gearing);
}

#[test]
fn without_a_clutch_a_running_master_is_caught_up_within_the_bounds() {
    // The slave's own acceleration bound is 800: it lags the geared path
    // at first and catches it up, never asking for more.
    let mut p = Pair::new(AxisConfig {
        stream_acceleration: 800.0,
        ..op_axis()
    });
    jog_master(&mut p, 5.0, 50);
    let from = p.k();
    p.gear(gear_spec(1.0)).unwrap();
    renew(&mut p, 200);
    let cmds = p.s.since(from as u64 - 1);
    assert!(max_accel(cmds, CYCLE_S) <= 800.0 * (1.0 + 1e-6) + 1e-6);
    // Locked where both stood: caught up with the geared position.
    let end = p.k() - 1;
    // From where both stood in the step the gear was accepted.
    let geared = p.s.cmds[from].position + (p.m.cmds[end].position - p.m.cmds[from].position);
    assert!((p.s.cmds[end].position - geared).abs() < 1e-9);
}

#[test]
fn a_master_faster_than_the_slaves_cap_stops_the_slave_with_1025_2() {
    // Ratio 10, master at 8: 80 u/s against the slave's max_speed 50.
    let mut p = Pair::standard();
    let from = p.k();
    p.gear(gear_spec(10.0)).unwrap();
    p.master_op(jog(8.0));
    renew_until_er(&mut p, 400);
    geared_fault(&p, EX_GEAR_CANNOT_FOLLOW);
    assert!(max_speed(p.s.since(from as u64), CYCLE_S) <= 50.0 * (1.0 + 1e-9));
}

#[test]
fn the_slave_at_its_travel_limit_stops_inside_it_with_1025_1() {
    // Limits ±10; ratio 4: the master at 6 u/s drives the slave at 24.
    let mut p = Pair::standard();
    let from = p.k();
    p.gear(gear_spec(4.0)).unwrap();
    p.master_op(jog(6.0));
    renew_until_er(&mut p, 1000);
    geared_fault(&p, EX_GEAR_SOFT_LIMIT);
    for _ in 0..200 {
        p.s.step(Request::default());
    }
    let cmds = p.s.since(from as u64);
    let most = cmds.iter().map(|c| c.position).fold(f64::MIN, f64::max);
    assert!(most <= 10.0 + 0.0005, "{most}");
    assert!(most > 9.0, "stopped early: {most}");
    // Never harder than max_deceleration (500) braking, never faster than the cap.
    assert!(max_speed(cmds, CYCLE_S) <= 50.0 * (1.0 + 1e-9));
    assert!(max_accel(cmds, CYCLE_S) <= 2000.0 + 1e-6);
    assert_eq!(p.s.cmds.last().unwrap().velocity, 0.0);
}

#[test]
fn a_stop_or_disable_of_the_slave_ends_the_gearing_normally() {
    for op in [Operation::Stop, Operation::Disable] {
        let mut p = Pair::standard();
        p.gear(gear_spec(1.0)).unwrap();
        jog_master(&mut p, 3.0, 100);
        let id = p.slave_op(op).unwrap();
        let s = *p.s.axis.status();
        assert!(!s.gearing && !s.er, "{op:?}: {s:?}");
        renew(&mut p, 100);
        let s = p.s.axis.status();
        assert!(
            !s.gearing && !s.er && s.op.id == id && s.op.pc,
            "{op:?}: {s:?}"
        );
        assert_eq!(p.s.cmds.last().unwrap().velocity, 0.0);
        // The master runs on.
        assert!(p.m.axis.status().jogging);
    }
}

#[test]
fn a_stop_or_disable_of_the_master_ends_the_gearing_normally() {
    for op in [Operation::Stop, Operation::Disable] {
        let mut p = Pair::standard();
        let id = p.gear(gear_spec(1.0)).unwrap();
        jog_master(&mut p, 3.0, 100);
        p.master_op(op);
        let s = *p.s.axis.status();
        assert!(!s.gearing && !s.er && s.stopping, "{op:?}: {s:?}");
        p.run(100);
        let s = p.s.axis.status();
        assert!(
            !s.gearing && !s.er && s.op.id == id && s.op.pc,
            "{op:?}: {s:?}"
        );
    }
}

#[test]
fn a_fault_of_the_master_stops_the_slave_with_1025_3() {
    let mut p = Pair::standard();
    p.gear(gear_spec(1.0)).unwrap();
    jog_master(&mut p, 3.0, 100);
    p.m.plant.inject_fault();
    for _ in 0..5 {
        p.run(1);
        if p.s.axis.status().er {
            break;
        }
    }
    assert!(p.m.axis.status().faulted);
    geared_fault(&p, EX_GEAR_MASTER_FAULTED);
}

#[test]
fn a_fault_of_the_slave_ends_the_gearing() {
    let mut p = Pair::standard();
    p.gear(gear_spec(1.0)).unwrap();
    jog_master(&mut p, 3.0, 100);
    p.s.plant.inject_fault();
    p.run(3);
    let s = p.s.axis.status();
    assert!(
        s.faulted && !s.gearing && s.err == ERR_SERVO_MESSAGE,
        "{s:?}"
    );
    assert_eq!(p.s.axis.gear_master(), None);
}

#[test]
fn the_slave_refuses_what_it_cannot_do() {
    let refused = |mut p: Pair, spec: GearSpec, code: (u16, u16)| {
        let before = p.s.axis.status().gearing;
        assert_eq!(p.gear(spec), Err(code), "{spec:?}");
        assert_eq!(p.s.axis.status().gearing, before);
    };
    for ratio in [0.0, f64::NAN, f64::INFINITY] {
        refused(
            Pair::standard(),
            gear_spec(ratio),
            (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_RATIO),
        );
    }
    let mut clutch = gear_spec(1.0);
    clutch.clutch = Some(-1.0);
    refused(
        Pair::standard(),
        clutch,
        (ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_ACCELERATION),
    );
    // The cycle has nothing of the master.
    let mut p = Pair::standard();
    p.feed = false;
    refused(p, gear_spec(1.0), (ERR_GEARING, EX_GEAR_MASTER_UNAVAILABLE));
    // Already moving (jogging), already geared.
    let mut p = Pair::standard();
    p.s.step(Request {
        op: Some(jog(2.0)),
        ..Request::default()
    });
    refused(p, gear_spec(1.0), (ERR_EXECUTION_COLLISION, 0));
    let mut p = Pair::standard();
    p.gear(gear_spec(1.0)).unwrap();
    refused(p, gear_spec(1.0), (ERR_EXECUTION_COLLISION, 0));
    // Faulted master, faulted slave.
    let mut p = Pair::standard();
    p.m.plant.inject_fault();
    p.run(3);
    assert!(p.m.axis.status().faulted);
    refused(p, gear_spec(1.0), (ERR_GEARING, EX_GEAR_MASTER_FAULTED));
    let mut p = Pair::standard();
    p.s.plant.inject_fault();
    p.run(3);
    refused(p, gear_spec(1.0), (ERR_AXIS_FAULTED, 0));
    // Servo off.
    let mut p = Pair::standard();
    p.slave_op(Operation::Disable).unwrap();
    p.run(5);
    refused(p, gear_spec(1.0), (ERR_SERVO_OFF, 0));
    // Homing in process (a sequence that moves).
    let mut s = Rig::new(
        AxisConfig {
            home_sequence: HomeSequence::Switch,
            home_return_speed: 2.0,
            ..op_axis()
        },
        op_plant(0.0),
    );
    s.enable();
    let mut p = Pair::with(s);
    p.s.step(home());
    assert!(p.s.axis.status().ip);
    refused(p, gear_spec(1.0), (ERR_HOME_IN_PROCESS, 0));
}

#[test]
fn a_gear_on_actual_needs_the_masters_actual_position() {
    let mut p = Pair::standard();
    let mut spec = gear_spec(1.0);
    spec.actual = true;
    p.m.frame = |_, _| None;
    // The master's feedback stays away long enough to be lost.
    p.run(200);
    assert!(p.m.axis.raw_position().is_none());
    assert_eq!(p.gear(spec), Err((ERR_GEARING, EX_GEAR_MASTER_UNAVAILABLE)));
}

#[test]
fn an_unhomed_slave_gears_at_its_unhomed_speed() {
    // Not homed: the cap is unhomed_speed (home_speed 20); ratio 5 with the
    // master at 5 asks 25 u/s: refused on the way (1025 / 2), never past 20.
    let mut s = Rig::at(0.0);
    s.enable();
    let mut p = Pair::with(s);
    assert!(!p.s.axis.status().homed);
    let from = p.k();
    p.gear(gear_spec(5.0)).unwrap();
    jog_master(&mut p, 3.0, 100);
    assert!(p.s.axis.status().gearing, "15 u/s is under the cap");
    p.master_op(jog(5.0));
    renew(&mut p, 300);
    geared_fault(&p, EX_GEAR_CANNOT_FOLLOW);
    assert!(max_speed(p.s.since(from as u64), CYCLE_S) <= 20.0 * (1.0 + 1e-9));
}

#[test]
fn home_is_refused_on_a_geared_slave() {
    let mut p = Pair::standard();
    p.gear(gear_spec(1.0)).unwrap();
    // Home on the slave while geared: refused (execution collision).
    p.step(Request::default(), home());
    let s = p.s.axis.status();
    assert!(
        s.er && s.err == ERR_EXECUTION_COLLISION && s.gearing,
        "{s:?}"
    );
}
