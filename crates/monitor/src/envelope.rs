//! The speed bound over time: the cap that applies now, and after the cap
//! drops (a stop, a slower operation, the reference lost) a bound that
//! decays from the speed allowed before at the deceleration allowed — the
//! ramp monitoring of a safe stop 1 (IEC 61800-5-2 SS1-r): a stop may take
//! the time its deceleration needs, no longer.
//!
//! The decay starts at the cycle that saw the cap drop (a stop planned in
//! that cycle starts there), and a cycle's command is judged by the bound
//! at the *start* of its interval: the average speed over an interval of
//! a stop that began at `t_s` is at most `v − d·(t_start − t_s)`.

use motion_homing::time::ns_to_s;

#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Envelope {
    /// The bound at the end of the last cycle judged, units/s.
    value: f64,
    /// The cap in force in that cycle: it holds until this one.
    cap: f64,
    /// What is left of the hold after the last drop, ns: an S-curve's
    /// stop builds its deceleration up at its jerk before it reaches it.
    held_ns: u64,
}

impl Envelope {
    #[cfg(test)]
    fn advance0(&mut self, cap: f64, decel: f64, dt_ns: u64) {
        self.advance(cap, decel, dt_ns, 0)
    }

    /// The bound for the interval that ends now: the cap, or the decaying
    /// bound at the interval's start.
    pub fn interval(&self, cap: f64) -> f64 {
        cap.max(self.value)
    }

    /// The bound at the end of this cycle's interval (after
    /// [`Envelope::advance`]): what the command's velocity may be now.
    pub fn now(&self) -> f64 {
        self.value
    }

    /// Moves the bound to the end of an interval of `dt_ns` with `cap` in
    /// force and deceleration `decel` allowed: the cap, the cap of the
    /// cycle before (a stop that begins now begins from it), or what
    /// decayed from the bound before. A drop of the cap starts a hold of
    /// `hold_ns` (0 for a trapezoid) during which the bound does not
    /// decay: a jerk-limited stop's speed stays above the line
    /// `v − decel·(t − hold)` it then follows, never above the cap.
    pub fn advance(&mut self, cap: f64, decel: f64, dt_ns: u64, hold_ns: u64) {
        if cap < self.cap {
            self.held_ns = hold_ns;
        }
        let held = self.held_ns.min(dt_ns);
        self.held_ns -= held;
        let decayed = self.value - decel * ns_to_s(dt_ns - held);
        let decayed = if decayed.is_nan() { 0.0 } else { decayed };
        self.value = cap.max(self.cap).max(decayed);
        self.cap = cap;
    }

    /// Nothing may move any more: the bound has decayed to a cap of 0.
    pub fn at_rest(&self) -> bool {
        self.value <= 0.0
    }

    /// Starts again from rest (after a trip was reset).
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    #[test]
    fn a_dropped_cap_decays_from_the_cycle_after_it_dropped() {
        let mut e = Envelope::default();
        e.advance0(20.0, 500.0, MS);
        assert_eq!((e.interval(0.0), e.now()), (20.0, 20.0));
        // the stop is seen: the interval before it and its own first
        // interval keep the speed allowed before
        e.advance0(0.0, 500.0, MS);
        assert_eq!(e.now(), 20.0);
        assert_eq!(e.interval(0.0), 20.0);
        e.advance0(0.0, 500.0, MS);
        assert!((e.now() - 19.5).abs() < 1e-12);
        for _ in 0..39 {
            e.advance0(0.0, 500.0, MS);
        }
        assert!(e.at_rest(), "{}", e.now());
        // a cap that rises again is the bound at once
        e.advance0(5.0, 500.0, MS);
        assert_eq!(e.now(), 5.0);
        // a second drop while the first decays: the cap in force until now
        // decays from now on
        let mut e = Envelope::default();
        e.advance0(20.0, 500.0, MS);
        e.advance0(10.0, 500.0, MS);
        e.advance0(10.0, 500.0, MS);
        assert_eq!(e.now(), 19.5);
        e.advance0(10.0, 500.0, 10 * MS);
        assert_eq!(e.now(), 14.5);
        e.advance0(1.0, 500.0, 10 * MS);
        assert_eq!(e.now(), 10.0);
        e.advance0(1.0, 500.0, MS);
        assert_eq!(e.now(), 9.5);
    }

    #[test]
    fn a_jerk_limited_stop_is_allowed_its_ramp_in() {
        // 20 u/s, decel 500, hold 30 ms: 30 ms at 20, then 500 u/s².
        let mut e = Envelope::default();
        e.advance(20.0, 500.0, MS, 30 * MS);
        for _ in 0..30 {
            e.advance(0.0, 500.0, MS, 30 * MS);
        }
        assert_eq!(e.now(), 20.0);
        e.advance(0.0, 500.0, MS, 30 * MS);
        assert!((e.now() - 19.5).abs() < 1e-12, "{}", e.now());
        // an S-curve stop (jerk 20 000, from cruise: ramp-in 25 ms) stays
        // under the bound with hold (accel + decel / 2) / jerk
        let (v0, d, j) = (20.0f64, 500.0f64, 20_000.0f64);
        let hold = ((500.0 + d / 2.0) / j * 1e9) as u64;
        let mut e = Envelope::default();
        e.advance(v0, d, MS, hold);
        let (mut v, mut a) = (v0, 0.0f64);
        for _ in 0..200 {
            a = (a + j * 1e-3).min(d);
            v = (v - a * 1e-3).max(0.0);
            e.advance(0.0, d, MS, hold);
            assert!(v <= e.now() + 1e-9, "{v} above {}", e.now());
        }
    }
}
