//! The setpoint stream's intake and its owners, as the cycle keeps them:
//! which owner token owns which axes (granted and released through the
//! control queue), the last sequence number taken per token, and each
//! axis's newest setpoint of this cycle.
//!
//! A frame is taken only with this session's layout and key and at most
//! [`MAX_AXES`] entries ([`SetpointFrame::check`]), a token that owns axes,
//! and a sequence number above the token's last; each entry only for an
//! axis the token owns, addressed by the axis's lead (a gantry's first
//! side: its setpoint moves every side). Everything refused is counted by
//! kind and never reaches an engine; what is taken is judged again by the
//! engine (finite, limits, speed, acceleration, time order, freshness).
//!
//! Fixed-size arrays only: no allocation, bounded loops (at most
//! [`MAX_AXES`] owners, [`MAX_AXES`] entries per frame).

use motion_frames::{SetpointFrame, SetpointRefusal, MAX_AXES};
use motion_homing::Setpoint;

use crate::shared::StreamCounts;

/// Counts a refusal by kind.
fn count(c: &mut StreamCounts, r: SetpointRefusal) {
    let n = match r {
        SetpointRefusal::Layout => &mut c.refused_layout,
        SetpointRefusal::Key => &mut c.refused_key,
        SetpointRefusal::Count => &mut c.refused_count,
        SetpointRefusal::Token => &mut c.refused_token,
        SetpointRefusal::Sequence => &mut c.refused_sequence,
        SetpointRefusal::Axis => &mut c.refused_axis,
    };
    *n += 1;
}

/// One owner: its token, its axes, the last sequence number taken.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Owner {
    /// 0: a free entry (0 is never handed out).
    token: u64,
    mask: u64,
    last_seq: u64,
}

/// Owners and this cycle's setpoints.
#[derive(Clone, Debug)]
pub struct StreamIntake {
    /// This session's key (`None`: not known yet, every frame is refused).
    key: Option<[u64; 2]>,
    /// Per axis, the axis whose setpoints move it (itself, or its gantry's
    /// first side).
    lead: [u8; MAX_AXES],
    axis_count: usize,
    owners: [Owner; MAX_AXES],
    /// This cycle's newest setpoint per axis.
    newest: [Option<Setpoint>; MAX_AXES],
    pub counts: StreamCounts,
}

impl StreamIntake {
    /// `lead[i]`: the axis whose setpoints move axis `i` (itself, or its
    /// gantry's first side); `key`: this session's (`None`: every frame is
    /// refused until [`StreamIntake::set_key`]).
    pub fn new(key: Option<[u64; 2]>, lead: &[usize]) -> Self {
        let mut l = [0u8; MAX_AXES];
        let n = lead.len().min(MAX_AXES);
        for (i, (dst, &src)) in l.iter_mut().zip(lead).enumerate().take(n) {
            *dst = if src < n { src as u8 } else { i as u8 };
        }
        Self {
            key,
            lead: l,
            axis_count: n,
            owners: [Owner::default(); MAX_AXES],
            newest: [None; MAX_AXES],
            counts: StreamCounts::default(),
        }
    }

    /// Frames must carry `key` from now on.
    pub fn set_key(&mut self, key: [u64; 2]) {
        self.key = Some(key);
    }

    /// The token that owns axis `i` (0: none).
    pub fn owner_of(&self, i: usize) -> u64 {
        self.owners
            .iter()
            .find(|o| o.token != 0 && o.mask & bit(i) != 0)
            .map_or(0, |o| o.token)
    }

    /// Every axis some token owns.
    pub fn owned(&self) -> u64 {
        self.owners.iter().fold(0, |m, o| m | o.mask)
    }

    /// The axes `token` owns (0: an unknown token).
    pub fn mask_of(&self, token: u64) -> u64 {
        if token == 0 {
            return 0;
        }
        self.owners
            .iter()
            .find(|o| o.token == token)
            .map_or(0, |o| o.mask)
    }

    /// Owners now.
    pub fn owner_count(&self) -> u32 {
        self.owners.iter().filter(|o| o.token != 0).count() as u32
    }

    /// `token` (never 0) now owns the axes of `mask` (none of them owned
    /// by another: the caller checked). False when no entry is free
    /// (cannot happen: at most one owner per axis).
    pub fn grant(&mut self, token: u64, mask: u64) -> bool {
        if token == 0 || mask == 0 {
            return false;
        }
        let Some(o) = self.owners.iter_mut().find(|o| o.token == 0) else {
            return false;
        };
        *o = Owner {
            token,
            mask,
            last_seq: 0,
        };
        self.counts.acquired += 1;
        true
    }

    /// Axes of `mask` are no longer owned (released, or their stream ended
    /// in the engine); an owner left without axes is gone.
    pub fn drop_axes(&mut self, mask: u64) {
        for o in self.owners.iter_mut().filter(|o| o.token != 0) {
            o.mask &= !mask;
            if o.mask == 0 {
                *o = Owner::default();
            }
        }
    }

    /// Forgets last cycle's setpoints (before the frames of this cycle).
    pub fn begin_cycle(&mut self) {
        self.newest = [None; MAX_AXES];
    }

