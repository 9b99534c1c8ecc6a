//! The profile the axis follows, sampled once per step.
//!
//! One step looks at the command state up to five times (the overtravel
//! direction, the search limit, the search travel, the output, the stop of
//! an abort). A sample is a pure function of the profile and the time, so
//! the first one of a step is remembered for that time and the others read
//! it back — the same numbers, bit for bit. The memory belongs to the
//! profile: replacing the profile ([`Followed::set`]) forgets it.

use crate::profile::{Kinematics, Profile};

#[derive(Clone, Copy, Debug)]
pub(super) struct Followed {
    profile: Profile,
    /// `(now, position, velocity)`: the last sample taken.
    memo: Option<(u64, f64, f64)>,
}

impl Followed {
    pub fn new(profile: Profile) -> Self {
        Self {
            profile,
            memo: None,
        }
    }

    /// Follow `profile` from now on.
    pub fn set(&mut self, profile: Profile) {
        self.profile = profile;
        self.memo = None;
    }

    /// Commanded position and velocity at `now`, remembered for `now`.
    #[inline]
    pub fn at(&mut self, now: u64) -> (f64, f64) {
        match self.memo {
            Some((t, p, v)) if t == now => (p, v),
            _ => {
                let (p, v) = self.profile.sample(now);
                self.memo = Some((now, p, v));
                (p, v)
            }
        }
    }

    /// As [`Followed::at`], for a caller that cannot remember.
    #[inline]
    pub fn sample(&self, now: u64) -> (f64, f64) {
        match self.memo {
            Some((t, p, v)) if t == now => (p, v),
            _ => self.profile.sample(now),
        }
    }

    /// Commanded position, velocity and acceleration at `now`: the exact
    /// state a re-plan starts from (the same position and velocity as
    /// [`Followed::at`], bit for bit).
    pub fn state(&self, now: u64) -> Kinematics {
        self.profile.state(now)
    }

    pub fn is_done(&self, now: u64) -> bool {
        self.profile.is_done(now)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_remembered_sample_is_the_sample_and_a_new_profile_forgets_it() {
        let jog = Profile::jog(0, 1.0, 0.0, 10.0, 100.0, 100.0);
        let mut f = Followed::new(jog);
        for now in [0, 7_000_000, 7_000_000, 250_000_000] {
            assert_eq!(f.at(now), jog.sample(now));
            assert_eq!(f.sample(now), jog.sample(now));
        }
        let hold = Profile::hold(250_000_000, -3.0);
        f.set(hold);
        assert_eq!(f.sample(250_000_000), (-3.0, 0.0));
        assert_eq!(f.at(250_000_000), (-3.0, 0.0));
    }
}
