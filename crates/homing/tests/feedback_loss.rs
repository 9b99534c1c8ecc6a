//! The feedback-loss rule, stated in time (a leaky bucket: missing time adds,
//! 0.25 × fresh time drains, trips above 10 ms), and what the engine does
//! during a gap it tolerates: nothing decided on old data, the planned
//! profile runs on, a switch edge across the gap placed at the midpoint of
//! the samples around it.
//!
//! Machine: switch [0, 5], markers every 10 at 2.5, home speed V = 20,
//! return speed R = 2, acceleration = deceleration = 500, cycle 1 ms (the
//! plant reaches its command in the cycle, so a cruising jog advances exactly
//! V × T = 0.02 per cycle).

mod common;

use common::{axis, machine, steps, Steps};
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::PlantConfig;

const MS: u64 = 1_000_000;

fn switch_axis(dir: HomeDirection) -> AxisConfig {
    AxisConfig {
        marker: false,
        ..axis(HomeSequence::Switch, dir)
    }
}

/// Steps engine and plant every `cycle_ns` for `steps`, homing from step 0;
/// `drop(k, feedback)` true withholds step k's frame.
fn trace(
    cfg: AxisConfig,
    plant: PlantConfig,
    cycle_ns: u64,
    n: usize,
    mut drop: impl FnMut(usize, &Feedback) -> bool,
) -> Steps {
    steps(cfg, plant, cycle_ns, n, |k, _, fb| {
        (!drop(k, &fb)).then_some(fb)
    })
}

#[test]
fn a_5_ms_gap_during_homing_does_not_abort_and_the_jog_runs_on() {
    // At step 1000 the seek cruises at 20 u/s (enabled by step 3, 40 ms of
    // acceleration) near -30.5, far from the switch.
    let t = trace(
        switch_axis(HomeDirection::BidirectionalForward),
        machine(),
        MS,
        8000,
        |k, _| (1000..1005).contains(&k),
    );
    let end = t.st.last().unwrap();
    assert!(end.pc && !end.er, "{end:?}");
    assert!(end.event_raw.unwrap().abs() <= 2.0 * 0.001 / 2.0 + 1e-9);
    assert_eq!(end.lost_after_ns, None);
    // Last frame seen at 999: the gap is 5 ms at step 1004, over at 1005.
    assert_eq!(t.st[1004].feedback_gap_ns, 5 * MS);
    assert_eq!(t.st[1004].feedback_loss_ns, 5 * MS);
    assert_eq!(t.st[1005].feedback_gap_ns, 0);
    assert_eq!(t.st[1005].feedback_loss_ns, 5 * MS - MS / 4);
    assert!(t.st[1000..1005].iter().all(|s| s.feedback_ok && s.ip));
    // The planned profile ran on: the jog, 0.02 per cycle.
    for k in 1000..1006 {
        assert_eq!(t.cmd[k].velocity, 20.0);
        let step = t.cmd[k].position - t.cmd[k - 1].position;
        assert!((step - 0.02).abs() < 1e-9, "{k}: {step}");
    }
}

#[test]
fn a_15_ms_gap_aborts_after_10_ms_plus_one_cycle() {
    let t = trace(
        switch_axis(HomeDirection::BidirectionalForward),
        machine(),
        MS,
        3000,
        |k, _| (1000..1015).contains(&k),
    );
    // Last frame seen at 999; steps 1000..=1009 fill the bucket to 10 ms
    // (not above the timeout), step 1010 to 11 ms: tripped, gap 11 ms.
    assert!(t.st[1009].ip && !t.st[1009].er);
    let s = t.st[1010];
    assert!(s.er && s.dn && !s.ip && !s.homed && !s.feedback_ok, "{s:?}");
    assert_eq!((s.err, s.exerr), (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST));
    assert_eq!(s.lost_after_ns, Some(11 * MS));
    assert_eq!(s.finished_ns, Some(1010 * MS));
    assert!(s.stopping, "the axis is stopped");
    // Feedback back at 1015: usable again, the abort stands.
    let end = t.st.last().unwrap();
    assert!(end.feedback_ok && end.er && !end.homed);
    assert_eq!(end.lost_after_ns, Some(11 * MS));
    assert_eq!(t.cmd.last().unwrap().velocity, 0.0);
}

