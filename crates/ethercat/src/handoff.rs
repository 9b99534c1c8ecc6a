//! The supervisor's set-points handed to the bus cycle: which command's
//! target each bus frame carries.
//!
//! Two clocks meet here: the supervisor samples its profiles at its own
//! cycle's deadlines (`CLOCK_MONOTONIC`), the bus thread sends a frame per
//! cycle of its own — with distributed clocks at the reference clock's
//! SYNC0, whose crystal runs some ppm off the host's. Taking "the newest
//! command" for every frame makes the frame's target depend on which side
//! of the frame's instant the newest command arrived: where the two phases
//! meet, host jitter decides cycle by cycle, and frames carry a target twice
//! (a step of 0) and then skip one (a step of two cycles' travel). With a
//! drifting clock the phases meet again and again: on the emulator at
//! 1,000 ppm, 2–4 % of the frames at constant speed stepped by 0 or twice
//! the travel (`ecat-emu/tests/regularity.rs`).
//!
//! Here each frame takes the command that follows the previous frame's in
//! the supervisor's sequence — one supervisor cycle per bus cycle — whatever
//! arrived when. Its *lead* is how far that sequence is from the newest
//! command's:
//!
//! * 0: the newest command's target;
//! * 1 (not arrived yet): the newest target plus one cycle of the newest
//!   velocity (exact at constant speed; off by at most ½·a·T² while
//!   accelerating). Never further: a position the supervisor has not
//!   commanded yet reaches its feedback no sooner than it commands it, so
//!   its plausibility check never sees the axis ahead of its commands;
//! * −1 or −2 (newer ones arrived too): the target of that command, kept
//!   from the last three.
//!
//! Host jitter moves the lead by one from frame to frame; the two clocks'
//! drift moves it for good, a cycle every 1/drift frames. Only that trend is
//! corrected: when the lead has been 1 (−1 or less) in every frame of
//! [`TREND_FRAMES`], the frames' sequence is moved by one — one frame steps
//! by 0 (the bus clock ahead) or by two cycles' travel (behind), once per
//! 1/drift frames (10,000 at 100 ppm). A lead beyond the window (a host
//! stall of a cycle or more) is corrected at once.
//!
//! Pure and allocation-free per frame (the per-axis memory is allocated
//! once); commands without a sequence (0) pass through unchanged.

use motion_frames::{AxisCommand, INVALID_COUNTS};

/// How far the frames' sequence may be from the newest command's: one
/// cycle ahead (extrapolated), two behind (a kept command).
pub const AHEAD: i64 = 1;
pub const BEHIND: i64 = 2;
/// Frames over which a lead that never came back to 0 is a trend.
pub const TREND_FRAMES: u32 = 256;

/// The hand-off of one bus: the frames' sequence and the last commands'
/// targets.
#[derive(Clone, Debug)]
pub struct HandOff {
    /// The bus cycle in seconds (one cycle of velocity).
    cycle_s: f64,
    /// The sequence the last frame carried, if any.
    frame: Option<u64>,
    /// The last three commands' sequences (0 = none) and targets, the
    /// newest at `newest`.
    seqs: [u64; 3],
    targets: [Vec<i64>; 3],
    newest: usize,
    /// The smallest and largest lead over the trend's frames so far.
    low: i64,
    high: i64,
    frames: u32,
    /// Frames whose sequence had to be moved.
    pub corrections: u64,
}

impl HandOff {
    /// For `axes` axes and a bus cycle of `cycle_s` seconds.
    pub fn new(axes: usize, cycle_s: f64) -> HandOff {
        HandOff {
            cycle_s,
            frame: None,
            seqs: [0; 3],
            targets: [vec![0; axes], vec![0; axes], vec![0; axes]],
            newest: 0,
            low: i64::MAX,
            high: i64::MIN,
            frames: 0,
            corrections: 0,
        }
    }

    /// The commands do not follow the supervisor's cycles (a stop, a
    /// pause): the next frame starts again at the newest command.
    pub fn reset(&mut self) {
        self.frame = None;
        self.frames = 0;
        self.low = i64::MAX;
        self.high = i64::MIN;
    }

