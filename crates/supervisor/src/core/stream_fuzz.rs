//! Fuzzed like the frame decoding: setpoint frames of any content
//! — any bytes, or chosen fields (wrong keys, stale and forged tokens,
//! replayed and reordered sequence numbers, entries for axes not owned or
//! beyond the machine, NaN / ±inf / huge positions) — go through the
//! cycle's intake the way the real-time thread hands them over. Whatever
//! arrives:
//!
//! * nothing panics, and every frame is counted once: taken or refused by
//!   one reason;
//! * an axis gets a setpoint only from a frame with this session's key and
//!   layout, from the token that owns it, with a sequence number above that
//!   token's last, addressed to its lead (a gantry's first side) — anything
//!   else reaches no engine;
//! * what is taken is exactly the frame's value (the engine judges it:
//!   `motion-homing`'s stream checks and the core's fuzz below);
//! * through the whole cycle, whatever a program's timestamps claim (a
//!   microsecond, an hour, a jump), the commands the cycle publishes never
//!   move faster than `max_speed` nor change velocity by more than
//!   `stream_acceleration` × cycle, and stay inside the travel limits.

use super::stream::StreamIntake;
use motion_frames::{SetpointAxis, SetpointFrame, MAX_AXES, SETPOINT_LAYOUT, SP_VELOCITY};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

const KEY: [u64; 2] = [0x1234_5678_9abc_def0, 0x0fed_cba9_8765_4321];
/// Owned: axis 0 by token 7; the gantry 1 + 2 (lead 1) by token 9. Axis 3
/// is nobody's.
const LEAD: [usize; 4] = [0, 1, 1, 3];

fn wild_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -1e3..1e3f64,
        2 => any::<f64>(),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(f64::MAX),
    ]
}

fn entry() -> impl Strategy<Value = SetpointAxis> {
    (
        prop_oneof![4 => 0u32..5, 1 => any::<u32>()],
        prop_oneof![3 => Just(0u32), 1 => Just(SP_VELOCITY), 1 => any::<u32>()],
        wild_f64(),
        wild_f64(),
    )
        .prop_map(|(axis, flags, position, velocity)| SetpointAxis {
            axis,
            flags,
            position,
            velocity,
        })
}

/// A frame as a program (or a forger) could publish it.
fn frame() -> impl Strategy<Value = SetpointFrame> {
    (
        prop_oneof![6 => Just(SETPOINT_LAYOUT), 1 => any::<u32>()],
        prop_oneof![6 => Just(KEY), 1 => any::<[u64; 2]>(), 1 => Just([0, 0])],
        prop_oneof![3 => Just(7u64), 3 => Just(9u64), 1 => Just(0u64), 1 => any::<u64>()],
        prop_oneof![4 => 0u64..40, 1 => any::<u64>()],
        any::<u64>(),
        prop_oneof![4 => 0u32..4, 1 => any::<u32>()],
        prop::collection::vec(entry(), 0..4),
    )
        .prop_map(|(layout, key, token, seq, t_ns, count, entries)| {
            let mut f = SetpointFrame {
                layout_version: layout,
                key,
                token,
                seq,
                t_ns,
                count,
                ..SetpointFrame::ZERO
            };
            for (k, e) in entries.into_iter().enumerate().take(MAX_AXES) {
                f.axes[k] = e;
            }
            f
        })
}

/// Any bytes in a frame.
fn bytes_frame() -> impl Strategy<Value = SetpointFrame> {
    prop::collection::vec(any::<u8>(), 0..160).prop_map(|b| {
        let mut f = SetpointFrame::ZERO;
        let n = b.len().min(std::mem::size_of::<SetpointFrame>());
        // SAFETY: SetpointFrame is plain integers and floats (every bit
        // pattern a value); at most its size is written.
        unsafe {
            std::ptr::copy_nonoverlapping(b.as_ptr(), (&mut f as *mut SetpointFrame).cast(), n);
        }
        f
    })
}

/// What the intake may take from `f` for axis `i`, given the tokens' last
/// sequence numbers (updated as the intake would).
fn expected(f: &SetpointFrame, last: &[(u64, u64, u64)], i: usize) -> Option<f64> {
    if f.layout_version != SETPOINT_LAYOUT || f.key != KEY || f.count as usize > MAX_AXES {
        return None;
    }
    let o = last.iter().find(|o| o.0 == f.token && f.token != 0)?;
    if f.seq <= o.1 {
        return None;
    }
    let lead = LEAD[i];
    let owns = |k: usize| o.2 & (1 << k) != 0;
    f.entries()
        .iter()
        .rev()
        .find(|e| e.axis as usize == lead && owns(lead) && owns(i))
        .map(|e| e.position)
}