#[test]
fn every_other_frame_lost_trips() {
    // Odd steps missing: after step 2n+1 the bucket holds 1 + 0.75 n ms, above
    // 10 ms first at n = 13: step 27, with 10.75 ms in the bucket and a gap of
    // one cycle.
    let t = trace(
        switch_axis(HomeDirection::BidirectionalForward),
        machine(),
        MS,
        200,
        |k, _| k % 2 == 1,
    );
    assert!(!t.st[25].er);
    let s = t.st[27];
    assert_eq!(
        (s.err, s.exerr),
        (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST),
        "{s:?}"
    );
    assert_eq!(s.feedback_loss_ns, 10_750_000);
    assert_eq!(s.lost_after_ns, Some(MS));
    assert_eq!(s.finished_ns, Some(27 * MS));
}

#[test]
fn a_switch_crossed_during_a_5_cycle_gap_is_placed_at_the_midpoint() {
    // Unidirectional seek at V = 20 towards the switch at 0. The gap starts
    // with the first frame at or past -0.01 and withholds five frames, so the
    // last sample before it, p, lies in [-0.03, -0.01) and the first after it
    // is six cycles later: p + 0.12. The edge is placed at p + 0.06, in
    // [0.03, 0.05): beyond the gapless bound V x T / 2 = 0.01, within
    // V x 6T / 2 = 0.06.
    let mut gap_from = None;
    let t = trace(
        switch_axis(HomeDirection::UnidirectionalForward),
        machine(),
        MS,
        6000,
        |k, fb| {
            if gap_from.is_none() && fb.position >= -0.01 {
                gap_from = Some(k);
            }
            gap_from.is_some_and(|g| (g..g + 5).contains(&k))
        },
    );
    let g = gap_from.unwrap();
    let (before, after) = (t.seen[g - 1], t.seen[g + 5]);
    assert!((-0.03..-0.01).contains(&before), "{before}");
    assert!((after - before - 0.12).abs() < 1e-9);
    // Nothing is detected from old data during the gap.
    assert!(t.st[g..g + 5].iter().all(|s| s.event_raw.is_none()));
    let e = t.st[g + 5]
        .event_raw
        .expect("found on the first fresh sample");
    assert!((e - (before + after) / 2.0).abs() < 1e-12, "{e}");
    assert!(e.abs() <= 20.0 * 0.006 / 2.0 + 1e-9 && e > 0.01, "{e}");
    assert!(t.st.last().unwrap().homed);
}

#[test]
fn a_stop_ramp_ends_during_a_gap_but_the_next_leg_waits_for_feedback() {
    // Bidirectional switch: the seek's stop ramp from 20 u/s lasts
    // 20 / 500 = 40 ms. Frames withheld from 35 to 42 ms into it: the ramp
    // reaches rest at 40 ms (the profile runs on), but the return leg, which
    // needs the switch state, starts only on the fresh frame at 43 ms.
    let cfg = switch_axis(HomeDirection::BidirectionalForward);
    let clean = trace(cfg, machine(), MS, 8000, |_, _| false);
    let s0 = clean
        .st
        .iter()
        .position(|s| s.phase == Phase::SeekStop)
        .unwrap();
    // The same run (deterministic) with the frames withheld.
    let t = trace(cfg, machine(), MS, 8000, |k, _| {
        (s0 + 35..s0 + 43).contains(&k)
    });
    assert_eq!(t.st[s0].phase, Phase::SeekStop);
    assert!(t.cmd[s0 + 39].velocity > 0.0);
    for k in s0 + 40..s0 + 43 {
        assert_eq!(t.cmd[k].velocity, 0.0, "{k}: at rest");
        assert_eq!(t.st[k].phase, Phase::SeekStop, "{k}: no new leg blind");
    }
    assert_eq!(t.st[s0 + 43].phase, Phase::Return);
    assert!(t.cmd[s0 + 44].velocity < 0.0);
    assert!(t.st.last().unwrap().pc);
}

#[test]
fn the_rule_means_the_same_at_8_khz() {
    // 125 us steps: 80 missing steps are exactly 10 ms (tolerated), the 81st
    // trips with a gap of 81 x 0.125 = 10.125 ms.
    const STEP: u64 = 125_000;
    let mut axis = Axis::new(AxisConfig::default()); // immediate
    let home = common::home();
    axis.step(0, Some(&Feedback::default()), &home);
    assert!(axis.status().homed);
    for k in 1..=80 {
        axis.step(k * STEP, None, &home);
        assert!(axis.status().homed, "{k}");
    }
    axis.step(81 * STEP, None, &home);
    assert!(!axis.status().homed && !axis.status().feedback_ok);
    assert_eq!(axis.status().lost_after_ns, Some(10_125_000));
}
