//! Forged or corrupt frames never become an event: positions that jump
//! further than the axis can move, and latches off the travel since arming.
//!
//! Machine: switch [0, 5], markers every 10 at 2.5, V = 20, R = 2,
//! acceleration = deceleration = 500, 1000 counts per unit, cycle 1 ms.
//! `max_speed` derived: 2 x max(V, R) = 40 units/s, so between two samples
//! 1 ms apart a position may move 40 x 0.001 x 1.5 + 2 / 1000 = 0.062, and a
//! latch may lie 40 x 0.001 + 0.002 = 0.042 outside the travel since arming.

mod common;

use common::{axis, machine, steps, Steps};
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::{Plant, PlantConfig};

const MS: u64 = 1_000_000;

/// Homes from step 0; `forge(k, previous command, frame)` may rewrite the
/// frame the engine sees at step k.
fn run(
    cfg: AxisConfig,
    plant: PlantConfig,
    n: usize,
    mut forge: impl FnMut(usize, &Command, &mut Feedback),
) -> Steps {
    steps(cfg, plant, MS, n, |k, last, mut fb| {
        forge(k, last, &mut fb);
        Some(fb)
    })
}

#[test]
fn a_forged_position_on_the_switch_is_never_the_event() {
    // Unidirectional switch seek: at step 1000 (near -30.5) a frame claims the
    // axis is at 2.5 with the switch actuated. Without the check that would
    // be the switch detected (event at the midpoint, about -14). It is a jump
    // of about 33 in 1 ms against 0.062 allowed: refused, ERR 12 / EXERR 44.
    let r = run(
        axis(HomeSequence::Switch, HomeDirection::UnidirectionalForward),
        machine(),
        1500,
        |k, _, fb| {
            if k == 1000 {
                fb.position = 2.5;
                fb.home_switch = true;
            }
        },
    );
    assert!(r.st[999].ip);
    let s = r.st[1000];
    assert!(s.er && !s.ip && !s.homed && s.stopping, "{s:?}");
    assert_eq!(
        (s.err, s.exerr),
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_IMPLAUSIBLE)
    );
    assert_eq!(s.event_raw, None);
    assert_eq!(s.implausible.jumps, 1);
    // The genuine frames after it are plausible against the last plausible
    // one (the forged sample never became the reference).
    let end = r.st.last().unwrap();
    assert_eq!(
        end.implausible,
        Implausible {
            jumps: 1,
            ..Implausible::default()
        }
    );
    assert_eq!(end.event_raw, None);
    assert_eq!(r.cmd.last().unwrap().velocity, 0.0, "stopped");
}

#[test]
fn a_forged_frame_clears_homed_at_rest_without_an_error() {
    // Immediate homing with an explicit max_speed (immediate commands no
    // motion, so nothing would be derived): homed at step 0, then one frame
    // 1 unit away (allowed at 10 u/s: 10 x 0.001 x 1.5 + 0.002 = 0.017).
    let cfg = AxisConfig {
        counts_per_unit: 1000.0,
        max_speed: 10.0,
        ..AxisConfig::default()
    };
    let mut axis = Axis::new(cfg);
    let home = common::home();
    let at = |p: f64| Feedback {
        position: p,
        ..Feedback::default()
    };
    axis.step(0, Some(&at(0.0)), &home);
    assert!(axis.status().homed && axis.status().pc);
    axis.step(MS, Some(&at(1.0)), &home);
    let s = *axis.status();
    assert!(
        !s.homed && !s.er && s.pc,
        "no instruction error at rest: {s:?}"
    );
    assert_eq!(s.implausible.jumps, 1);
    assert_eq!(
        axis.raw_position(),
        Some(0.0),
        "the forged sample is not used"
    );
    assert_eq!(s.feedback_gap_ns, 2 * MS - MS, "it counts as missing");
    axis.step(2 * MS, Some(&at(0.0)), &home);
    assert_eq!(axis.status().implausible.jumps, 1);
    assert_eq!(axis.status().feedback_gap_ns, 0);
}

#[test]
fn a_latched_marker_off_the_travel_is_ignored_and_the_latch_re_armed() {
    // Bidirectional marker seek from -50: the first marker is -47.5. At step
    // 100 (near -48.6, well before it) a frame claims the armed latch caught a
    // marker at 10.0: 58 beyond the travel since arming ([-50, -48.6] plus
    // 0.042). Ignored, counted, re-armed: the event is the genuine -47.5.
    let mut armed = 0;
    let r = run(
        axis(HomeSequence::Marker, HomeDirection::BidirectionalForward),
        machine(),
        3000,
        |k, last, fb| {
            if k == 100 {
                armed = last.marker_arm.id;
                fb.marker_latch = LatchFeedback {
                    id: armed,
                    latched: true,
                    position: 10.0,
                };
            }
        },
    );
    assert_ne!(armed, 0);
    assert_eq!(r.st[100].implausible.marker_latches, 1);
    assert!(r.st[100].ip && r.st[100].event_raw.is_none());
    assert_ne!(r.cmd[100].marker_arm.id, armed, "re-armed");
    let end = r.st.last().unwrap();
    assert!(end.pc, "{end:?}");
    assert_eq!(end.event_raw, Some(-47.5));
    assert_eq!(end.implausible.marker_latches, 1);
}

