//! Fuzzed: feedback frames of any content reach the cycle the way
//! the real-time thread hands them over (after the ports' key and layout
//! checks, which a forger with the key passes): the link, `axis_to_feedback`,
//! the engines' feedback checks. Whatever arrives, and whenever during a
//! homing of the demo machine:
//!
//! * nothing panics;
//! * no decoded value that is not finite or is out of range (position or
//!   velocity beyond `max_position`, torque beyond 1000 %, a latched latch
//!   beyond `max_position`) is taken as feedback: the axis keeps its last
//!   good sample, and the status shows only good ones;
//! * every command published stays finite (bad input never becomes motion).

use super::testbench::{Bench, MS};
use super::*;
use motion_frames::{
    axis_to_command, axis_to_feedback, AxisFeedback, INVALID_COUNTS, LAYOUT_VERSION, SW_NO_DATA,
};
use motion_homing::{AxisConfiguration, Feedback};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// What a hostile or broken peer sends in place of one answer.
#[derive(Clone, Debug)]
enum Garbage {
    /// Any bytes, header included (mostly refused by the link).
    Bytes(Vec<u8>),
    /// Any bytes in the axes behind a header the link accepts.
    AxisBytes(Vec<u8>),
    /// Chosen values (NaN, ±inf, extremes, the sentinel) in the axes behind
    /// a header the link accepts.
    Fields(Vec<AxisFeedback>),
}

fn wild_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -1e5..1e5f64,
        2 => any::<f64>(),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(f64::MAX),
        1 => Just(1e10),
    ]
}

fn wild_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -2000.0..2000.0f32,
        1 => any::<f32>(),
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::MAX),
    ]
}

fn wild_i64() -> impl Strategy<Value = i64> {
    prop_oneof![
        4 => -200_000i64..200_000,
        2 => any::<i64>(),
        1 => Just(INVALID_COUNTS),
        1 => Just(i64::MAX),
        1 => Just(i64::MIN + 1),
    ]
}

fn wild_axis() -> impl Strategy<Value = AxisFeedback> {
    (
        (
            wild_i64(),
            wild_f64(),
            wild_f32(),
            any::<u32>(),
            any::<u16>(),
        ),
        (any::<u8>(), 0u8..3, any::<u8>(), 0u8..3, any::<u16>()),
        (wild_i64(), wild_i64()),
    )
        .prop_map(
            |((p, v, t, di, sw), (mid, ml, sid, sl, ec), (mp, sp))| AxisFeedback {
                position: p,
                velocity: v,
                torque: t,
                digital_inputs: di,
                // Mostly with data: SW_NO_DATA makes the engine skip the axis.
                status_word: (sw & !SW_NO_DATA) | if sw % 8 == 0 { SW_NO_DATA } else { 0 },
                marker_latch_id: mid,
                marker_latched: ml,
                switch_latch_id: sid,
                switch_latched: sl,
                error_code: ec,
                marker_latch_position: mp,
                switch_latch_position: sp,
            },
        )
}

fn garbage(axes: usize) -> impl Strategy<Value = Garbage> {
    let frame = std::mem::size_of::<FeedbackFrame>();
    let axis = std::mem::size_of::<AxisFeedback>();
    prop_oneof![
        1 => prop::collection::vec(any::<u8>(), 0..=frame).prop_map(Garbage::Bytes),
        2 => prop::collection::vec(any::<u8>(), axes * axis).prop_map(Garbage::AxisBytes),
        4 => prop::collection::vec(wild_axis(), axes).prop_map(Garbage::Fields),
    ]
}

/// `bytes` written over `f` from `offset` on.
fn overwrite(f: &mut FeedbackFrame, offset: usize, bytes: &[u8]) {
    let n = bytes
        .len()
        .min(std::mem::size_of::<FeedbackFrame>().saturating_sub(offset));
    // SAFETY: FeedbackFrame is a repr(C) struct of integers and floats only
    // (as on the wire): every bit pattern is a value; the write stays inside.
    unsafe {
        let base = (f as *mut FeedbackFrame).cast::<u8>();
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), base.add(offset), n);
    }
}

/// The frame a peer sends: accepted by the link (this process's axis count,
/// the answer to the last command, the same incarnation) unless it is all
/// bytes.
fn frame(b: &Bench, g: &Garbage) -> FeedbackFrame {
    let mut f = b.fb[0];
    f.header.layout_version = LAYOUT_VERSION;
    f.header.axis_count = b.m.axes.len() as u32;
    f.header.origin = b.origin[0];
    f.answers_sequence = b.seq[0];
    match g {
        Garbage::Bytes(bytes) => overwrite(&mut f, 0, bytes),
        Garbage::AxisBytes(bytes) => {
            let start = std::mem::offset_of!(FeedbackFrame, axes);
            overwrite(&mut f, start, bytes);
        }
        Garbage::Fields(axes) => f.axes[..axes.len()].copy_from_slice(axes),
    }
    f
}

