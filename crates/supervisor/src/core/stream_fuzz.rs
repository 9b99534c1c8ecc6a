//! Issue 15, fuzzed like the frame decoding: setpoint frames of any content
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
//!   `motion-homing`'s stream checks and the core's fuzz below).

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
