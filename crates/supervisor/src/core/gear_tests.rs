//! Gearing where it crosses axes, through frames and plants: the slave
//! follows its master's command of the same cycle (whichever comes first
//! in the configuration), an operator's stop of the master ends it, a
//! slave at its travel limit stops its master, a master's fault stops the
//! slave, and the rules only the cycle sees (self, chains).

use super::testbench::Bench;
use crate::shared::{AxisAck, Refusal};
use motion_homing::codes::*;
use motion_homing::{GearSpec, JogSpec, MoveSpec, Operation};

/// Axes of these names (config order), immediate homing at 0, max_speed
/// 50, travel limits ±10, max_deceleration 100.
fn machine(names: &[&str]) -> String {
    let mut t = String::from("[supervisor]\ncycle_us = 1000\ncpu = 0\n");
    for n in names {
        t += &format!(
            "\n[[axis]]\nname = \"{n}\"\ncounts_per_unit = 1000.0\nhome_sequence = \"immediate\"\n\
             home_speed = 10.0\nhome_acceleration = 100.0\nhome_deceleration = 100.0\n\
             max_speed = 50.0\ntravel_limits = [-10.0, 10.0]\n"
        );
    }
    t
}

fn two(a: &str, b: &str) -> String {
    machine(&[a, b])
}

/// Both axes homed and enabled, at rest at 0.
fn ready(toml: &str) -> Bench {
    let mut b = Bench::new(toml);
    b.run(5);
    b.home(0b11, true);
    b.run(5);
    b.op(0b11, Operation::Enable, 0);
    b.run(20);
    for a in b.snap().axes[..2].iter() {
        assert!(a.status.homed && a.status.servo_action, "{:?}", a.status);
    }
    b
}

fn jog(speed: f64) -> Operation {
    Operation::Jog(JogSpec {
        speed,
        lease: Some(5.0),
        accel: Some(100.0),
        decel: Some(100.0),
        jerk: None,
    })
}

/// Gear axis `slave` to `master` at `ratio`: the answer for the slave.
fn gear(b: &mut Bench, slave: usize, master: u16, ratio: f64) -> AxisAck {
    b.op(1 << slave, Operation::Gear(GearSpec::to(master, ratio)), 0);
    b.cycle();
    b.acks.pop().unwrap().axes[slave]
}

#[test]
fn the_slave_follows_its_masters_command_of_the_same_cycle_in_either_order() {
    // M first and S second, then S first: no cycle of lag either way.
    for (toml, m, s) in [(two("M", "S"), 0, 1), (two("S", "M"), 1, 0)] {
        let mut b = ready(&toml);
        assert_eq!(gear(&mut b, s, m as u16, -2.0), AxisAck::Accepted);
        let at = b.snap();
        let (m0, s0) = (at.axes[m].cmd_position, at.axes[s].cmd_position);
        b.op(1 << m, jog(2.0), 7);
        for _ in 0..300 {
            b.cycle();
            let snap = b.snap();
            let (mc, sc) = (snap.axes[m].cmd_position, snap.axes[s].cmd_position);
            assert!((sc - s0 + 2.0 * (mc - m0)).abs() < 1e-9, "{mc} {sc}");
            assert!(snap.axes[s].status.gearing);
        }
        assert!(b.snap().axes[m].cmd_position > 0.4);
        assert!(b.core.in_gearing(m) && b.core.in_gearing(s));
    }
}

#[test]
fn an_operators_stop_of_the_master_ends_the_gearing() {
    let mut b = ready(&two("M", "S"));
    gear(&mut b, 1, 0, 1.0);
    b.op(1, jog(2.0), 7);
    b.run(100);
    b.ask(5, crate::shared::Ask::Stop { mask: 1 });
    b.run(1);
    let s = b.snap().axes[1].status;
    assert!(!s.gearing && !s.er, "{s:?}");
    b.run(100);
    let s = b.snap().axes[1].status;
    assert!(!s.gearing && !s.er && s.op.pc, "{s:?}");
    assert!(!b.core.in_gearing(0) && !b.core.in_gearing(1));
}