#[test]
fn any_setpoint_frame_moves_only_what_its_owner_owns() {
    let mut runner = TestRunner::new(Config {
        cases: 512,
        failure_persistence: None,
        ..Config::default()
    });
    let frames = prop::collection::vec(prop_oneof![4 => frame(), 1 => bytes_frame()], 1..24);
    runner
        .run(&frames, |frames| {
            let mut s = StreamIntake::new(Some(KEY), &LEAD);
            assert!(s.grant(7, 0b0001) && s.grant(9, 0b0110));
            // (token, last seq, mask)
            let mut last = [(7u64, 0u64, 0b0001u64), (9, 0, 0b0110)];
            for f in &frames {
                s.begin_cycle();
                let want: Vec<Option<f64>> = (0..4).map(|i| expected(f, &last, i)).collect();
                let before = s.counts;
                s.take(f);
                let c = s.counts;
                prop_assert_eq!(c.frames, before.frames + 1);
                let refused = (c.refused_layout + c.refused_key + c.refused_count)
                    + (c.refused_token + c.refused_sequence)
                    - (before.refused_layout + before.refused_key + before.refused_count)
                    - (before.refused_token + before.refused_sequence);
                prop_assert!(refused <= 1, "a frame is refused once at most");
                for (i, w) in want.iter().enumerate() {
                    let got = s.setpoint(i).map(|p| p.position);
                    match w {
                        None => prop_assert!(got.is_none(), "axis {} moved by {:?}", i, f),
                        Some(p) => {
                            let g = got.expect("taken");
                            prop_assert!(g == *p || (g.is_nan() && p.is_nan()));
                        }
                    }
                }
                prop_assert!(s.setpoint(3).is_none(), "nobody owns axis 3");
                // the intake's view of the tokens' sequence numbers
                if let Some(o) = last.iter_mut().find(|o| o.0 == f.token) {
                    let ok = f.layout_version == SETPOINT_LAYOUT
                        && f.key == KEY
                        && f.count as usize <= MAX_AXES;
                    if ok && f.seq > o.1 {
                        o.1 = f.seq;
                    }
                }
            }
            Ok(())
        })
        .unwrap();
}

/// A program's setpoint through the cycle: the program-time step (any),
/// where (a walk or a jump), and cycles until the next.
#[derive(Clone, Debug)]
struct Timed {
    dt_ns: u64,
    step: f64,
    jump: Option<f64>,
    wait: u8,
}

fn timed() -> impl Strategy<Value = Timed> {
    let dt = prop_oneof![
        4 => (1u64..40).prop_map(|ms| ms * 1_000_000),
        1 => Just(1_000u64),
        1 => Just(3_600_000_000_000u64),
        1 => 1u64..100_000_000_000,
    ];
    (
        dt,
        -0.04..0.04f64,
        prop::option::weighted(0.05, -19.0..19.0f64),
        0u8..40,
    )
        .prop_map(|(dt_ns, step, jump, wait)| Timed {
            dt_ns,
            step,
            jump,
            wait,
        })
}

#[test]
fn no_timestamp_buys_a_faster_or_harder_command_through_the_cycle() {
    use super::ops_tests::{cmd, streaming, TOKEN};
    use super::testbench::Bench;
    let mut runner = TestRunner::new(Config {
        cases: 64,
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(&prop::collection::vec(timed(), 1..40), |inputs| {
            // X: max_speed 20, stream_acceleration 1000 (its stops brake
            // at that too: max_deceleration is 100), limits ±20, 1 ms.
            let mut b = streaming();
            let mut x = vec![cmd(&b)];
            let (mut t, mut p, mut seq) = (0u64, 0.0f64, 0u64);
            let one = |b: &mut Bench, x: &mut Vec<f64>| {
                b.cycle();
                x.push(cmd(b));
            };
            for s in &inputs {
                t = t.saturating_add(s.dt_ns);
                p = s.jump.unwrap_or((p + s.step).clamp(-19.0, 19.0));
                seq += 1;
                b.setpoint(TOKEN, seq, t, 0, p);
                one(&mut b, &mut x);
                for _ in 0..s.wait {
                    one(&mut b, &mut x);
                }
            }
            for _ in 0..100 {
                one(&mut b, &mut x);
            }
            let dt = 1e-3;
            for w in x.windows(3) {
                let (v0, v1) = ((w[1] - w[0]) / dt, (w[2] - w[1]) / dt);
                prop_assert!(v1.abs() <= 20.0 * (1.0 + 1e-9), "speed {v1}");
                let a = (v1 - v0).abs() / dt;
                prop_assert!(a <= 1000.0 * (1.0 + 1e-6), "acceleration {a}");
                prop_assert!(w[2].abs() <= 20.0 + 1e-9, "outside: {}", w[2]);
            }
            Ok(())
        })
        .unwrap();
}
