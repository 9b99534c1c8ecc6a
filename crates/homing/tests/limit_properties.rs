//! Property tests of homing with limit switches: random layouts (limits,
//! hard stops, home switch, markers), speeds, cycle times and start
//! positions anywhere between the hard stops — on a limit, on the switch,
//! on either side of it.
//!
//! * homing succeeds from any start position inside the travel: the
//!   limit-switch sequences, and the switch sequences with
//!   `home_reverse_at_limit`, end homed at Home Position, off both limits
//!   (`limit_switch_then_marker` also with no offset: on its marker);
//! * the event never differs from the reference by more than ½·R·T for a
//!   sampled edge (R the return speed, T the cycle) and by nothing for a
//!   latched one (marker, registration: the plant latches the exact
//!   boundary; over the frames it is one count, see the e2e tests).
//!
//! The worst event error is printed (`-- --nocapture`) as a fraction of R·T.

mod common;

use common::run;
use motion_homing::*;
use motion_plant::{Markers, PlantConfig, RegistrationInput};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::cell::{Cell, RefCell};

#[derive(Clone, Debug)]
struct Layout {
    sequence: HomeSequence,
    positive: bool,
    cycle: f64,
    home_speed: f64,
    return_speed: f64,
    accel: f64,
    decel: f64,
    /// Limit switch ends.
    lo: f64,
    hi: f64,
    /// Room between a limit's end and its hard stop beyond what a seek
    /// needs to stop.
    extra_zone: f64,
    /// Where the switch lies between the limits, 0..1.
    sw_at: f64,
    sw_width: f64,
    marker_every: f64,
    marker_phase: f64,
    nc_limits: bool,
    registration: bool,
    /// Start between the hard stops, 0..1.
    start_at: f64,
    /// |Home Offset|.
    offset: f64,
}

fn layout() -> impl Strategy<Value = Layout> {
    use HomeSequence::*;
    (
        (
            prop::sample::select(
                &[LimitSwitch, LimitSwitchThenMarker, Switch, SwitchThenMarker][..],
            ),
            any::<bool>(),
            prop::sample::select(&[0.0005, 0.001, 0.002][..]),
            10.0..40.0f64,
            0.1..1.0f64,
            200.0..5000.0f64,
            200.0..5000.0f64,
        ),
        (
            -100.0..-80.0f64,
            80.0..100.0f64,
            0.1..10.0f64,
            0.0..1.0f64,
            1.0..10.0f64,
            1.0..20.0f64,
            0.0..1.0f64,
        ),
        (any::<bool>(), any::<bool>(), 0.0..1.0f64, 0.01..5.0f64),
    )
        .prop_map(
            |(
                (sequence, positive, cycle, home_speed, rf, accel, decel),
                (lo, hi, extra_zone, sw_at, sw_width, marker_every, marker_phase),
                (nc_limits, registration, start_at, offset),
            )| Layout {
                return_speed: home_speed * rf,
                sequence,
                positive,
                cycle,
                home_speed,
                accel,
                decel,
                lo,
                hi,
                extra_zone,
                sw_at,
                sw_width,
                marker_every,
                marker_phase,
                nc_limits,
                registration,
                start_at,
                offset,
            },
        )
}

impl Layout {
    fn direction(&self) -> HomeDirection {
        if self.positive {
            HomeDirection::BidirectionalForward
        } else {
            HomeDirection::BidirectionalReverse
        }
    }

    /// How far past a switch a seek at V comes to rest, at most.
    fn seek_overrun(&self) -> f64 {
        self.home_speed * self.home_speed / (2.0 * self.decel) + 2.0 * self.home_speed * self.cycle
    }

    fn hard_stops(&self) -> (f64, f64) {
        let z = self.seek_overrun() + self.extra_zone;
        (self.lo - z, self.hi + z)
    }

    /// The home switch, far enough from both limits for a seek's stop, a
    /// marker spacing and the offset.
    fn switch(&self) -> (f64, f64) {
        let clearance = self.seek_overrun() + self.marker_every + 6.0;
        let room = self.hi - self.lo - 2.0 * clearance - self.sw_width;
        let lo = self.lo + clearance + self.sw_at * room;
        (lo, lo + self.sw_width)
    }

    fn start(&self) -> f64 {
        let (a, b) = self.hard_stops();
        a + self.start_at * (b - a)
    }

    fn markers(&self) -> Markers {
        Markers::new(self.marker_phase * self.marker_every, self.marker_every)
    }

