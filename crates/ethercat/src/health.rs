//! The SubDevices as the bus thread sees them from cycle to cycle: which
//! answer, which are in OP, which are lost, and what to do about it.
//!
//! * **Lost**: a SubDevice that drives an axis and does not answer its AL
//!   status read in a frame that came back, or answers out of OP, is lost
//!   this cycle: its axes report `SW_NO_DATA | SW_DRIVE_LOST` (the
//!   supervisor names the drive, not the I/O process), they do not hold up a
//!   stop (nothing can be done there: its SM watchdog stops it), and an
//!   axis that was enabled is not enabled again by itself when it is back
//!   (`AxisLogic::lost`). After [`SILENT_FRAMES`] frames in a row that came
//!   back from nobody (the first cable pulled, its power gone, the interface
//!   down) every SubDevice counts as not answering: sooner than any
//!   feedback-loss bound, so the loss is named after the drives.
//! * **Back to OP**, without restarting anything: one that answers out of
//!   OP gets its AL error acknowledged and SAFE-OP → OP requested
//!   ([`Job::Recover`], every [`RECOVERY_INTERVAL_NS`]); one found in INIT
//!   or PRE-OP, or one that stopped answering and is found again at its bus
//!   position without its station address ([`Job::Probe`]: power-cycled), is
//!   re-configured completely ([`Job::Reconfigure`], `crate::reconfigure`).
//!   What failed is never retried in a loop: the SubDevice is then given up
//!   (`needs_restart`) and motion-io's log says to restart it.
//! * Every change of health is published ([`crate::status::Health`]) for
//!   motion-io's log, with counters of losses, returns, re-configurations.

use std::sync::atomic::Ordering;

use ethercrab::SubDeviceState;

use crate::jobs::{Done, Job};
use crate::status::{Health, Shared};

/// A SubDevice out of OP is looked at again after this long.
pub const RECOVERY_INTERVAL_NS: u64 = 20_000_000;
/// A SubDevice that does not answer is looked for at its bus position
/// this long after it fell silent, and then every this long.
pub const PROBE_INTERVAL_NS: u64 = 200_000_000;
/// Frames in a row that nobody answered before every SubDevice counts as
/// not answering.
pub const SILENT_FRAMES: u32 = 3;
/// Cycles in a row a SubDevice must be out of OP (or not answer in a frame
/// that came back) before it is lost. One such cycle is only a missing
/// sample (its axes' data is invalid that cycle): a late frame matched to
/// the wrong cycle reads every AL status as unanswered, and on a loaded
/// host that happened about once in 2,000 cycles — a "lost" drive in the
/// middle of a drive-side homing.
pub const LOST_CYCLES: u32 = 3;

/// The SubDevices of the group.
pub(crate) struct Devices {
    /// Drives an axis.
    mapped: Vec<bool>,
    /// Not in OP since (ns).
    pub not_op_since: Vec<Option<u64>>,
    /// Answered its AL status read in the last frame that came back.
    answering: Vec<bool>,
    /// Its AL state as last read.
    states: Vec<SubDeviceState>,
    silent_frames: u32,
    /// Lost this cycle.
    lost: Vec<bool>,
    /// Cycles in a row out of OP or not answering (see [`LOST_CYCLES`]).
    quiet: Vec<u32>,
    health: Vec<Health>,
    last_recovery: Vec<u64>,
    last_probe: Vec<u64>,
    /// Found power-cycled (or in INIT / PRE-OP): re-configure it.
    reconfigure: Vec<bool>,
    /// Given up on: only a restart brings it back.
    given_up: Vec<bool>,
}

impl Devices {
    pub fn new(count: usize, mapped: &[usize]) -> Devices {
        Devices {
            mapped: (0..count).map(|i| mapped.contains(&i)).collect(),
            not_op_since: vec![None; count],
            answering: vec![true; count],
            states: vec![SubDeviceState::None; count],
            silent_frames: 0,
            lost: vec![false; count],
            quiet: vec![0; count],
            health: vec![Health::Ok; count],
            last_recovery: vec![0; count],
            last_probe: vec![0; count],
            reconfigure: vec![false; count],
            given_up: vec![false; count],
        }
    }

    pub fn count(&self) -> usize {
        self.mapped.len()
    }

    /// Every SubDevice is in OP.
    pub fn all_in_op(&self) -> bool {
        self.not_op_since.iter().all(Option::is_none)
    }

    /// SubDevice `i` is lost this cycle.
    pub fn lost(&self, i: usize) -> bool {
        self.lost.get(i).copied().unwrap_or(false)
    }

    /// This cycle's frame did not come back.
    pub fn frame_lost(&mut self, done: u64) {
        self.silent_frames = self.silent_frames.saturating_add(1);
        if self.silent_frames >= SILENT_FRAMES {
            for i in 0..self.count() {
                // the silent frames were the wait: lost at once
                self.quiet[i] = self.quiet[i].max(LOST_CYCLES);
                self.answering[i] = false;
                self.states[i] = SubDeviceState::None;
                self.not_op_since[i].get_or_insert(done);
            }
        }
    }

