//! Gantries: the sides of one machine axis homed in lockstep.
//!
//! Each side is its own engine with its own switch, marker or hard stop —
//! that is what squares the gantry — and its own `home_offset`. The
//! coordinator keeps `Request::hold` set on every side and clears it for
//! exactly one cycle when every side waits at rest before the same leg, so
//! every phase starts on all sides in the same cycle and the next phase
//! waits for all (a barrier per phase). Before the move to Home Position it
//! also sets `move_duration_ns` to the longest side's minimal move: the final
//! moves start together and end together.
//!
//! **Skew.** In a search leg every side stops on its own event. The
//! coordinator measures, in the common command frame (command travel since
//! the leg began, the same profile on every side), where each side found its
//! event. Once the first side has, the others must find theirs within
//! `max_skew` of further travel; otherwise every side is stopped at once
//! with ERR 1017 — before the gantry is racked further than `max_skew`.
//! The largest skew of the homing is reported.
//!
//! **One side fails, all stop.** A fault, stop, feedback loss or any other
//! error on one side stops every side still homing (ERR 12 / EXERR 1,
//! naming the side that failed).
//!
//! Pure and allocation-free per cycle (fixed arrays).

use motion_config::{GantryConfig, MAX_SIDES};
use motion_homing::codes::{ERR_GANTRY_SKEW, ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST};
use motion_homing::plan::{plan_for, Leg};
use motion_homing::AxisConfig;

use super::slot::AxisSlot;

/// What the coordinator asks of the sides this cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Decision {
    /// `Request::hold` for every side.
    pub hold: bool,
    /// `Request::move_duration_ns` for every side.
    pub move_duration_ns: u64,
    /// Sides to stop now, with the code they report.
    pub stop: [Option<(u16, u16)>; MAX_SIDES],
    /// The side whose failure stopped the others.
    pub failed_side: Option<usize>,
}

#[derive(Clone, Debug)]
pub struct GantryCoord {
    pub name: String,
    sides: [usize; MAX_SIDES],
    n: usize,
    max_skew: f64,
    cycle_ns: u64,
    /// Bit `k`: leg `k` of the sides' plan searches for an event.
    search_legs: u64,
    /// Bit `k`: leg `k` is the move to Home Position.
    move_legs: u64,
    homing: bool,
    released_leg: Option<u8>,
    start_cmd: [f64; MAX_SIDES],
    /// Command travel at which each side left the released search leg.
    left_at: [Option<f64>; MAX_SIDES],
    /// Largest skew measured in this homing.
    skew: Option<f64>,
    /// Stops already sent in this homing.
    stopped: bool,
}

impl GantryCoord {
    pub fn new(g: &GantryConfig, cfgs: &[AxisConfig], cycle_ns: u64) -> Self {
        let mut sides = [0; MAX_SIDES];
        let n = g.axes.len().min(MAX_SIDES);
        sides[..n].copy_from_slice(&g.axes[..n]);
        let (mut search_legs, mut move_legs) = (0u64, 0u64);
        if let Some(&first) = g.axes.first() {
            for (k, leg) in plan_for(&cfgs[first]).iter().enumerate().take(64) {
                if leg.goal().is_some() {
                    search_legs |= 1 << k;
                }
                if *leg == Leg::MoveHome {
                    move_legs |= 1 << k;
                }
            }
        }
        Self {
            name: g.name.clone(),
            sides,
            n,
            max_skew: g.max_skew,
            cycle_ns: cycle_ns.max(1),
            search_legs,
            move_legs,
            homing: false,
            released_leg: None,
            start_cmd: [0.0; MAX_SIDES],
            left_at: [None; MAX_SIDES],
            skew: None,
            stopped: false,
        }
    }

    pub fn sides(&self) -> &[usize] {
        &self.sides[..self.n]
    }

    /// Largest skew measured in the current (or last) homing, units.
    pub fn skew(&self) -> Option<f64> {
        self.skew
    }

    /// One cycle, before the engines step: the axes as the previous step
    /// left them.
    pub fn step(&mut self, axes: &[AxisSlot]) -> Decision {
        let mut d = Decision {
            hold: true,
            ..Decision::default()
        };
        let sides = &self.sides[..self.n];
        let any_ip = sides.iter().any(|&i| axes[i].status().ip);
        if !any_ip {
            self.homing = false;
            return d;
        }
        if !self.homing {
            // A new homing of the gantry.
            self.homing = true;
            self.released_leg = None;
            self.left_at = [None; MAX_SIDES];
            self.skew = None;
            self.stopped = false;
        }

        // One side failed: every other side still homing stops.
        if !self.stopped {
            if let Some(k) = sides.iter().position(|&i| axes[i].status().er) {
                self.stopped = true;
                d.failed_side = Some(sides[k]);
                for (j, &i) in sides.iter().enumerate() {
                    if j != k && axes[i].status().ip {
                        d.stop[j] = Some((ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST));
                    }
                }
                return d;
            }
        }

        // The barrier: release when every side waits before the same leg.
        let first = axes[sides[0]].status();
        let all_wait = sides.iter().all(|&i| {
            let s = axes[i].status();
            s.ip && s.waiting && s.leg == first.leg
        });
        if all_wait {
            d.hold = false;
            let leg = first.leg;
            if self.move_legs & (1u64 << (leg % 64)) != 0 {
                let longest = sides
                    .iter()
                    .map(|&i| axes[i].status().min_move_ns)
                    .max()
                    .unwrap_or(0);
                d.move_duration_ns = longest.div_ceil(self.cycle_ns) * self.cycle_ns;
            }
            self.released_leg = Some(leg);
            for (j, &i) in sides.iter().enumerate() {
                self.start_cmd[j] = axes[i].command().position;
                self.left_at[j] = None;
            }
            return d;
        }

        // Skew in a released search leg, in the common command frame.
        let Some(leg) = self.released_leg else {
            return d;
        };
        if self.search_legs & (1u64 << (leg % 64)) == 0 {
            return d;
        }
        for (j, &i) in sides.iter().enumerate() {
            let s = axes[i].status();
            if self.left_at[j].is_none() && (s.leg > leg || !s.ip) && !s.waiting {
                self.left_at[j] = Some((axes[i].command().position - self.start_cmd[j]).abs());
            }
        }
        let mut lo = f64::INFINITY;
        let mut hi = 0.0f64;
        let mut found = 0;
        for t in self.left_at[..self.n].iter().flatten() {
            lo = lo.min(*t);
            hi = hi.max(*t);
            found += 1;
        }
        if found == 0 {
            return d;
        }
        if found == self.n {
            let skew = hi - lo;
            self.skew = Some(self.skew.map_or(skew, |s: f64| s.max(skew)));
            self.released_leg = None;
        }
        // A side still searching beyond the first event + max_skew: racked.
        let beyond = sides.iter().enumerate().any(|(j, &i)| {
            self.left_at[j].is_none()
                && (axes[i].command().position - self.start_cmd[j]).abs() > lo + self.max_skew
        });
        if beyond || (found == self.n && hi - lo > self.max_skew) {
            if beyond {
                self.skew = Some(
                    self.skew
                        .map_or(self.max_skew, |s: f64| s.max(self.max_skew)),
                );
            }
            self.stopped = true;
            for (j, &i) in sides.iter().enumerate() {
                if axes[i].status().ip {
                    d.stop[j] = Some((ERR_GANTRY_SKEW, 0));
                }
            }
        }
        d
    }
}