#[test]
fn a_slave_at_its_travel_limit_stops_inside_it_and_stops_its_master() {
    // Ratio 4: the master at 5 u/s drives the slave at 20 towards +10.
    let mut b = ready(&two("M", "S"));
    gear(&mut b, 1, 0, 4.0);
    b.op(1, jog(5.0), 7);
    let mut most: f64 = 0.0;
    for _ in 0..2000 {
        b.cycle();
        most = most.max(b.snap().axes[1].cmd_position);
    }
    let snap = b.snap();
    let (m, s) = (snap.axes[0].status, snap.axes[1].status);
    assert_eq!((s.err, s.exerr), (ERR_GEARING, EX_GEAR_SOFT_LIMIT), "{s:?}");
    assert!(s.faulted && !s.gearing);
    assert!(most <= 10.0 + 0.0005, "{most}");
    // The master was stopped (normally) and stands.
    assert!(!m.jogging && !m.er && !m.stopping, "{m:?}");
    assert!(
        snap.axes[0].cmd_position < 2.6,
        "{}",
        snap.axes[0].cmd_position
    );
}

#[test]
fn a_masters_fault_stops_the_slave() {
    let mut b = ready(&two("M", "S"));
    gear(&mut b, 1, 0, 1.0);
    b.op(1, jog(2.0), 7);
    b.run(100);
    b.plants[0].inject_fault();
    b.run(5);
    let s = b.snap().axes[1].status;
    assert_eq!(
        (s.err, s.exerr),
        (ERR_GEARING, EX_GEAR_MASTER_FAULTED),
        "{s:?}"
    );
    assert!(!s.gearing);
}

#[test]
fn a_gear_to_itself_or_in_a_chain_is_refused() {
    let mut b = ready(&machine(&["A", "B", "C"]));
    b.op(0b100, Operation::Enable, 0);
    b.run(20);
    let refused = |exerr| {
        AxisAck::Refused(Refusal::Operation {
            err: ERR_GEARING,
            exerr,
        })
    };
    assert_eq!(gear(&mut b, 1, 1, 1.0), refused(EX_GEAR_SELF));
    assert_eq!(gear(&mut b, 1, 0, 1.0), AxisAck::Accepted);
    // C to B (a geared master), A to C (A is a master).
    assert_eq!(gear(&mut b, 2, 1, 1.0), refused(EX_GEAR_CHAINED));
    assert_eq!(gear(&mut b, 0, 2, 1.0), refused(EX_GEAR_CHAINED));
    assert_eq!(gear(&mut b, 2, 0, 1.0), AxisAck::Accepted);
}

#[test]
fn a_geared_axis_master_or_slave_is_not_redefined_until_the_gear_ends() {
    // M at rest, S geared to it: redefining either would move what the
    // gear follows. Refused on both (1023 / 3) by the cycle, which sees
    // both ends of the gear (the slave's engine refuses it too, were it
    // asked); once the gear ends, it is accepted.
    let mut b = ready(&two("M", "S"));
    assert_eq!(gear(&mut b, 1, 0, 2.0), AxisAck::Accepted);
    b.run(5);
    let geared = (ERR_REDEFINE_REFUSED, EX_REDEFINE_GEARED);
    b.op(
        1,
        Operation::Redefine(motion_homing::RedefineSpec::by(1.0)),
        0,
    );
    b.cycle();
    assert_eq!(
        b.acks.pop().unwrap().axes[0],
        AxisAck::Refused(Refusal::Operation {
            err: geared.0,
            exerr: geared.1
        })
    );
    b.op(
        0b10,
        Operation::Redefine(motion_homing::RedefineSpec::by(1.0)),
        0,
    );
    b.cycle();
    assert_eq!(
        b.acks.pop().unwrap().axes[1],
        AxisAck::Refused(Refusal::Operation {
            err: geared.0,
            exerr: geared.1
        })
    );
    assert!(b.snap().axes[1].status.gearing);
    b.op(0b10, Operation::Stop, 0);
    b.run(50);
    assert!(!b.core.in_gearing(0) && !b.core.in_gearing(1));
    let before = b.snap().axes[0].cmd_position;
    b.op(
        1,
        Operation::Redefine(motion_homing::RedefineSpec::by(1.0)),
        0,
    );
    b.run(2);
    let m = b.snap().axes[0];
    assert!(m.status.op.refused.is_none(), "{:?}", m.status);
    assert!((m.cmd_position - before).abs() < 1e-12, "no motion");
}