    /// SubDevice `i` answered (or not) in this cycle's frame with `state`.
    pub fn observe(&mut self, i: usize, state: SubDeviceState, done: u64) {
        self.silent_frames = 0;
        self.answering[i] = state != SubDeviceState::None;
        self.states[i] = state;
        self.quiet[i] = if state == SubDeviceState::Op {
            0
        } else {
            self.quiet[i].saturating_add(1)
        };
        match (state == SubDeviceState::Op, self.not_op_since[i]) {
            (true, Some(_)) => {
                self.not_op_since[i] = None;
                self.given_up[i] = false;
                self.reconfigure[i] = false;
            }
            (false, None) => self.not_op_since[i] = Some(done),
            _ => {}
        }
    }

    /// Works out who is lost this cycle (`counting`: after start-up) and
    /// publishes every change of health.
    pub fn update(&mut self, shared: &Shared, counting: bool) {
        for i in 0..self.count() {
            self.lost[i] = counting
                && self.mapped[i]
                && self.not_op_since[i].is_some()
                && self.quiet[i] >= LOST_CYCLES;
            if !counting || !self.mapped[i] {
                continue;
            }
            let h = if !self.lost[i] {
                Health::Ok
            } else if self.given_up[i] {
                Health::Failed
            } else if self.reconfigure[i] {
                Health::PowerCycled
            } else if self.answering[i] {
                Health::NotOp
            } else {
                Health::NotAnswering
            };
            let sd = &shared.sd[i];
            if let SubDeviceState::Other(v) = self.states[i] {
                sd.al_status.store(v, Ordering::Relaxed);
            } else {
                sd.al_status
                    .store(state_code(self.states[i]), Ordering::Relaxed);
            }
            if h != self.health[i] {
                if self.health[i] == Health::Ok {
                    sd.losses.fetch_add(1, Ordering::Relaxed);
                } else if h == Health::Ok {
                    sd.returns.fetch_add(1, Ordering::Relaxed);
                }
                self.health[i] = h;
                sd.set_health(h);
                shared.health_events.fetch_add(1, Ordering::Release);
            }
        }
    }

    /// The next job for a SubDevice, if one is due.
    pub fn next_job(&mut self, now: u64) -> Option<Job> {
        for i in 0..self.count() {
            let Some(since) = self.not_op_since[i] else {
                continue;
            };
            if self.given_up[i] {
                continue;
            }
            if self.reconfigure[i] {
                return Some(Job::Reconfigure(i));
            }
            if self.answering[i]
                && now.saturating_sub(since) >= RECOVERY_INTERVAL_NS / 4
                && now.saturating_sub(self.last_recovery[i]) >= RECOVERY_INTERVAL_NS
            {
                self.last_recovery[i] = now;
                return Some(Job::Recover(i));
            }
            if self.mapped[i]
                && !self.answering[i]
                && now.saturating_sub(since) >= PROBE_INTERVAL_NS / 2
                && now.saturating_sub(self.last_probe[i]) >= PROBE_INTERVAL_NS
            {
                self.last_probe[i] = now;
                return Some(Job::Probe(i));
            }
        }
        None
    }

    /// Counts how a SubDevice's job ended (`None`: it timed out or failed).
    pub fn job_done(&mut self, shared: &Shared, job: Job, r: Option<Done>) {
        let c = |a: &std::sync::atomic::AtomicU64| {
            a.fetch_add(1, Ordering::Relaxed);
        };
        match (job, r) {
            (Job::Recover(i), Some(Done::Acknowledged { code })) => {
                shared.sd[i].al_code.store(code, Ordering::Relaxed);
            }
            (Job::Recover(_), Some(Done::OpRequested)) => c(&shared.recoveries),
            (Job::Recover(i) | Job::Probe(i), Some(Done::LostConfiguration)) => {
                self.reconfigure[i] = true;
            }
            (Job::Recover(_) | Job::Probe(_), Some(_)) => {}
            (Job::Recover(_) | Job::Probe(_), None) => c(&shared.recovery_failures),
            (Job::Reconfigure(i), Some(Done::Reconfigured)) => {
                self.reconfigure[i] = false;
                c(&shared.sd[i].reconfigured);
            }
            (Job::Reconfigure(i), _) => {
                self.reconfigure[i] = false;
                self.given_up[i] = true;
                c(&shared.needs_restart);
            }
            (Job::Window { .. }, _) => {}
        }
    }
}

/// The AL state's code (0x0130 low nibble).
fn state_code(s: SubDeviceState) -> u8 {
    match s {
        SubDeviceState::Init => 0x01,
        SubDeviceState::PreOp => 0x02,
        SubDeviceState::Bootstrap => 0x03,
        SubDeviceState::SafeOp => 0x04,
        SubDeviceState::Op => 0x08,
        _ => 0,
    }
}
