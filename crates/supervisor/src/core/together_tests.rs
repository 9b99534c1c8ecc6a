//! The cycle monitor in the cycle: a gantry whose sides' operations
//! diverge is stopped on every side by their monitors (ERR 1021 / 6), and
//! the trip reaches the status snapshot with its values.

use super::testbench::Bench;
use crate::shared::{Ask, Control};
use motion_homing::codes::{ERR_MONITOR, EX_MONITOR_GANTRY};
use motion_homing::JogSpec;
use motion_homing::Operation;
use motion_monitor::{Category, Invariant};

/// A gantry Y (switch homing, sides alike for homing) whose sides' caps
/// while not homed differ: Y1 10 u/s, Y2 5 u/s (the lockstep rule of the
/// configuration compares the homing keys only).
fn gantry() -> String {
    let side = |name: &str, unhomed: f64| {
        format!(
            r#"
[[axis]]
name = "{name}"
counts_per_unit = 1000.0
home_sequence = "switch"
home_speed = 20.0
home_return_speed = 2.0
home_acceleration = 500.0
home_deceleration = 500.0
unhomed_speed = {unhomed}
travel_limits = [-100.0, 100.0]
[axis.sim]
start = -10.0
switch = [0.0, 5.0]
"#
        )
    };
    format!(
        "[supervisor]\ncycle_us = 1000\ncpu = 0\n{}{}\n[[gantry]]\nname = \"Y\"\naxes = [\"Y1\", \"Y2\"]\nmax_skew = 0.5\n",
        side("Y1", 10.0),
        side("Y2", 5.0)
    )
}

#[test]
fn gantry_sides_that_move_apart_are_stopped_together_by_their_monitors() {
    let mut b = Bench::new(&gantry());
    b.run(5);
    assert!(b.home(0b11, false).axes[..2].iter().all(|a| a.accepted()));
    b.run(4000);
    let s = b.snap();
    assert!(s.axes[0].status.homed && s.axes[1].status.homed);
    b.control(Control::undated(
        1,
        Ask::Op {
            mask: 0b11,
            op: Operation::Jog(JogSpec {
                speed: 8.0,
                lease: Some(5.0),
                accel: Some(500.0),
                decel: Some(500.0),
            }),
            token: 77,
        },
    ));
    b.run(100);
    // both jog at 8, together: nothing to say
    assert!(b.snap().axes[..2].iter().all(|a| a.status.jogging));
    b.allow_trips = true;
    b.control(Control::undated(2, Ask::Unhome { mask: 0b11 }));
    // Y1 runs on at 8 (under its cap of 10), Y2 slows to 5: apart by
    // 0.5 within a fifth of a second
    b.run(400);
    let s = b.snap();
    for a in &s.axes[..2] {
        let t = a.monitor.expect("tripped");
        assert_eq!(t.invariant, Invariant::Gantry);
        assert_eq!(t.category, Category::Stop1);
        assert_eq!(t.bound, 0.5);
        assert!(t.value > 0.5 && t.value < 0.6, "{t:?}");
        assert_eq!(a.monitor_trips, 1);
        let st = a.status;
        assert_eq!((st.err, st.exerr), (ERR_MONITOR, EX_MONITOR_GANTRY));
        assert!(st.faulted && !st.jogging, "{st:?}");
        assert!(!a.enable, "at rest, the power stage off");
    }
    // the sides stood still from the cycle the monitor tripped
    let apart = (b.plants[0].position() - b.plants[1].position()).abs();
    assert!(apart < 0.5 + 0.1, "{apart}");
}
