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
}

impl Envelope {
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
    /// decayed from the bound before.
    pub fn advance(&mut self, cap: f64, decel: f64, dt_ns: u64) {
        let decayed = self.value - decel * ns_to_s(dt_ns);
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
        e.advance(20.0, 500.0, MS);
        assert_eq!((e.interval(0.0), e.now()), (20.0, 20.0));
        // the stop is seen: the interval before it and its own first
        // interval keep the speed allowed before
        e.advance(0.0, 500.0, MS);
        assert_eq!(e.now(), 20.0);
        assert_eq!(e.interval(0.0), 20.0);
        e.advance(0.0, 500.0, MS);
        assert!((e.now() - 19.5).abs() < 1e-12);
        for _ in 0..39 {
            e.advance(0.0, 500.0, MS);
        }
        assert!(e.at_rest(), "{}", e.now());
        // a cap that rises again is the bound at once
        e.advance(5.0, 500.0, MS);
        assert_eq!(e.now(), 5.0);
        // a second drop while the first decays: the cap in force until now
        // decays from now on
        let mut e = Envelope::default();
        e.advance(20.0, 500.0, MS);
        e.advance(10.0, 500.0, MS);
        e.advance(10.0, 500.0, MS);
        assert_eq!(e.now(), 19.5);
        e.advance(10.0, 500.0, 10 * MS);
        assert_eq!(e.now(), 14.5);
        e.advance(1.0, 500.0, 10 * MS);
        assert_eq!(e.now(), 10.0);
        e.advance(1.0, 500.0, MS);
        assert_eq!(e.now(), 9.5);
    }
}
