//! Set-point regularity over a drifting distributed clock (veth pair,
//! root; skipped otherwise). The test's thread plays the supervisor: a
//! 1 kHz cycle on absolute `CLOCK_MONOTONIC` deadlines (the supervisor's
//! timer), jogging at 5 counts per cycle — target = 5 counts × the cycle's
//! index, its velocity 5,000 counts/s — while the bus thread cycles on the
//! emulated drive's distributed clock, which runs `ppm` off the host's.
//! The drive records the target of every frame it takes: at constant speed
//! each should advance by 5 counts.
//!
//! The bound (`motion_ethercat::handoff`): each frame carries the command
//! that follows the previous frame's in the supervisor's sequence, so a
//! frame steps by other than one cycle's travel only
//!
//! * next to an event of the host: a frame that passed more than half a
//!   cycle off its period (the bus thread late, a frame lost) or a command
//!   published more than a quarter cycle after its deadline (the test's
//!   cycle late) within four cycles — such frames are counted apart;
//! * or where the hand-off moved the frames' sequence (a correction): every
//!   other irregular frame must be one of those, and the corrections are at
//!   most one per whole cycle the clocks drifted apart, plus one, plus one
//!   per cycle the host took (the test cycle's missed deadlines and late
//!   commands, the bus thread's overruns, lost and late frames).
//!
//! Before, with the newest command taken for every frame, 2–4 % of the
//! frames at 1,000 ppm stepped by 0 or two cycles' travel, host or not.

mod common;

use std::time::{Duration, Instant};

use common::*;
use motion_frames::backend::Backend;
use motion_rt::timer::PeriodicTimer;

/// Counts per cycle of the jog.
const STEP: i32 = 5;
const CYCLE_NS: u64 = 1_000_000;

/// What one run saw.
#[derive(Debug, Default)]
struct Regularity {
    ppm: f64,
    /// Frames whose step was measured (at constant speed).
    frames: usize,
    /// Steps of other than [`STEP`] counts, and of those: 0 (a set-point
    /// twice), 2 × [`STEP`] (one skipped), anything else.
    irregular: usize,
    repeated: usize,
    skipped: usize,
    other: usize,
    /// Irregular steps within four cycles of an event of the host.
    excused: usize,
    /// Frames the hand-off had to move back into its window.
    corrections: u64,
    /// Cycles the host took: the test cycle's missed deadlines and its
    /// commands published more than a quarter cycle late, the bus thread's
    /// overruns, lost and late frames.
    host_cycles: u64,
}

impl Regularity {
    fn share(&self) -> f64 {
        self.irregular as f64 / self.frames.max(1) as f64
    }

    /// The corrections the hand-off may make (see the top).
    fn bound(&self) -> u64 {
        (self.frames as f64 * self.ppm.abs() * 1e-6).ceil() as u64 + 1 + self.host_cycles
    }
}

/// Jogs for `seconds` with the drive's clock `ppm` off; `None`: skipped.
fn jog(ppm: f64, seconds: u64) -> Option<Regularity> {
    let mut d = drive("EMU-DRIFT");
    d.clock_ppm = ppm;
    d.plant.hard_stop = None;
    d.plant.overtravel = None;
    let mut r = rig_with(vec![d], |_| {})?;
    r.enable(0);
    let p0 = r.cmd.axes[0].target_position;
    let st0 = r.backend.bus_status();
    r.emu().record_targets(0, true);
    let mut timer = PeriodicTimer::new(CYCLE_NS);
    let first = timer.next_deadline_ns();
    // when the commands published late (or after missed deadlines) went out
    let mut late = Vec::new();
    let mut missed = 0;
    for seq in 1..=seconds * 1000 {
        let w = timer.wait();
        missed += w.missed;
        // one frame per cycle, numbered as the supervisor's publisher does
        r.cmd.header.sequence = seq;
        // the profile sampled at the cycle's deadline, as the engine does
        let k = ((w.deadline_ns - first) / CYCLE_NS) as i64;
        let a = r.axis(0);
        a.target_position = p0 + i64::from(STEP) * k;
        a.target_velocity = f64::from(STEP) * 1000.0;
        r.backend.exchange(&r.cmd, &mut r.fb).expect("exchange");
        if w.missed > 0 || motion_rt::now_ns() - w.deadline_ns > CYCLE_NS / 4 {
            late.push(Instant::now());
        }
    }
    let t = r.emu().take_timed_targets(0);
    let st = r.backend.bus_status();
    let mut g = judge(ppm, seconds, &t, &late);
    g.corrections = st.handoff_corrections - st0.handoff_corrections;
    g.host_cycles = missed
        + late.len() as u64
        + (st.overruns - st0.overruns)
        + (st.lost_frames - st0.lost_frames)
        + (st.late_frames - st0.late_frames);
    eprintln!(
        "  hand-off corrections {}, host cycles {}",
        g.corrections, g.host_cycles
    );
    Some(g)
}

