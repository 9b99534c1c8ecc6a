//! Property tests of the plant: crossing rules, latch exactness, totality.

use motion_homing::{Command, Edge, Feedback, LatchArm};
use motion_plant::{
    feedback_numbers, Markers, Plant, PlantConfig, RegistrationInput, Switch, TorqueSpike,
};
use proptest::prelude::*;

fn assert_finite(fb: &Feedback) -> Result<(), TestCaseError> {
    let numbers = feedback_numbers(fb);
    prop_assert!(numbers.iter().all(|v| v.is_finite()), "{:?}", fb);
    Ok(())
}

/// Drive an enabled plant through `points` (the first is where it starts),
/// arming a fresh marker capture every step; returns every marker latched.
fn latch_markers(cfg: PlantConfig, points: &[f64]) -> Result<Vec<f64>, TestCaseError> {
    let mut plant = Plant::new(PlantConfig {
        start: points[0],
        enable_delay_cycles: 0,
        ..cfg
    });
    let mut cmd = Command {
        enable: true,
        position: points[0],
        torque_limit_positive: 100.0,
        torque_limit_negative: 100.0,
        ..Command::default()
    };
    plant.step(&cmd, 0.001);
    let mut id: u8 = 0;
    let mut latched = Vec::new();
    for &p in &points[1..] {
        id = id % 255 + 1;
        cmd.position = p;
        cmd.marker_arm = LatchArm {
            id,
            edge: Edge::Rising,
        };
        let fb = plant.step(&cmd, 0.001);
        assert_finite(&fb)?;
        prop_assert_eq!(fb.position, p);
        prop_assert_eq!(fb.marker_latch.id, id);
        if fb.marker_latch.latched {
            latched.push(fb.marker_latch.position);
        }
    }
    Ok(latched)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Any f64, with the awkward ones well represented.
fn wild_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -1e3..1e3f64,
        2 => any::<f64>(),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(f64::MAX),
        1 => Just(-f64::MAX),
        1 => Just(0.0),
        1 => Just(-0.0),
    ]
}

fn wild_interval() -> impl Strategy<Value = Option<(f64, f64)>> {
    proptest::option::of((wild_f64(), wild_f64()))
}

fn wild_config() -> impl Strategy<Value = PlantConfig> {
    (
        (
            wild_f64(),
            wild_interval(),
            any::<bool>(),
            wild_f64(),
            wild_f64(),
        ),
        (
            wild_interval(),
            wild_interval(),
            wild_f64(),
            any::<bool>(),
            0u8..3,
        ),
        (wild_f64(), wild_f64(), wild_f64(), 0u32..4),
        proptest::option::of((wild_f64(), wild_f64(), wild_f64())),
    )
        .prop_map(
            |(
                (start, switch, nc, every, at),
                (hard_stop, overtravel, external_speed, limits_nc, probe),
                (push_gain, inertia_gain, friction, delay),
                spike,
            )| PlantConfig {
                start,
                switch,
                switch_normally_closed: nc,
                marker_every: every,
                marker_at: at,
                hard_stop,
                overtravel,
                limit_switches_normally_closed: limits_nc,
                registration_input: match probe {
                    0 => RegistrationInput::HomeSwitch,
                    1 => RegistrationInput::NegativeLimit,
                    _ => RegistrationInput::PositiveLimit,
                },
                external_speed,
                push_gain,
                inertia_gain,
                friction,
                enable_delay_cycles: delay,
                torque_spike: spike.map(|(at, width, level)| TorqueSpike { at, width, level }),
            },
        )
}

fn wild_command() -> impl Strategy<Value = (Command, f64)> {
    (
        (
            prop::bool::weighted(0.9),
            wild_f64(),
            wild_f64(),
            prop::bool::weighted(0.1),
        ),
        (wild_f64(), wild_f64(), wild_f64(), wild_f64()),
        (0u8..4, any::<bool>(), 0u8..4, any::<bool>()),
        prop_oneof![4 => Just(0.001), 1 => wild_f64()],
    )
        .prop_map(
            |(
                (enable, position, velocity, fault_reset),
                (lp, ln, pt, vt),
                (mi, me, si, se),
                dt,
            )| {
                let edge = |b| if b { Edge::Rising } else { Edge::Falling };
                (
                    Command {
                        enable,
                        position,
                        velocity,
                        torque_limit_positive: lp,
                        torque_limit_negative: ln,
                        position_error_tolerance: pt,
                        velocity_error_tolerance: vt,
                        marker_arm: LatchArm {
                            id: mi,
                            edge: edge(me),
                        },
                        switch_arm: LatchArm {
                            id: si,
                            edge: edge(se),
                        },
                        fault_reset,
                        drive_home: false,
                    },
                    dt,
                )
            },
        )
}