    fn config(&self) -> AxisConfig {
        let s = self.direction().sign();
        let (a, b) = self.hard_stops();
        let limit = self.sequence.uses_limit_switch();
        AxisConfig {
            counts_per_unit: 1000.0,
            marker: true,
            registration: self.registration,
            home_direction: self.direction(),
            home_sequence: self.sequence,
            home_reverse_at_limit: !limit,
            // Two fifths of the limit-then-marker homes rest on the marker
            // itself (CiA 402 methods 1 and 2 as commonly used); else into
            // the travel for a limit, by more than a cycle of travel at R
            // (validation's margin for a limit's edge); either way for the
            // switch.
            home_offset: if self.sequence == HomeSequence::LimitSwitchThenMarker
                && self.offset < 2.0
            {
                0.0
            } else if limit || self.start_at < 0.5 {
                -s * (self.offset + self.return_speed * self.cycle)
            } else {
                s * self.offset
            },
            home_speed: self.home_speed,
            home_return_speed: self.return_speed,
            home_acceleration: self.accel,
            home_deceleration: self.decel,
            travel_limits: Some((a, b)),
            cycle_ns: (self.cycle * 1e9).round() as u64,
            ..AxisConfig::default()
        }
    }

    fn plant(&self) -> PlantConfig {
        let registration_input = match (self.sequence.uses_limit_switch(), self.positive) {
            (false, _) => RegistrationInput::HomeSwitch,
            (true, true) => RegistrationInput::PositiveLimit,
            (true, false) => RegistrationInput::NegativeLimit,
        };
        PlantConfig {
            start: self.start(),
            switch: Some(self.switch()),
            marker_every: self.marker_every,
            marker_at: self.marker_phase * self.marker_every,
            hard_stop: Some(self.hard_stops()),
            overtravel: Some((self.lo, self.hi)),
            limit_switches_normally_closed: self.nc_limits,
            registration_input,
            ..PlantConfig::default()
        }
    }

    /// The switch edge the sequence keys on (its clear point on the return
    /// leg), and the first marker beyond it into the travel.
    fn edge(&self) -> f64 {
        let (sw_lo, sw_hi) = self.switch();
        match (self.sequence.uses_limit_switch(), self.positive) {
            (true, true) => self.hi,
            (true, false) => self.lo,
            (false, true) => sw_lo,
            (false, false) => sw_hi,
        }
    }

    fn marker_after_edge(&self) -> f64 {
        let m = self.markers();
        let e = self.edge();
        let next = if self.positive {
            m.next_below(e)
        } else {
            m.next_above(e)
        };
        next.unwrap()
    }
}

#[test]
fn homing_succeeds_from_any_start_and_the_event_is_within_its_bound() {
    let worst = RefCell::new((0.0f64, String::new()));
    let cases = Cell::new([0usize; 3]);
    TestRunner::new(Config {
        cases: 192,
        failure_persistence: None,
        ..Config::default()
    })
    .run(&layout(), |m| {
        let cfg = m.config();
        prop_assert!(validate(&cfg).is_empty(), "{:?}", validate(&cfg));
        let marker = m.sequence.uses_marker();
        let edge = m.edge();
        // A marker within the edge's sampling uncertainty is ambiguous by
        // nature; installations keep them apart.
        let clearance = {
            let mk = m.markers();
            let a = mk.next_above(edge).map_or(f64::MAX, |x| x - edge);
            let b = mk.next_below(edge).map_or(f64::MAX, |x| edge - x);
            a.min(b)
        };
        prop_assume!(!marker || clearance > 2.0 * m.return_speed * m.cycle);
        let (truth, tol) = if marker {
            (m.marker_after_edge(), 1e-9)
        } else if m.registration {
            (edge, 1e-9)
        } else {
            (edge, m.return_speed * m.cycle / 2.0 + 1e-9)
        };
        let o = run(cfg, m.plant(), m.cycle, 600.0);
        let st = o.status;
        prop_assert!(st.homed && st.pc && !st.er, "{st:?}");
        prop_assert_eq!(st.implausible, Implausible::default());
        let Some(e) = st.event_raw else {
            return Err(TestCaseError::fail("no event"));
        };
        let error = (e - truth).abs();
        prop_assert!(error <= tol, "event {e}, reference {truth}, bound {tol}");
        if !marker && !m.registration {
            let frac = error / (m.return_speed * m.cycle);
            if frac > worst.borrow().0 {
                *worst.borrow_mut() = (frac, format!("{m:?}"));
            }
        }
        let rest = e + cfg.home_offset;
        prop_assert!((o.final_raw - rest).abs() <= 1e-9 * (1.0 + rest.abs()));
        prop_assert!((o.final_axis - cfg.home_position).abs() <= 1e-6);
        prop_assert!(m.lo < o.final_raw && o.final_raw < m.hi, "rests on a limit");
        let mut n = cases.get();
        n[usize::from(st.reversed_at_limit)] += 1;
        n[2] += usize::from(m.sequence.uses_limit_switch() && cfg.home_offset == 0.0);
        cases.set(n);
        Ok(())
    })
    .unwrap();
    let (frac, case) = worst.take();
    let n = cases.get();
    println!(
        "limit switches: worst sampled event error {frac:.3} x R x T (bound 0.5); \
         {} runs without and {} with a reversal at a limit, {} on a limit's marker with no \
         offset; case {case}",
        n[0], n[1], n[2]
    );
    assert!(
        n[1] > 0 && n[2] > 0,
        "no case reversed, or none homed on a limit's marker with no offset: the layouts miss \
         what they test"
    );
}