/// What the engine must refuse (its feedback checks, as documented).
fn bad(fb: &Feedback, max_position: f64) -> bool {
    let out = |x: f64, limit: f64| !x.is_finite() || x.abs() > limit;
    out(fb.position, max_position)
        || out(fb.velocity, max_position)
        || out(fb.torque, 1000.0)
        || (fb.marker_latch.latched && out(fb.marker_latch.position, max_position))
        || (fb.switch_latch.latched && out(fb.switch_latch.position, max_position))
}

/// One cycle on frame `f` in place of the I/O process's answer.
fn garbage_cycle(b: &mut Bench, f: &FeedbackFrame) {
    let now = b.k * MS;
    b.core.step(now, false, &[Some(f)]);
    b.core.fill(0, &mut b.cmd[0]);
    b.seq[0] += 1;
    b.core.sent(0, b.seq[0], now);
    b.k += 1;
}

/// The published commands are finite and inside `max_position`; the status
/// holds only good feedback.
fn check_cycle(b: &Bench) -> Result<(), TestCaseError> {
    let s = b.snap();
    for (j, a) in b.m.axes.iter().enumerate() {
        let e = &a.engine;
        let w = &b.cmd[0].axes[j];
        prop_assert_ne!(w.target_position, INVALID_COUNTS, "axis {}", a.name);
        let c = axis_to_command(w, e.counts_per_unit);
        for x in [
            c.position,
            c.velocity,
            c.torque_limit_positive,
            c.torque_limit_negative,
            c.position_error_tolerance,
            c.velocity_error_tolerance,
        ] {
            prop_assert!(x.is_finite(), "axis {}: command {c:?}", a.name);
        }
        prop_assert!(c.position.abs() <= e.max_position, "axis {}: {c:?}", a.name);
        let st = &s.axes[j];
        if let Some(raw) = st.raw {
            prop_assert!(raw.is_finite() && raw.abs() <= e.max_position, "{st:?}");
        }
        prop_assert!(st.velocity.is_finite() && st.velocity.abs() <= e.max_position);
        prop_assert!(st.torque.is_finite() && st.torque.abs() <= 1000.0, "{st:?}");
    }
    Ok(())
}

#[test]
fn garbage_feedback_never_becomes_feedback_nor_motion() {
    let mut runner = TestRunner::new(Config {
        cases: 128,
        failure_persistence: None,
        ..Config::default()
    });
    let axes = motion_config::parse(motion_config::DEMO_TOML)
        .unwrap()
        .axes
        .len();
    let script = prop::collection::vec((garbage(axes), 0u64..4), 1..12);
    runner
        .run(&(0u64..4000, script), |(warm, script)| {
            let mut b = Bench::new(motion_config::DEMO_TOML);
            // a hostile peer's frames (a fault bit that comes and goes):
            // the monitor may stop an axis, as it should
            b.allow_trips = true;
            b.run(20);
            let all = b.core.all_mask();
            prop_assert!(b.home(all, false).axes[..axes].iter().all(|a| a.accepted()));
            b.run(warm);
            for (g, then) in &script {
                let f = frame(&b, g);
                let before: Vec<Option<f64>> = b
                    .core
                    .axes()
                    .iter()
                    .map(|a| a.engine().raw_position())
                    .collect();
                garbage_cycle(&mut b, &f);
                check_cycle(&b)?;
                if !matches!(g, Garbage::Bytes(_)) {
                    for (j, a) in b.m.axes.iter().enumerate() {
                        let d = axis_to_feedback(&f.axes[j], a.engine.counts_per_unit);
                        let virtual_axis = a.engine.configuration == AxisConfiguration::Virtual;
                        if bad(&d, a.engine.max_position) && !virtual_axis {
                            // never taken as a position: the one before
                            // stays, or none is known any more (bad samples
                            // count as missing: enough of them are a loss)
                            let after = b.core.axes()[j].engine().raw_position();
                            prop_assert!(
                                after.is_none()
                                    || after.map(f64::to_bits) == before[j].map(f64::to_bits),
                                "axis {} took {:?}: {:?} -> {:?}",
                                a.name,
                                d,
                                before[j],
                                after
                            );
                        }
                    }
                }
                for _ in 0..*then {
                    b.cycle();
                    check_cycle(&b)?;
                }
            }
            b.run(50);
            check_cycle(&b)?;
            Ok(())
        })
        .unwrap();
}
