//! A planned motion as data: constant-jerk segments from a start time,
//! then an exact hold or a cruise, and its sampling.
//!
//! A trapezoid's segments have zero jerk and are sampled with the same
//! expressions as before jerk existed (`p0 + v0·τ + ½·a·τ²`), so a
//! trapezoidal profile samples bit for bit as it always did. A segment
//! with jerk adds the cubic term.

/// Segments a profile holds at most: an S-curve move from a state it must
/// first stop from (3), then up to its peak speed (3), a cruise (1) and
/// down to rest (3).
pub(super) const MAX_SEGMENTS: usize = 10;

/// Position, velocity and acceleration at one instant (units, units/s,
/// units/s²): what a profile returns when sampled, and what a re-plan
/// starts from so that the new profile continues the old one without a
/// step in any of them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kinematics {
    pub p: f64,
    pub v: f64,
    pub a: f64,
}

impl Kinematics {
    /// At rest at `p`.
    pub fn rest(p: f64) -> Self {
        Self { p, v: 0.0, a: 0.0 }
    }

    /// Position and velocity only (a trapezoid's re-plan ignores the
    /// acceleration: it may step).
    pub fn moving(p: f64, v: f64) -> Self {
        Self { p, v, a: 0.0 }
    }

    pub fn is_finite(&self) -> bool {
        self.p.is_finite() && self.v.is_finite() && self.a.is_finite()
    }

