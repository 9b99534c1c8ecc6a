//! The oracle: what must hold every cycle, judged from the plant's truth
//! (its position, its power stage), the enable request the frame carried
//! to it, the configuration, and what the test itself asked for — never
//! from the engine's status or the monitor's verdict.

use super::rig::Rig;
use super::states::{State, HOME_DECEL, LIMITS, MAX_ACCEL, MAX_DECEL, MAX_SPEED, REFERENCE};

/// One cycle, s.
const T: f64 = 1e-3;
/// A position the drive cannot tell apart (two counts at 1e6 per unit).
const COUNT: f64 = 2e-6;

pub struct Oracle {
    /// The test asked for the power stage since it was last taken away.
    may_power: bool,
    /// Until this cycle the enable request may still be on after it was
    /// taken away (the cycles that carry the news to the engine and its
    /// answer to the drive; a gone drive's time away).
    grace_until: u64,
    /// From this cycle on the axis is at rest.
    rest_by: Option<u64>,
    /// The soft limits apply (the machine's reference stands).
    limits: bool,
    /// A limit switch tripped: its direction, where, at what speed.
    switch: Option<(bool, f64, f64)>,
    early: Option<String>,
}

impl Oracle {
    pub fn new(state: State) -> Self {
        Self {
            may_power: !matches!(state, State::Faulted | State::Disabled),
            grace_until: 0,
            rest_by: None,
            limits: true,
            switch: None,
            early: None,
        }
    }

    /// The plant's speed in the last cycle, units/s.
    pub fn speed(r: &Rig) -> f64 {
        match r.trail {
            [Some((a, _)), Some((b, _)), _] => (a - b).abs() / T,
            _ => 0.0,
        }
    }

    /// The direction the plant moves in (positive?), if it moves.
    pub fn direction(r: &Rig) -> Option<bool> {
        match r.trail {
            [Some((a, _)), Some((b, _)), _] if a != b => Some(a > b),
            _ => None,
        }
    }

    /// The test asked for the power stage (enable, home, a motion).
    pub fn asked_power(&mut self) {
        self.may_power = true;
    }

    /// The power stage was taken away (or must go: a disable); the enable
    /// request may stay on until cycle `until`.
    pub fn power_lost(&mut self, until: u64) {
        self.may_power = false;
        self.grace_until = until;
    }

    /// A disable: the power stage off by cycle `by`.
    pub fn power_off_by(&mut self, by: u64) {
        self.power_lost(by);
    }

    pub fn rest_by(&mut self, by: u64) {
        self.rest_by = Some(self.rest_by.map_or(by, |b| b.min(by)));
    }

    /// Homing was asked for: its searches run without soft limits (the
    /// reference is being established again; a search is bounded by its
    /// search limit and the limit switches).
    pub fn homing(&mut self) {
        self.limits = false;
    }

    /// The operator cleared the reference: the soft limits are off by
    /// design (a jog runs on under the unhomed cap).
    pub fn unhomed(&mut self) {
        self.limits = false;
    }

    pub fn switch_tripped(&mut self, r: &Rig, positive: bool, _k: u64) {
        let v = reached(Self::speed(r), 0);
        self.switch = Some((positive, r.plant().position(), v));
    }

    /// A violation found while the event was still being applied.
    pub fn early(&mut self, e: String) {
        self.early.get_or_insert(e);
    }

    /// The deadline of rest, for the run's length.
    pub fn rest_deadline(&self) -> Option<u64> {
        self.rest_by
    }

    /// Every cycle.
    pub fn check(&mut self, r: &Rig) -> Result<(), String> {
        if let Some(e) = self.early.take() {
            return Err(e);
        }
        let k = r.k();
        let plant = r.plant();
        let x = plant.position();
        let on = plant.feedback().drive.enabled;
        let asked = r.enable_sent();
        if (on || asked) && !self.may_power && k > self.grace_until {
            return Err(format!(
                "power stage {} without a request since it was taken away (cycle {k})",
                if on { "on" } else { "asked on" }
            ));
        }
        let tol = REFERENCE + COUNT;
        if self.limits && !(LIMITS.0 - tol..=LIMITS.1 + tol).contains(&x) {
            return Err(format!("at {x}, beyond a soft limit {LIMITS:?}"));
        }
        if let Some((positive, at, v)) = self.switch {
            let beyond = if positive { x - at } else { at - x };
            let allowed = v * v / (2.0 * MAX_DECEL.min(HOME_DECEL)) + 3.0 * v * T + COUNT;
            if beyond > allowed {
                return Err(format!(
                    "{beyond} beyond the limit switch tripped at {at} (at most {allowed})"
                ));
            }
        }
        self.motion(r, k)
    }

    /// Speed, acceleration (while the drive followed its command in the
    /// three cycles) and rest, from the plant's positions.
    fn motion(&self, r: &Rig, k: u64) -> Result<(), String> {
        let [Some((x, on)), Some((x1, on1)), x2] = r.trail else {
            return Ok(());
        };
        let v = (x - x1) / T;
        if v.abs() > MAX_SPEED * (1.0 + 1e-6) + 2.0 * COUNT / T {
            return Err(format!(
                "moving at {v} units/s, above max_speed {MAX_SPEED}"
            ));
        }
        if let Some(by) = self.rest_by.filter(|&b| k > b) {
            if (x - x1).abs() > COUNT {
                return Err(format!(
                    "moving at {v} units/s at cycle {k}, at rest due by {by}"
                ));
            }
        }
        if let Some((x2, on2)) = x2.filter(|_| on && on1) {
            let a = (x - 2.0 * x1 + x2) / (T * T);
            if on2 && a.abs() > MAX_ACCEL * (1.0 + 1e-6) + 4.0 * COUNT / (T * T) {
                return Err(format!("accelerating at {a} units/s², above {MAX_ACCEL}"));
            }
        }
        Ok(())
    }

    /// At the end of the run: the rest that was due was seen.
    pub fn finish(&self, r: &Rig) -> Result<(), String> {
        match self.rest_by {
            Some(by) if r.k() <= by + 1 => Err(format!(
                "the run ended at {} before rest was due at {by}",
                r.k()
            )),
            _ => Ok(()),
        }
    }
}

/// The speed a motion seen at `v` may have reached by the time the engine
/// acts on an event `delay` cycles later (plus the two that carry it),
/// accelerating at the most the axis allows, never beyond `max_speed`.
pub fn reached(v: f64, delay: u64) -> f64 {
    (v.abs() + MAX_ACCEL * (delay + 2) as f64 * 1e-3).min(MAX_SPEED)
}

/// Cycles a stop from a motion seen at `v` at deceleration `d` may take
/// once the engine acts on the event `delay` cycles later: the delay, the
/// two cycles that carry the event, the stop (rounded up), one of rounding.
pub fn stop_cycles(v: f64, d: f64, delay: u64) -> u64 {
    delay + (reached(v, delay) / d * 1000.0).ceil() as u64 + 3
}