    /// Takes one received frame: refused as a whole, or its entries for
    /// owned axes become their newest setpoint of this cycle.
    pub fn take(&mut self, f: &SetpointFrame) {
        self.counts.frames += 1;
        let Some(key) = self.key else {
            return count(&mut self.counts, SetpointRefusal::Key);
        };
        if let Err(r) = f.check(key) {
            return count(&mut self.counts, r);
        }
        let Some(o) = self
            .owners
            .iter_mut()
            .find(|o| o.token != 0 && o.token == f.token)
        else {
            return count(&mut self.counts, SetpointRefusal::Token);
        };
        if f.seq <= o.last_seq {
            return count(&mut self.counts, SetpointRefusal::Sequence);
        }
        o.last_seq = f.seq;
        let mask = o.mask;
        for e in f.entries() {
            let i = e.axis as usize;
            if i >= self.axis_count || mask & bit(i) == 0 || self.lead[i] as usize != i {
                count(&mut self.counts, SetpointRefusal::Axis);
                continue;
            }
            let sp = Setpoint {
                t_ns: f.t_ns,
                position: e.position,
                velocity: e.feed_forward(),
            };
            self.counts.setpoints += 1;
            // The lead and every side it moves, in the same cycle.
            for j in 0..self.axis_count {
                if self.lead[j] as usize == i && mask & bit(j) != 0 {
                    self.newest[j] = Some(sp);
                }
            }
        }
    }

    /// Axis `i`'s newest setpoint of this cycle.
    pub fn setpoint(&self, i: usize) -> Option<Setpoint> {
        self.newest.get(i).copied().flatten()
    }
}

fn bit(i: usize) -> u64 {
    if i < 64 {
        1 << i
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_frames::{SetpointAxis, SETPOINT_LAYOUT, SP_VELOCITY};

    const KEY: [u64; 2] = [11, 22];

    fn frame(token: u64, seq: u64, entries: &[(u32, f64)]) -> SetpointFrame {
        let mut f = SetpointFrame {
            layout_version: SETPOINT_LAYOUT,
            key: KEY,
            token,
            seq,
            t_ns: seq * 1_000_000,
            count: entries.len() as u32,
            ..SetpointFrame::ZERO
        };
        for (k, &(axis, position)) in entries.iter().enumerate() {
            f.axes[k] = SetpointAxis {
                axis,
                position,
                ..SetpointAxis::ZERO
            };
        }
        f
    }

    /// X (0), gantry Y1 (1) + Y2 (2), Z (3).
    fn intake() -> StreamIntake {
        StreamIntake::new(Some(KEY), &[0, 1, 1, 3])
    }

    #[test]
    fn only_the_owner_moves_its_axes_in_sequence() {
        let mut s = intake();
        assert!(s.grant(7, 0b0001));
        assert!(s.grant(9, 0b0110));
        assert_eq!((s.owner_of(0), s.owner_of(2), s.owner_of(3)), (7, 9, 0));
        s.begin_cycle();
        s.take(&frame(7, 1, &[(0, 1.5)]));
        s.take(&frame(7, 2, &[(0, 1.75)])); // the newest wins
        s.take(&frame(7, 2, &[(0, 99.0)])); // replayed sequence
        s.take(&frame(7, 3, &[(3, 99.0)])); // an axis it does not own
        s.take(&frame(8, 1, &[(0, 99.0)])); // a token that owns nothing
        s.take(&frame(9, 1, &[(2, 99.0)])); // a gantry side other than the lead
        s.take(&frame(9, 2, &[(1, 4.0)])); // the gantry's lead: both sides
        assert_eq!(s.setpoint(0).map(|p| p.position), Some(1.75));
        assert_eq!(s.setpoint(1).map(|p| p.position), Some(4.0));
        assert_eq!(s.setpoint(2).map(|p| p.position), Some(4.0));
        assert_eq!(s.setpoint(3), None);
        let c = s.counts;
        assert_eq!((c.frames, c.setpoints), (7, 3));
        assert_eq!(
            (c.refused_sequence, c.refused_axis, c.refused_token),
            (1, 2, 1)
        );
        s.begin_cycle();
        assert_eq!(s.setpoint(0), None, "one cycle only");
    }

    #[test]
    fn without_the_key_or_after_release_nothing_is_taken() {
        let mut s = intake();
        s.grant(7, 0b1000);
        let mut f = frame(7, 1, &[(3, 1.0)]);
        f.key = [11, 23];
        s.take(&f);
        f.key = KEY;
        f.layout_version += 1;
        s.take(&f);
        assert_eq!((s.counts.refused_key, s.counts.refused_layout), (1, 1));
        s.drop_axes(0b1000);
        assert_eq!((s.owner_of(3), s.owner_count(), s.mask_of(7)), (0, 0, 0));
        s.take(&frame(7, 2, &[(3, 1.0)]));
        assert_eq!(s.setpoint(3), None);
        assert_eq!(s.counts.refused_token, 1);
        // token 0 is nobody's
        assert!(!s.grant(0, 1));
        s.take(&frame(0, 1, &[(0, 1.0)]));
        assert_eq!(s.counts.refused_token, 2);
    }

    #[test]
    fn feed_forward_and_time_come_from_the_frame() {
        let mut s = intake();
        s.grant(5, 1);
        let mut f = frame(5, 4, &[(0, 2.0)]);
        f.axes[0].flags = SP_VELOCITY;
        f.axes[0].velocity = -3.0;
        s.take(&f);
        let p = s.setpoint(0).expect("taken");
        assert_eq!((p.t_ns, p.velocity), (4_000_000, Some(-3.0)));
    }
}