    /// This frame's commands: `cmds` are the newest, of sequence `seq`;
    /// their targets are set to the frame's (see the module docs).
    pub fn frame(&mut self, seq: u64, cmds: &mut [AxisCommand]) {
        if seq == 0 {
            self.reset();
            return;
        }
        if seq != self.seqs[self.newest] {
            if seq < self.seqs[self.newest] {
                // a new supervisor: its sequence starts again
                self.reset();
                self.seqs = [0; 3];
            }
            self.newest = (self.newest + 1) % 3;
            self.seqs[self.newest] = seq;
        }
        for (t, c) in self.targets[self.newest].iter_mut().zip(cmds.iter()) {
            *t = c.target_position;
        }
        let want = self.frame.map_or(seq, |f| f.wrapping_add(1));
        let mut lead = (want as i64).wrapping_sub(seq as i64);
        if !(-BEHIND..=AHEAD).contains(&lead) {
            self.corrections += 1;
            lead = lead.clamp(-BEHIND, AHEAD);
        }
        lead = self.trend(lead);
        self.frame = Some(seq.wrapping_add_signed(lead));
        for (k, c) in cmds.iter_mut().enumerate() {
            c.target_position = self.target(k, seq, c, lead);
        }
    }

    /// The lead after the trend's correction, if one is due.
    fn trend(&mut self, lead: i64) -> i64 {
        self.low = self.low.min(lead);
        self.high = self.high.max(lead);
        self.frames += 1;
        if self.frames < TREND_FRAMES {
            return lead;
        }
        let step = if self.low >= 1 {
            -1
        } else if self.high <= -1 {
            1
        } else {
            0
        };
        self.frames = 0;
        self.low = i64::MAX;
        self.high = i64::MIN;
        if step != 0 {
            self.corrections += 1;
        }
        (lead + step).clamp(-BEHIND, AHEAD)
    }

    /// Axis `k`'s target `lead` cycles from the newest command `c` (of
    /// sequence `seq`).
    fn target(&self, k: usize, seq: u64, c: &AxisCommand, lead: i64) -> i64 {
        let cur = self.targets[self.newest][k];
        if cur == INVALID_COUNTS {
            return cur;
        }
        if lead < 0 {
            let want = seq.wrapping_add_signed(lead);
            if let Some(i) = (0..3).find(|&i| self.seqs[i] == want) {
                let kept = self.targets[i][k];
                if kept != INVALID_COUNTS {
                    return kept;
                }
            }
        }
        cur.saturating_add(self.travel(c).saturating_mul(lead))
    }