    pub fn at_rest(&self) -> bool {
        self.v == 0.0 && self.a == 0.0
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Segment {
    /// Time from the profile's start at which the segment begins, s.
    pub t0: f64,
    /// State at the beginning of the segment.
    pub p0: f64,
    pub v0: f64,
    pub a0: f64,
    /// Constant jerk over the segment, units/s³ (0 for a trapezoid's).
    pub j: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum End {
    /// After the segments, stay exactly here.
    Hold(f64),
    /// After the segments, keep the final velocity forever (a jog).
    Cruise,
}

/// A planned motion. `Copy`, fixed size, no heap: the cycle samples it
/// ([`Profile::sample`], [`Profile::state`]) with a bounded scan of at
/// most [`MAX_SEGMENTS`] start times and one polynomial.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    pub(super) start_ns: u64,
    pub(super) segs: [Segment; MAX_SEGMENTS],
    pub(super) n: usize,
    /// State at the end of the last segment.
    pub(super) p_end: f64,
    pub(super) v_end: f64,
    pub(super) t_end: f64,
    pub(super) end: End,
}

/// Builds the segment list while tracking the state at its end.
pub(super) struct Builder {
    segs: [Segment; MAX_SEGMENTS],
    n: usize,
    pub t: f64,
    pub p: f64,
    pub v: f64,
    pub a: f64,
}

/// A duration a builder keeps: positive and finite. Others are rounding
/// leftovers of a zero-length phase (or nonsense) and are dropped.
fn keeps(dt: f64) -> bool {
    !(dt.is_nan() || dt <= 0.0 || !dt.is_finite())
}

impl Builder {
    pub fn new(p: f64, v: f64) -> Self {
        Self::from(Kinematics { p, v, a: 0.0 })
    }

    pub fn from(k: Kinematics) -> Self {
        let zero = Segment {
            t0: 0.0,
            p0: k.p,
            v0: k.v,
            a0: k.a,
            j: 0.0,
        };
        Self {
            segs: [zero; MAX_SEGMENTS],
            n: 0,
            t: 0.0,
            p: k.p,
            v: k.v,
            a: k.a,
        }
    }

    /// Appends a constant-acceleration segment (a trapezoid's): the
    /// acceleration is the segment's own, whatever the one before ended
    /// with.
    pub fn push(&mut self, a: f64, dt: f64) {
        if self.append(a, 0.0, dt) {
            self.p += self.v * dt + 0.5 * a * dt * dt;
            self.v += a * dt;
            self.a = a;
            self.t += dt;
        }
    }

    /// Appends a constant-jerk segment continuing the current acceleration.
    pub fn push_jerk(&mut self, j: f64, dt: f64) {
        if self.append(self.a, j, dt) {
            (self.p, self.v, self.a) = advance(self.p, self.v, self.a, j, dt);
            self.t += dt;
        }
    }

    /// Stores a segment from the current state with acceleration `a0` and
    /// jerk `j`, unless `dt` is not kept or the list is full (false).
    fn append(&mut self, a0: f64, j: f64, dt: f64) -> bool {
        if !keeps(dt) || self.n == MAX_SEGMENTS {
            return false;
        }
        self.segs[self.n] = Segment {
            t0: self.t,
            p0: self.p,
            v0: self.v,
            a0,
            j,
        };
        self.n += 1;
        true
    }

    pub fn finish(self, start_ns: u64, end: End, v_end: f64) -> Profile {
        let p_end = match end {
            End::Hold(p) => p,
            End::Cruise => self.p,
        };
        Profile {
            start_ns,
            segs: self.segs,
            n: self.n,
            p_end,
            v_end,
            t_end: self.t,
            end,
        }
    }
}

/// The state `dt` later under constant jerk `j`.
#[inline]
pub(super) fn advance(p: f64, v: f64, a: f64, j: f64, dt: f64) -> (f64, f64, f64) {
    (
        p + dt * (v + dt * (0.5 * a + dt * (j / 6.0))),
        v + dt * (a + dt * (0.5 * j)),
        a + j * dt,
    )
}

impl Profile {
    /// Stand still at `p`.
    pub fn hold(now_ns: u64, p: f64) -> Self {
        Builder::new(p, 0.0).finish(now_ns, End::Hold(p), 0.0)
    }

    /// Time until a stop or move is done, rounded up to whole ns (0 for a
    /// hold; a jog is never done and reports its acceleration time).
    pub fn duration_ns(&self) -> u64 {
        (self.t_end * 1e9).ceil().min(u64::MAX as f64) as u64
    }

    fn t(&self, now_ns: u64) -> f64 {
        crate::time::ns_to_s(now_ns.saturating_sub(self.start_ns))
    }

    /// Commanded position and velocity at `now_ns`.
    pub fn sample(&self, now_ns: u64) -> (f64, f64) {
        let (p, v, _) = self.eval(now_ns);
        (p, v)
    }

    /// Commanded position, velocity and acceleration at `now_ns`: the
    /// state a re-plan at `now_ns` starts from.
    pub fn state(&self, now_ns: u64) -> Kinematics {
        let (p, v, a) = self.eval(now_ns);
        Kinematics { p, v, a }
    }

    /// Both of the above (inlined into each: the cycle's
    /// [`Profile::sample`] returns in registers and skips the
    /// acceleration).
    #[inline(always)]
    fn eval(&self, now_ns: u64) -> (f64, f64, f64) {
        let t = self.t(now_ns);
        if t >= self.t_end {
            return match self.end {
                End::Hold(p) => (p, 0.0, 0.0),
                End::Cruise => {
                    let dt = t - self.t_end;
                    (self.p_end + self.v_end * dt, self.v_end, 0.0)
                }
            };
        }
        let mut i = 0;
        while i + 1 < self.n && t >= self.segs[i + 1].t0 {
            i += 1;
        }
        let s = &self.segs[i];
        let tau = t - s.t0;
        if s.j == 0.0 {
            // A trapezoid's segment, as it was always sampled.
            return (
                s.p0 + s.v0 * tau + 0.5 * s.a0 * tau * tau,
                s.v0 + s.a0 * tau,
                s.a0,
            );
        }
        advance(s.p0, s.v0, s.a0, s.j, tau)
    }

    /// Every number of the plan is finite: what the S-curve planners check
    /// before they hand a plan out (extreme but finite inputs could
    /// overflow), holding instead.
    pub(super) fn is_finite(&self) -> bool {
        let segs = self.segs.iter().take(self.n);
        segs.into_iter().all(|s| {
            s.t0.is_finite()
                && s.p0.is_finite()
                && s.v0.is_finite()
                && s.a0.is_finite()
                && s.j.is_finite()
        }) && self.p_end.is_finite()
            && self.v_end.is_finite()
            && self.t_end.is_finite()
    }

    /// True once a stop or move has reached its end (always false for a jog).
    pub fn is_done(&self, now_ns: u64) -> bool {
        matches!(self.end, End::Hold(_)) && self.t(now_ns) >= self.t_end
    }

    /// Where a stop or move ends (the jog's cruise start for a jog).
    pub fn end_position(&self) -> f64 {
        self.p_end
    }
}