/// Gantry G (A, B: switch homing) and S (±10), S to be geared to side A.
fn gantry_and_slave() -> String {
    let mut t = String::from("[supervisor]\ncycle_us = 1000\ncpu = 0\n");
    for n in ["A", "B"] {
        t += &format!(
            "\n[[axis]]\nname = \"{n}\"\ncounts_per_unit = 1000.0\nhome_sequence = \"switch\"\n\
             home_speed = 20.0\nhome_return_speed = 2.0\nhome_acceleration = 500.0\n\
             home_deceleration = 500.0\nmax_speed = 50.0\ntravel_limits = [-100.0, 100.0]\n\
             [axis.sim]\nstart = -10.0\nswitch = [0.0, 5.0]\n"
        );
    }
    t += "\n[[axis]]\nname = \"S\"\ncounts_per_unit = 1000.0\nhome_sequence = \"immediate\"\n\
          home_speed = 10.0\nhome_acceleration = 100.0\nhome_deceleration = 100.0\n\
          max_speed = 50.0\ntravel_limits = [-10.0, 10.0]\n\
          \n[[gantry]]\nname = \"G\"\naxes = [\"A\", \"B\"]\nmax_skew = 0.5\n";
    t
}

#[test]
fn a_slave_that_faults_stops_every_side_of_its_gantry_master() {
    // S geared ×4 to side A while G moves to 50 at 5 u/s: S reaches its
    // travel limit (1025 / 1) and its master stops — both sides of the
    // gantry, together (before: A alone stopped and B moved on until the
    // cycle monitor tripped on the skew). The bench fails on any trip.
    let mut b = Bench::new(&gantry_and_slave());
    b.run(5);
    b.home(0b111, true);
    b.run(4000);
    b.op(0b111, Operation::Enable, 0);
    b.run(20);
    assert_eq!(gear(&mut b, 2, 0, 4.0), AxisAck::Accepted);
    let to_50 = MoveSpec {
        target: 50.0,
        relative: false,
        speed: Some(5.0),
        accel: Some(100.0),
        decel: Some(100.0),
        supersede: false,
        jerk: None,
    };
    b.op(0b011, Operation::Move(to_50), 0);
    let mut skew: f64 = 0.0;
    for _ in 0..3000 {
        b.cycle();
        let s = b.snap();
        skew = skew.max((s.axes[0].cmd_position - s.axes[1].cmd_position).abs());
    }
    let s = b.snap();
    assert_eq!(
        (s.axes[2].status.err, s.axes[2].status.exerr),
        (ERR_GEARING, EX_GEAR_SOFT_LIMIT)
    );
    for side in &s.axes[..2] {
        assert!(!side.status.moving && side.cmd_position < 5.0, "{side:?}");
    }
    assert!(skew < 1e-6, "racked {skew}");
}

#[test]
fn an_unhomed_geared_slave_slows_to_its_cap_without_a_trip() {
    // S follows M at 40 u/s; unhomed, its cap drops to unhomed_speed 10:
    // the follower slows at stream_acceleration (200), and the monitor's
    // bound decays no faster (the bench fails on any trip; before, the
    // monitor tripped at 37.2 against 37.0). Held to 10 while its master
    // runs at 40, the slave falls behind beyond catching up: the gear ends
    // with its own error (1025 / 2).
    let toml = machine(&["M", "S"]).replace(
        "max_speed = 50.0\n",
        "max_speed = 50.0\nunhomed_speed = 10.0\nmax_deceleration = 1000.0\n\
         stream_acceleration = 200.0\n",
    );
    let toml = toml.replace(
        "travel_limits = [-10.0, 10.0]",
        "travel_limits = [-1000.0, 1000.0]",
    );
    let mut b = ready(&toml);
    assert_eq!(gear(&mut b, 1, 0, 1.0), AxisAck::Accepted);
    b.op(1, jog(40.0), 7);
    b.run(1000);
    assert!(b.snap().axes[1].cmd_velocity > 39.0);
    b.ask(9, crate::shared::Ask::Unhome { mask: 0b10 });
    b.run(500);
    let s = b.snap().axes[1];
    assert_eq!(
        (s.status.err, s.status.exerr),
        (ERR_GEARING, 2),
        "{:?}",
        s.status
    );
    assert!(!s.status.gearing && b.core.axes()[1].trip().is_none());
    assert!(s.cmd_velocity.abs() <= 10.0 + 1e-9, "{}", s.cmd_velocity);
}