/// The steps of `t` at constant speed (from the first frame that moved, the
/// last few — still on their way at the end — left out), judged.
fn judge(ppm: f64, seconds: u64, t: &[(i32, Instant)], late: &[Instant]) -> Regularity {
    let from = t.windows(2).position(|w| w[1].0 != w[0].0).unwrap_or(0) + 10;
    let t = &t[from..t.len().saturating_sub(10)];
    let cycle = Duration::from_nanos(CYCLE_NS);
    // frame j passed off its period: the bus thread late, a frame lost
    let off: Vec<bool> = (0..t.len())
        .map(|j| {
            j > 0 && {
                let dt = t[j].1 - t[j - 1].1;
                dt > cycle * 3 / 2 || dt < cycle / 2
            }
        })
        .collect();
    let near = |j: usize| {
        let (lo, hi) = (j.saturating_sub(4), (j + 4).min(t.len() - 1));
        (lo..=hi).any(|i| off[i])
            || late
                .iter()
                .any(|p| t[j].1 + 4 * cycle >= *p && *p + 4 * cycle >= t[j].1)
    };
    let mut g = Regularity {
        ppm,
        frames: t.len().saturating_sub(1),
        ..Regularity::default()
    };
    let mut hist = std::collections::BTreeMap::new();
    for j in 1..t.len() {
        let step = t[j].0.wrapping_sub(t[j - 1].0);
        *hist.entry(step).or_insert(0u32) += 1;
        if step == STEP {
            continue;
        }
        match step {
            0 => g.repeated += 1,
            s if s == 2 * STEP => g.skipped += 1,
            _ => g.other += 1,
        }
        g.irregular += 1;
        g.excused += usize::from(near(j));
    }
    eprintln!(
        "clock {ppm:+} ppm, {seconds} s: {} frames, {} irregular ({:.3} %): {} repeated, {} \
         skipped, {} other; {} of them next to an event of the host; steps {hist:?}",
        g.frames,
        g.irregular,
        g.share() * 100.0,
        g.repeated,
        g.skipped,
        g.other,
        g.excused
    );
    g
}

#[test]
fn set_points_advance_regularly_over_a_drifting_clock() {
    let _t = turn();
    for ppm in [1000.0, -1000.0] {
        // a host that takes more than 1 % of the cycles (other builds and
        // tests on 2 vCPUs) can take them where no event shows: such an
        // attempt that fails measures the host and is made again (at most
        // three)
        for attempt in 1..=3 {
            let Some(g) = jog(ppm, 3) else { return };
            assert!(g.frames > 2500, "{g:?}");
            let own = (g.irregular - g.excused) as u64;
            let holds = own <= g.corrections && g.corrections <= g.bound();
            if !holds && g.host_cycles * 100 > g.frames as u64 && attempt < 3 {
                eprintln!(
                    "attempt {attempt}: the host took {} cycles: again",
                    g.host_cycles
                );
                continue;
            }
            assert!(
                own <= g.corrections,
                "{own} irregular frames away from the host's events, {} corrections: {g:?}",
                g.corrections
            );
            assert!(g.corrections <= g.bound(), "{g:?}");
            break;
        }
    }
}

/// The figures of the README (run on purpose):
/// `cargo test -p ecat-emu --test regularity -- --ignored --nocapture`.
#[test]
#[ignore = "figures: 100 and 1,000 ppm, 12 s each way"]
fn figures() {
    let _t = turn();
    for ppm in [100.0, -100.0, 1000.0, -1000.0] {
        jog(ppm, 12);
    }
}
