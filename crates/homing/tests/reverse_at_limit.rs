//! `home_reverse_at_limit`: a bidirectional switch (then marker) search that
//! meets the limit switch in Home Direction before the home switch
//! reverses, passes the home switch, stops, and searches again from the
//! near side — so the event is the one a near-side start finds.
//!
//! The machine (raw units), as in `limit_sequences.rs`:
//!
//! ```text
//!   hard stop -100 | negative limit ≤ -90 | switch [0, 5] | positive limit ≥ 90 | hard stop +100
//!   markers every 10 at 2.5; V = 20, R = 2, A = D = 500, T = 1 ms; V²/2D = 0.4
//! ```
//!
//! Events, the same from every start (near side, on the switch, far side,
//! on either limit):
//!
//! * forward: the seek detects the switch's near edge 0, the return leg at R
//!   clears it going negative: switch 0 ± R·T/2 = 0.001; then marker -7.5.
//! * reverse: near edge 5, cleared going positive: 5 ± 0.001; marker 12.5.
//!
//! A far-side start forward from 50: seek +20 to the limit at 90 (40 units,
//! 2 s), stop on it (0.4 + ≤ 0.04: rest ≈ 90.42), run back at 20 until the
//! switch has been passed (actuated at 5, released strictly below 0), stop
//! 0.4 further (≈ -0.42), seek +20 again: the near edge 0 as from a
//! near-side start. The run back is ≈ 90.84 units long, the whole search
//! ≈ 131 units.

mod common;

use common::{limit_machine_at as plant, run};
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::PlantConfig;

const T: f64 = 0.001;
const SAMPLED: f64 = 2.0 * T / 2.0 + 1e-9;
const EXACT: f64 = 1e-9;

use HomeDirection::*;
use HomeSequence::*;

fn axis(seq: HomeSequence, dir: HomeDirection) -> AxisConfig {
    AxisConfig {
        home_reverse_at_limit: true,
        ..common::axis(seq, dir)
    }
}

/// The event of a near-side start.
fn near_side_event(seq: HomeSequence, dir: HomeDirection) -> (f64, f64) {
    match (seq, dir) {
        (Switch, BidirectionalForward) => (0.0, SAMPLED),
        (Switch, _) => (5.0, SAMPLED),
        (_, BidirectionalForward) => (-7.5, EXACT),
        _ => (12.5, EXACT),
    }
}

