//! Registration meets redefine position: an armed window stays at its
//! place on the machine when the positions are redefined.

mod common;
use common::{op, Rig};

/// Soft limits ±`lim`, `max_deceleration` 100.
fn axis(lim: f64) -> AxisConfig {
    AxisConfig {
        max_deceleration: 100.0,
        ..common::immediate_axis(lim)
    }
}
use motion_homing::*;
use motion_plant::PlantConfig;

/// Armed around the switch edge (axis 3, window [2.5, 3.5]), then
/// redefined by +100: the window follows the positions, so the same edge
/// on the machine — now at axis 103 — is latched there (before, the window
/// stayed at [2.5, 3.5] of the new numbers: nothing latched, and
/// `motionctl arm` waited for ever).
#[test]
fn a_redefine_after_arm_keeps_the_window_on_the_machine() {
    for by in [0.0, 100.0] {
        let plant = PlantConfig {
            start: -3.0,
            switch: Some((0.0, 5.0)),
            ..PlantConfig::default()
        };
        let mut r = Rig::new(axis(1000.0), plant);
        r.step(op(Operation::Enable));
        r.idle(50);
        let rung = Request {
            home: true,
            ..Request::default()
        };
        for _ in 0..50 {
            r.step(rung);
        }
        r.idle(10);
        assert!(r.axis.status().homed);
        r.step(op(Operation::Arm(ArmSpec {
            input: LatchInput::Switch,
            edge: LatchEdge::Rising,
            window: Some((2.5, 3.5)),
        })));
        r.step(op(Operation::Redefine(RedefineSpec::by(by))));
        assert!(r.axis.status().op.refused.is_none());
        r.step(op(Operation::Move(MoveSpec {
            target: 10.0 + by,
            relative: false,
            speed: Some(5.0),
            accel: Some(100.0),
            decel: Some(100.0),
            supersede: false,
            jerk: None,
        })));
        r.idle(3000);
        let s = r.axis.status();
        assert!(!s.registration_armed, "{by}: still armed");
        let at = s.registration_position.expect("latched");
        assert!((at - (3.0 + by)).abs() < 0.01, "{by}: latched at {at}");
        assert!(r.tripped.is_none());
    }
}