proptest! {
    /// The same markers, bit for bit, whichever way a segment is travelled and
    /// however it is cut into cycles. Each cycle is at most half a marker
    /// pitch, so a fresh capture per cycle sees every marker. A marker exactly
    /// on an end of the segment is passed only when arriving on it (forward at
    /// `b`, backward at `a`), so those are compared without the ends.
    #[test]
    fn markers_latch_identically_both_ways(
        at in -100.0..100.0f64,
        every in 0.01..50.0f64,
        a in -1000.0..1000.0f64,
        pitches in 0.01..20.0f64,
        extra in 0usize..4,
    ) {
        let cfg = PlantConfig { marker_at: at, marker_every: every, ..PlantConfig::default() };
        let len = every * pitches;
        let b = a + len;
        let n = (2.0 * pitches).ceil() as usize + extra;
        let mut points: Vec<f64> = (0..=n).map(|i| a + len * i as f64 / n as f64).collect();
        points[n] = b;

        let forward = latch_markers(cfg, &points)?;
        points.reverse();
        let mut backward = latch_markers(cfg, &points)?;
        backward.reverse();

        let inner = |v: &[f64]| -> Vec<f64> {
            v.iter().copied().filter(|&m| m != a && m != b).collect()
        };
        prop_assert_eq!(bits(&inner(&forward)), bits(&inner(&backward)));

        // And they are exactly the analytic marker positions inside (a, b].
        let track = Markers::new(at, every);
        let mut expected = Vec::new();
        let mut x = a;
        while let Some(m) = track.next_above(x).filter(|&m| m <= b) {
            expected.push(m);
            x = m;
        }
        prop_assert_eq!(bits(&forward), bits(&expected));
        for m in &forward {
            // Each is `at + k * every` for an integer k.
            let k = ((m - at) / every).round();
            prop_assert_eq!(m.to_bits(), (at + k * every).to_bits());
        }
    }

    /// The edges counted on any segment agree with the levels at its ends,
    /// and alternate in sense; boundary values are drawn often.
    #[test]
    fn switch_edges_agree_with_levels(
        lo in -10.0..10.0f64,
        width in 0.0..10.0f64,
        nc in any::<bool>(),
        ends in (0usize..4, 0usize..4, -30.0..30.0f64, -30.0..30.0f64),
    ) {
        let hi = lo + width;
        let sw = Switch::new(lo, hi, nc);
        let pick = |i: usize, free: f64| [lo, hi, free, free][i];
        let (old, new) = (pick(ends.0, ends.2), pick(ends.1, ends.3));
        let edges: Vec<_> = sw.edges(old, new).into_iter().flatten().collect();
        prop_assert_eq!(edges.len() % 2 == 1, sw.level(old) != sw.level(new));
        if let Some(first) = edges.first() {
            let expect = if sw.level(old) { Edge::Falling } else { Edge::Rising };
            prop_assert_eq!(first.edge, expect);
        }
        if let [e1, e2] = edges[..] {
            prop_assert!(e1.edge != e2.edge);
        }
    }

    /// Whatever the config and commands, the plant neither panics nor reports
    /// a non-finite value, and never leaves its hard stops.
    #[test]
    fn feedback_is_always_finite(
        cfg in wild_config(),
        cmds in prop::collection::vec(wild_command(), 1..40),
    ) {
        let mut plant = Plant::new(cfg);
        assert_finite(&plant.feedback())?;
        let stops = plant.config().hard_stop;
        for (cmd, dt) in &cmds {
            let fb = plant.step(cmd, *dt);
            assert_finite(&fb)?;
            prop_assert_eq!(fb, plant.feedback());
            if let Some((lo, hi)) = stops {
                prop_assert!(lo <= fb.position && fb.position <= hi);
            }
            if !cmd.position.is_finite() {
                prop_assert!(fb.drive.fault && !fb.drive.enabled);
            }
            if !fb.drive.enabled {
                prop_assert_eq!(fb.torque, 0.0);
            }
        }
    }

    /// Determinism: the same inputs give the same bits.
    #[test]
    fn deterministic(
        cfg in wild_config(),
        cmds in prop::collection::vec(wild_command(), 1..20),
    ) {
        let mut p1 = Plant::new(cfg);
        let mut p2 = Plant::new(cfg);
        for (cmd, dt) in &cmds {
            let (f1, f2) = (p1.step(cmd, *dt), p2.step(cmd, *dt));
            prop_assert_eq!(format!("{f1:?}"), format!("{f2:?}"));
        }
    }
}