#[test]
fn every_start_position_ends_on_the_near_side_event() {
    let mut failures = Vec::new();
    for seq in [Switch, SwitchThenMarker] {
        for dir in [BidirectionalForward, BidirectionalReverse] {
            let s = dir.sign();
            let (event, tol) = near_side_event(seq, dir);
            // (start, reverses): the far side and the limit in Home
            // Direction reverse; the near side, the switch and the other
            // limit (the seek leaves it towards the switch) do not.
            for (start, reverses) in [
                (-50.0 * s, false),
                (2.0, false),
                (50.0 * s, true),
                (95.0 * s, true),
                (-95.0 * s, false),
            ] {
                let o = run(axis(seq, dir), plant(start), T, 300.0);
                let st = o.status;
                let e = st.event_raw.unwrap_or(f64::NAN);
                eprintln!(
                    "{seq} {dir} from {start:>6}: pc {} err {}/{} reversed {} event {e:.4} rest {:.4}",
                    st.pc, st.err, st.exerr, st.reversed_at_limit, o.final_raw
                );
                let ok = st.pc
                    && st.homed
                    && st.reversed_at_limit == reverses
                    && (e - event).abs() <= tol
                    && (o.final_raw - e).abs() <= 1e-9;
                if !ok {
                    failures.push(format!("{seq} {dir} from {start}: {st:?}"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// The search limit bounds each leg of the search from where the leg began
/// — the seek to the limit, the run back past the switch, the new seek —
/// not their sum; `home_timeout` bounds the whole.
#[test]
fn the_search_limit_counts_each_leg_and_the_timeout_the_whole() {
    let far = |f: &dyn Fn(&mut AxisConfig)| {
        let mut c = axis(Switch, BidirectionalForward);
        f(&mut c);
        run(c, plant(50.0), T, 300.0).status
    };
    // search_limit 100: seek 40, run back ≈ 90.84, new seek ≈ 0.42: each
    // below 100, together ≈ 131 above it: homes.
    let st = far(&|c| c.search_limit = 100.0);
    assert!(st.pc && st.reversed_at_limit, "{st:?}");
    // search_limit 80: the run back is longer: 1016 / 11 (reverse).
    let st = far(&|c| c.search_limit = 80.0);
    assert_eq!(
        (st.err, st.exerr),
        (ERR_SEARCH_LIMIT, EX_SEARCH_REVERSE),
        "{st:?}"
    );
    assert!(st.reversed_at_limit && !st.homed);
    // search_limit 30: the seek from 50 never reaches the limit at 90.
    let st = far(&|c| c.search_limit = 30.0);
    assert_eq!(
        (st.err, st.exerr),
        (ERR_SEARCH_LIMIT, EX_SEARCH_SEEK),
        "{st:?}"
    );
    assert!(!st.reversed_at_limit);
    // The whole search takes ≈ 2 + 0.04 + 4.6 + 0.04 + … s: a 4 s timeout
    // ends it during the run back (1015), 20 s is enough.
    let st = far(&|c| c.home_timeout = 4.0);
    assert_eq!((st.err, st.exerr), (ERR_TIMEOUT, 0), "{st:?}");
    assert!(st.reversed_at_limit && !st.homed);
    let st = far(&|c| c.home_timeout = 20.0);
    assert!(st.pc, "{st:?}");
}

/// A reversal happens once, and only at the limit in Home Direction.
#[test]
fn limits_the_reversal_does_not_excuse() {
    // No home switch between the limits (it lies inside the positive limit's
    // range): the run back meets the negative limit: overtravel.
    let p = PlantConfig {
        switch: Some((95.0, 98.0)),
        ..plant(0.0)
    };
    let st = run(axis(Switch, BidirectionalForward), p, T, 300.0).status;
    assert_eq!(
        (st.err, st.exerr),
        (ERR_SERVO_MESSAGE, EX_OVERTRAVEL),
        "{st:?}"
    );
    assert!(st.reversed_at_limit && !st.homed);
    // The move home into the other limit is an overtravel too: switch
    // reverse, event 5, offset -96 puts Home Position at -91.
    let c = AxisConfig {
        home_offset: -96.0,
        ..axis(Switch, BidirectionalReverse)
    };
    let st = run(c, plant(-50.0), T, 300.0).status;
    assert_eq!(
        (st.err, st.exerr),
        (ERR_SERVO_MESSAGE, EX_OVERTRAVEL),
        "{st:?}"
    );
    assert!(st.reversed_at_limit, "{st:?}");
}

#[test]
fn sequences_that_cannot_reverse_are_refused() {
    let refused = |seq, dir, mode| {
        let c = AxisConfig {
            home_mode: mode,
            ..axis(seq, dir)
        };
        let st = run(c, plant(0.0), T, 10.0).status;
        assert_eq!(
            (st.err, st.exerr),
            (ERR_ILLEGAL_HOMING_CONFIG, EX_REVERSE_NOT_APPLICABLE),
            "{seq} {dir} {mode}: {st:?}"
        );
    };
    // A unidirectional search cannot reverse (without the key it stops at a
    // limit with 12 / 43, see limit_sequences.rs); nor can sequences
    // without a home switch search, nor a passive one.
    refused(Switch, UnidirectionalForward, HomeMode::Active);
    refused(SwitchThenMarker, UnidirectionalReverse, HomeMode::Active);
    refused(Marker, BidirectionalForward, HomeMode::Active);
    refused(Torque, BidirectionalForward, HomeMode::Active);
    refused(LimitSwitch, BidirectionalReverse, HomeMode::Active);
    refused(Switch, BidirectionalForward, HomeMode::Passive);
    let c = AxisConfig {
        limit_switches: false,
        ..axis(Switch, BidirectionalForward)
    };
    let problems: Vec<u16> = validate(&c).iter().map(|e| e.exerr).collect();
    assert_eq!(problems, [EX_NO_LIMIT_SWITCHES]);
}