#[test]
fn a_registration_latch_off_the_travel_falls_back_to_the_sampled_edge() {
    // Bidirectional switch with registration: every switch capture is forged
    // to 3.0. The seek's capture (armed at -50, detected near 0) and the
    // return's (armed near 0.4 on the switch, cleared near 0) both lie off
    // their travel: two refused, and the event is the sampled clear edge,
    // within R x T / 2 = 0.001 of 0, not 3.0.
    let cfg = AxisConfig {
        registration: true,
        ..axis(HomeSequence::Switch, HomeDirection::BidirectionalForward)
    };
    let r = run(cfg, machine(), 8000, |_, _, fb| {
        if fb.switch_latch.latched {
            fb.switch_latch.position = 3.0;
        }
    });
    let end = r.st.last().unwrap();
    assert!(end.pc, "{end:?}");
    assert!(end.event_raw.unwrap().abs() <= 0.001 + 1e-9, "{end:?}");
    assert_eq!(end.implausible.switch_latches, 2);
}

#[test]
fn genuine_registration_is_still_exact() {
    // The same run without forging: the drive's capture at exactly 0 is used.
    let cfg = AxisConfig {
        registration: true,
        ..axis(HomeSequence::Switch, HomeDirection::BidirectionalForward)
    };
    let r = run(cfg, machine(), 8000, |_, _, _| {});
    let end = r.st.last().unwrap();
    assert_eq!(end.event_raw, Some(0.0));
    assert_eq!(end.implausible, Implausible::default());
}

#[test]
fn passive_axes_without_max_speed_are_not_checked() {
    // Passive switch: homing speeds do not apply, none derived. A 100-unit
    // step between two frames is accepted (something else moves the axis).
    let cfg = AxisConfig {
        configuration: AxisConfiguration::FeedbackOnly,
        home_mode: HomeMode::Passive,
        ..axis(HomeSequence::Switch, HomeDirection::BidirectionalForward)
    };
    assert_eq!(effective_max_speed(&cfg), None);
    let mut axis = Axis::new(cfg);
    let at = |p: f64| Feedback {
        position: p,
        ..Feedback::default()
    };
    let idle = Request::default();
    axis.step(0, Some(&at(-50.0)), &idle);
    axis.step(MS, Some(&at(50.0)), &idle);
    assert_eq!(axis.raw_position(), Some(50.0));
    assert_eq!(axis.status().implausible, Implausible::default());
}

#[test]
fn max_speed_derivation_and_validation() {
    let bi = axis(HomeSequence::Switch, HomeDirection::BidirectionalForward);
    // 2 x max(20, 2) = 40.
    assert_eq!(effective_max_speed(&bi), Some(40.0));
    // Unidirectional: the return speed is not commanded; a creep leg is.
    let uni = AxisConfig {
        home_direction: HomeDirection::UnidirectionalForward,
        home_return_speed: 30.0,
        ..bi
    };
    assert_eq!(effective_max_speed(&uni), Some(40.0));
    let creep = AxisConfig {
        home_sequence: HomeSequence::Marker,
        marker_latch: false,
        home_creep_speed: 25.0,
        ..bi
    };
    assert_eq!(effective_max_speed(&creep), Some(50.0));
    assert_eq!(
        effective_max_speed(&AxisConfig {
            max_speed: 15.0,
            ..bi
        }),
        Some(15.0)
    );

    let codes = |c: &AxisConfig| -> Vec<(&str, u16, u16)> {
        validate(c)
            .iter()
            .map(|e| (e.attribute, e.err, e.exerr))
            .collect()
    };
    assert_eq!(
        codes(&AxisConfig {
            max_speed: 15.0,
            ..bi
        }),
        [("home_speed", 41, EX_ABOVE_MAX_SPEED)]
    );
    assert!(codes(&AxisConfig {
        max_speed: 20.0,
        ..bi
    })
    .is_empty());
    assert_eq!(
        codes(&AxisConfig {
            max_speed: -1.0,
            ..bi
        }),
        [("max_speed", 41, EX_BAD_NUMBER)]
    );
    assert_eq!(
        codes(&AxisConfig {
            max_speed: f64::NAN,
            ..bi
        }),
        [("max_speed", 41, EX_BAD_NUMBER)]
    );
}

#[test]
fn lagging_feedback_catching_up_and_a_stalled_cycle_are_plausible() {
    // The engine only knows when it steps, not when a frame was sampled.
    // Bidirectional switch seek at V = 20 (0.02 per cycle), max_speed 40.
    //
    // 1. A lagging peer: steps 1000..=1008 get frames still showing the
    //    plant as at step 999, step 1009 the current one: 10 cycles of travel
    //    (0.2) in 1 ms, against 40 x 0.001 x 1.5 + 0.002 = 0.062 from the
    //    last sample; but every position on the way was commanded.
    // 2. A stalled cycle: step 2000 comes 10 ms after step 1999, so the
    //    command jumps 0.2 and the plant follows in that step; step 2001 (1 ms
    //    later) sees it.
    let cfg = axis(HomeSequence::Switch, HomeDirection::BidirectionalForward);
    let mut axis = Axis::new(cfg);
    let mut plant = Plant::new(machine());
    let req = common::home();
    let mut frames = vec![plant.feedback()];
    let mut now = 0;
    for k in 0..8000usize {
        now += if k == 2000 { 10 * MS } else { MS };
        let seen = if (1000..1009).contains(&k) {
            frames[999]
        } else {
            frames[k]
        };
        let cmd = axis.step(now, Some(&seen), &req);
        frames.push(plant.step(&cmd, 0.001));
        if k == 1009 {
            assert!((seen.position - frames[999].position - 0.2).abs() < 1e-9);
        }
    }
    let s = axis.status();
    assert_eq!(s.implausible, Implausible::default(), "{s:?}");
    assert!(s.pc && s.event_raw.unwrap().abs() <= 0.001 + 1e-9, "{s:?}");
}