    /// One cycle of `c`'s velocity, counts (0 for a velocity that is not a
    /// number).
    fn travel(&self, c: &AxisCommand) -> i64 {
        let d = c.target_velocity * self.cycle_s;
        if d.is_finite() && d.abs() < (1u64 << 40) as f64 {
            d.round() as i64
        } else {
            0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(target: i64, velocity: f64) -> AxisCommand {
        AxisCommand {
            target_position: target,
            target_velocity: velocity,
            ..AxisCommand::ZERO
        }
    }

    /// The targets of the frames when command `k` (target 5k, 5,000
    /// counts/s) is the newest at frame `i` for `newest[i] = k`.
    fn frames(h: &mut HandOff, newest: &[u64]) -> Vec<i64> {
        newest
            .iter()
            .map(|&k| {
                let mut c = [cmd(5 * k as i64, 5000.0)];
                h.frame(k, &mut c);
                c[0].target_position
            })
            .collect()
    }

    /// Frames every `bus` cycles of the commands (1 + drift), each command
    /// arriving up to `jitter` of a cycle late (a fixed pseudo-random
    /// sequence); returns the histogram of the frames' steps.
    fn drifting(bus: f64, jitter: f64, n: usize) -> (std::collections::BTreeMap<i64, u32>, u64) {
        let mut h = HandOff::new(1, 0.001);
        let mut seed = 12345u64;
        let mut late = |_: u64| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as f64 / (1u64 << 31) as f64 * jitter
        };
        // arrival of command k: k + its lateness (cycles)
        let arrivals: Vec<f64> = (1..=(n as f64 * bus) as u64 + 10)
            .map(|k| k as f64 + late(k))
            .collect();
        let mut newest = Vec::new();
        let mut arrived = 0;
        for j in 1..=n {
            let t = j as f64 * bus + 0.5;
            while arrivals.get(arrived).is_some_and(|&a| a <= t) {
                arrived += 1;
            }
            newest.push(arrived as u64);
        }
        let t = frames(&mut h, &newest);
        let mut hist = std::collections::BTreeMap::new();
        for w in t[40..].windows(2) {
            *hist.entry(w[1] - w[0]).or_insert(0) += 1;
        }
        (hist, h.corrections)
    }

    #[test]
    fn a_command_late_or_early_by_a_cycle_changes_no_frame() {
        let mut h = HandOff::new(1, 0.001);
        // the newest command jitters around the frames' instants: arrives
        // after its frame (3 twice), before the frame before (6 skipped)
        let t = frames(&mut h, &[1, 2, 3, 3, 5, 6, 6, 8, 8, 9, 10, 12]);
        assert_eq!(t, [5, 10, 15, 20, 25, 30, 35, 40, 45, 50, 55, 60]);
        assert_eq!(h.corrections, 0);
        // jitter of up to 0.9 cycles, no drift, 20,000 frames: every step
        // one cycle's travel
        let (hist, corrections) = drifting(1.0, 0.9, 20_000);
        assert_eq!((hist.len(), corrections), (1, 0), "{hist:?}");
    }

    #[test]
    fn drift_is_corrected_once_per_cycle_it_adds_up_to() {
        // 1,000 ppm either way over 20,000 frames: 20 cycles of drift, with
        // jitter of up to 0.9 cycles
        for (bus, repeats_or_skips) in [(1.0 - 1e-3, 0), (1.0 + 1e-3, 10)] {
            let (hist, corrections) = drifting(bus, 0.9, 20_000);
            let other = hist.get(&repeats_or_skips).copied().unwrap_or(0);
            assert!(
                (19..=21).contains(&other) && hist.len() == 2,
                "{bus}: {hist:?}"
            );
            assert_eq!(u64::from(other), corrections);
        }
    }

    #[test]
    fn a_lag_that_lasts_is_taken_back_a_cycle_at_a_time() {
        // two bus stalls of one cycle leave the frames two commands behind
        // the newest: after TREND_FRAMES frames one frame steps two cycles,
        // then the frames keep one command behind the newest (the next
        // window would take that back too)
        let mut h = HandOff::new(1, 0.001);
        let mut newest: Vec<u64> = (1..=10).collect();
        newest.extend(12..=20);
        newest.extend(22..22 + 2 * u64::from(TREND_FRAMES));
        let t = frames(&mut h, &newest);
        let last = *newest.last().unwrap() as i64;
        assert_eq!(*t.last().unwrap(), 5 * (last - 1), "one behind");
        assert_eq!(h.corrections, 1);
        let steps: Vec<i64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        assert_eq!(steps.iter().filter(|s| **s != 5).count(), 1, "{steps:?}");
    }

    #[test]
    fn a_stall_beyond_the_window_is_corrected_at_once() {
        let mut h = HandOff::new(1, 0.001);
        // the bus stalled three cycles: the newest is 4 ahead
        let t = frames(&mut h, &[1, 2, 3, 7, 8]);
        assert_eq!(t, [5, 10, 15, 25, 30]);
        assert_eq!(h.corrections, 1);
        // the commands stopped: one cycle extrapolated, then held
        let mut h = HandOff::new(1, 0.001);
        let t = frames(&mut h, &[1, 2, 3, 3, 3, 3, 3]);
        assert_eq!(t, [5, 10, 15, 20, 20, 20, 20]);
    }

    #[test]
    fn no_sequence_passes_through_and_a_new_supervisor_starts_afresh() {
        let mut h = HandOff::new(1, 0.001);
        let mut c = [cmd(42, 5000.0)];
        h.frame(0, &mut c);
        assert_eq!(c[0].target_position, 42);
        frames(&mut h, &[100, 101]);
        // a restarted supervisor: sequence 1 again, its own target
        assert_eq!(frames(&mut h, &[1, 2]), [5, 10]);
        // NaN velocity: no extrapolation; the sentinel stays
        let mut c = [cmd(7, f64::NAN)];
        h.frame(3, &mut c);
        h.frame(3, &mut c);
        assert_eq!(c[0].target_position, 7);
        let mut c = [cmd(INVALID_COUNTS, 5000.0)];
        h.frame(4, &mut c);
        assert_eq!(c[0].target_position, INVALID_COUNTS);
    }
}
