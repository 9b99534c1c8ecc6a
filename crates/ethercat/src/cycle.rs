//! `Engine`: the bus thread's per-cycle state and one cycle — outputs
//! into the process image, the exchange, validity per SubDevice, every
//! axis' step, the feedback published — plus what it decides between cycles
//! (which background job is due). Everything is allocated in
//! `Engine::new`; a cycle allocates nothing.

use std::pin::pin;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

use ethercrab::error::Error;
use ethercrab::{MainDevice, SubDeviceState};
use motion_config::EthercatBus;
use motion_frames::AxisCommand;
use motion_rt::now_ns;

use crate::axis::{AxisLogic, AxisSetup, Mode};
use crate::capacity::MAX_SUBDEVICES;
use crate::group::{Exchanged, OpGroup};
use crate::handoff::HandOff;
use crate::health::Devices;
use crate::io::BusIo;
use crate::jobs::{Done, Job};
use crate::objects::MODE_CSP;
use crate::pdo::DriveOutputs;
use crate::startup::AxisPlan;
use crate::status::Shared;
use crate::words::{self, FLAG_BUS_WATCHDOG, FLAG_RUNNING, MODE_EMERGENCY, MODE_WATCHDOG_STOP};
use motion_frames::{SW_DRIVE_LOST, SW_ENABLED};

/// The bound of the bus thread's own watchdog, in bus cycles it ran:
/// twice motion-io's (`io_watchdog_cycles`, [`EthercatBus::watchdog_cycles`]),
/// so motion-io's own watchdog — which says why in the log — acts first
/// when the supervisor falls silent, and this one only when motion-io's
/// main loop cannot (blocked, stalled, or gone without stopping). Counted
/// in cycles the bus thread ran, not in time: a host that held both
/// threads off the CPU is no silence of motion-io's (the bus thread, back
/// first, would otherwise stop the drives before motion-io had its turn).
/// With the defaults 100 cycles (100 ms, longer if cycles were late); the
/// drives are then in Switch on disabled within that plus the bounded stop
/// (`quick_stop_timeout_ms` + a brake's delay).
pub fn watchdog_cycles(cfg: &EthercatBus) -> u64 {
    2 * u64::from(cfg.watchdog_cycles.max(1))
}

/// A working counter `wkc` short of `expected` is explained by the
/// SubDevices out of OP when the shortfall lies between what the silent
/// ones (no answer to their AL status read: they counted nothing) and what
/// all of them out of OP would have counted (`contrib`: 1 for inputs, 2 for
/// outputs): one in SAFE-OP is read but may no longer take outputs (its
/// application deactivated the output sync manager after an SM watchdog or
/// an AL error), one in PRE-OP or INIT counts nothing. The SubDevices that
/// report OP in the same frame (their AL status is read after the process
/// data) are then taken to have processed theirs: an ESC in OP always does,
/// and one whose application stopped taking data leaves OP (its SM
/// watchdog), which the next frames show. Anything else — a shortfall only
/// SubDevices in OP can have caused, a counter above the expected one —
/// leaves no SubDevice's data trusted (a stop is still sent: see
/// `AxisLogic::blind`).
pub(crate) fn explained(
    wkc: u16,
    expected: u16,
    contrib: &[u16],
    state: impl Fn(usize) -> SubDeviceState,
) -> bool {
    let Some(short) = expected.checked_sub(wkc) else {
        return false;
    };
    let (mut silent, mut out_of_op) = (0u16, 0u16);
    for (i, c) in contrib.iter().enumerate() {
        match state(i) {
            SubDeviceState::Op => {}
            SubDeviceState::None => {
                silent += c;
                out_of_op += c;
            }
            _ => out_of_op += c,
        }
    }
    (silent..=out_of_op).contains(&short)
}

/// Per-cycle state of the bus.
pub(crate) struct Engine {
    pub shared: Arc<Shared>,
    axes: Vec<AxisLogic>,
    plans: Vec<AxisPlan>,
    pub sd_of_axis: Vec<usize>,
    outputs: Vec<DriveOutputs>,
    /// Working-counter contribution of each SubDevice (1 inputs, 2 outputs).
    contrib: Vec<u16>,
    expected_wkc: u16,
    cmd_words: Vec<u64>,
    fb_words: Vec<u64>,
    /// The newest commands from motion-io, and this frame's (their targets
    /// re-timed by the hand-off).
    newest: Vec<AxisCommand>,
    cmds: Vec<AxisCommand>,
    handoff: HandOff,
    mode: Mode,
    /// The bus thread's own watchdog: the generation of the newest command
    /// words, the bus cycles run since a new one came, the bound, whether
    /// it stops the drives now.
    generation: u64,
    silent_cycles: u64,
    watchdog_cycles: u64,
    watchdog: bool,
    window_written: Vec<Option<u32>>,
    window_pending: Vec<bool>,
    /// The SubDevices: answering, in OP, lost, their recovery.
    pub devices: Devices,
    pub period_ns: u64,
    reply_ns: u64,
    pub cycle: u64,
    /// Counting no-data causes (not while waiting for OP at start-up).
    pub counting: bool,
}

/// Validity of this cycle's data per SubDevice.
struct Validity {
    /// The frame came back in time.
    frame_ok: bool,
    /// In OP with a working counter that matches, or whose shortfall is
    /// explained by the SubDevices out of OP (see [`explained`]).
    valid: [bool; MAX_SUBDEVICES],
    /// Not in OP (the cause counted when its data is missing).
    not_op: [bool; MAX_SUBDEVICES],
}

impl Engine {
    pub fn new(
        shared: Arc<Shared>,
        plans: Vec<AxisPlan>,
        cfg: &EthercatBus,
        group: &OpGroup,
        md: &MainDevice<'_>,
    ) -> Engine {
        let n = plans.len();
        let cycle_s = cfg.cycle().as_secs_f64();
        let axes = plans
            .iter()
            .zip(&cfg.axes)
            .map(|(p, a)| {
                AxisLogic::new(AxisSetup {
                    layout: p.layout.clone(),
                    cycle_s,
                    index_pulse_bit: a.ethercat.index_pulse_bit,
                    home_switch_bit: a.ethercat.home_switch_bit,
                    quick_stop_ms: cfg.keys.quick_stop_timeout_ms,
                    brake_ms: a.ethercat.brake_delay_ms,
                    drive_homing: p.homing.is_some(),
                    gap_cycles: (cfg.feedback_timeout_ms * 1e-3 / cycle_s)
                        .ceil()
                        .clamp(0.0, 1e6) as u32,
                })
            })
            .collect();
        let count = group.len();
        let mut contrib = vec![0u16; count];
        for (i, c) in contrib.iter_mut().enumerate() {
            if let Ok(sd) = group.subdevice(md, i) {
                let io = sd.io_raw();
                *c = u16::from(!io.inputs().is_empty()) + 2 * u16::from(!io.outputs().is_empty());
            }
        }
        let window_written = plans
            .iter()
            .map(|p| p.has_window.then_some(u32::MAX))
            .collect();
        let sd_of_axis: Vec<usize> = plans.iter().map(|p| p.sd).collect();
        Engine {
            axes,
            sd_of_axis: sd_of_axis.clone(),
            outputs: plans
                .iter()
                .map(|_| DriveOutputs {
                    mode: MODE_CSP,
                    ..DriveOutputs::default()
                })
                .collect(),
            plans,
            expected_wkc: contrib.iter().sum(),
            contrib,
            cmd_words: vec![0; words::len(n)],
            fb_words: vec![0; words::len(n)],
            newest: vec![AxisCommand::ZERO; n],
            cmds: vec![AxisCommand::ZERO; n],
            handoff: HandOff::new(n, cycle_s),
            mode: Mode::Normal,
            generation: 0,
            silent_cycles: 0,
            watchdog_cycles: watchdog_cycles(cfg),
            watchdog: false,
            window_written,
            window_pending: vec![false; n],
            devices: Devices::new(count, &sd_of_axis),
            period_ns: cfg.cycle().as_nanos() as u64,
            reply_ns: cfg.reply_timeout().as_nanos() as u64,
            cycle: 0,
            counting: false,
            shared,
        }
    }

    /// Every SubDevice is in OP.
    pub fn all_in_op(&self) -> bool {
        self.devices.all_in_op()
    }

    /// Takes the newest commands from `motion-io` (never blocks; a failed
    /// read keeps the previous ones), once per bus cycle, and applies the
    /// bus thread's own watchdog: no new command for [`watchdog_cycles`]
    /// bus cycles while they ask for normal operation (motion-io's main
    /// loop blocked, or gone without stopping) is the watchdog stop, run
    /// here without motion-io, until a new command comes.
    pub fn read_commands(&mut self) {
        if self.shared.commands.published() == 0 {
            return; // nothing from motion-io yet: disabled
        }
        if self.shared.commands.read(&mut self.cmd_words) {
            self.mode = match self.cmd_words[1] {
                MODE_WATCHDOG_STOP => Mode::WatchdogStop,
                MODE_EMERGENCY => Mode::Emergency,
                _ => Mode::Normal,
            };
            for (i, c) in self.newest.iter_mut().enumerate() {
                *c = words::command(&self.cmd_words, i);
            }
            if self.cmd_words[0] != self.generation {
                self.generation = self.cmd_words[0];
                self.silent_cycles = 0;
            }
        } else {
            // keep the previous commands
            self.shared
                .command_read_failures
                .fetch_add(1, Ordering::Relaxed);
        }
        self.silent_cycles += 1;
        let trips = self.silent_cycles > self.watchdog_cycles && self.mode == Mode::Normal;
        if trips && !self.watchdog {
            self.shared
                .bus_watchdog_trips
                .fetch_add(1, Ordering::Relaxed);
        }
        self.watchdog = trips;
        if trips {
            self.mode = Mode::WatchdogStop;
        }
        self.cmds.copy_from_slice(&self.newest);
        if self.mode == Mode::Normal {
            self.handoff.frame(self.cmd_words[2], &mut self.cmds);
        } else {
            self.handoff.reset();
        }
        self.shared
            .handoff_corrections
            .store(self.handoff.corrections, Ordering::Relaxed);
    }

    /// One exchange; returns the DC wait to the next cycle, if any.
    pub fn cycle(
        &mut self,
        io: &mut BusIo<'_>,
        group: &OpGroup,
        md: &MainDevice<'_>,
        start: u64,
    ) -> Option<Duration> {
        self.cycle += 1;
        for (k, plan) in self.plans.iter().enumerate() {
            if let Ok(sd) = group.subdevice(md, plan.sd) {
                let mut o = sd.outputs_raw_mut();
                plan.layout.pack_outputs(&self.outputs[k], &mut o);
            }
        }
        let result = {
            let fut = pin!(group.exchange(md));
            io.run(fut, Some(start + self.reply_ns), self.reply_ns)
        };
        let done = now_ns();
        let sh = &self.shared;
        sh.frames_sent.store(io.counters.sent, Ordering::Relaxed);
        sh.frames_received
            .store(io.counters.received, Ordering::Relaxed);
        sh.late_frames
            .store(io.counters.unmatched, Ordering::Relaxed);
        let validity = self.validity(result.as_ref(), start, done);
        let rest_mask = self.step_axes(&validity, group, md);
        self.fb_words[0] = self.cycle;
        self.fb_words[1] = done;
        self.fb_words[2] = FLAG_RUNNING | if self.watchdog { FLAG_BUS_WATCHDOG } else { 0 };
        self.fb_words[3] = rest_mask;
        self.shared.feedback.write(&self.fb_words);
        self.shared.cycles.store(self.cycle, Ordering::Relaxed);
        match result {
            Some(Ok(ex)) => ex.next_wait,
            _ => None,
        }
    }

    /// Which SubDevices' data is valid this cycle; notes who left or came
    /// back to OP (`done`: when the exchange ended).
    fn validity(
        &mut self,
        result: Option<&Result<Exchanged, Error>>,
        start: u64,
        done: u64,
    ) -> Validity {
        let sh = &self.shared;
        let mut v = Validity {
            frame_ok: false,
            valid: [false; MAX_SUBDEVICES],
            not_op: [false; MAX_SUBDEVICES],
        };
        let Some(Ok(ex)) = result else {
            if self.counting {
                sh.lost_frames.fetch_add(1, Ordering::Relaxed);
            }
            self.devices.frame_lost(done);
            self.devices.update(sh, self.counting);
            return v;
        };
        v.frame_ok = true;
        sh.record_roundtrip(done.saturating_sub(start));
        let count = self.contrib.len();
        let state = |i: usize| ex.states.get(i).copied().unwrap_or(SubDeviceState::None);
        let all_ok = ex.wkc == self.expected_wkc;
        let trusted = all_ok || explained(ex.wkc, self.expected_wkc, &self.contrib, state);
        if !all_ok && self.counting {
            sh.wkc_errors.fetch_add(1, Ordering::Relaxed);
        }
        for i in 0..count {
            let op = state(i) == SubDeviceState::Op;
            v.not_op[i] = !op;
            v.valid[i] = op && trusted;
            self.devices.observe(i, state(i), done);
        }
        self.devices.update(sh, self.counting);
        v
    }

    /// Every axis' step (`SW_NO_DATA` and the cause counted where its data
    /// is not valid); returns the at-rest mask.
    fn step_axes(&mut self, v: &Validity, group: &OpGroup, md: &MainDevice<'_>) -> u64 {
        let sh = &self.shared;
        let mut rest_mask = 0u64;
        for k in 0..self.axes.len() {
            let sdi = self.sd_of_axis[k];
            let inputs = if v.frame_ok && v.valid[sdi] {
                group
                    .subdevice(md, sdi)
                    .ok()
                    .map(|sd| self.plans[k].layout.unpack_inputs(&sd.inputs_raw()))
            } else {
                if self.counting {
                    let a = &sh.axis[k];
                    let cause = if !v.frame_ok {
                        &a.lost
                    } else if v.not_op[sdi] {
                        &a.not_op
                    } else {
                        &a.wkc
                    };
                    cause.fetch_add(1, Ordering::Relaxed);
                }
                None
            };
            let lost = self.devices.lost(sdi);
            if lost {
                self.axes[k].lost();
            }
            let (out, mut fb) = self.axes[k].step(&self.cmds[k], self.mode, inputs.as_ref());
            self.outputs[k] = out;
            if lost {
                // named as the drive's loss; nothing to stop there (its SM
                // watchdog stops it)
                fb.status_word = (fb.status_word | SW_DRIVE_LOST) & !SW_ENABLED;
                rest_mask |= 1 << k;
            } else if self.axes[k].at_rest_and_disabled() {
                rest_mask |= 1 << k;
            }
            let (a, c) = (&sh.axis[k], &self.axes[k].counters);
            a.rejected.store(c.rejected_setpoints, Ordering::Relaxed);
            a.gap_stops.store(c.gap_stops, Ordering::Relaxed);
            a.blind_stop_cycles
                .store(c.blind_stop_cycles, Ordering::Relaxed);
            words::put_feedback(&mut self.fb_words, k, &fb);
        }
        rest_mask
    }

    /// The next background job, if one is due.
    pub fn next_job(&mut self, now: u64) -> Option<Job> {
        if let Some(job) = self.devices.next_job(now) {
            return Some(job);
        }
        for (k, a) in self.axes.iter().enumerate() {
            if let Some(written) = self.window_written[k] {
                let want = a.following_error_window();
                if want != written
                    && !self.window_pending[k]
                    && self.devices.not_op_since[self.sd_of_axis[k]].is_none()
                {
                    self.window_pending[k] = true;
                    return Some(Job::Window {
                        axis: k,
                        value: want,
                    });
                }
            }
        }
        None
    }

    /// Counts how `job` ended (`None`: it timed out).
    pub fn job_done(&mut self, job: Job, r: Option<Result<Done, Error>>) {
        let sh = &self.shared;
        match (job, r) {
            (Job::Window { axis, value }, Some(Ok(_))) => {
                self.window_written[axis] = Some(value);
                self.window_pending[axis] = false;
                sh.axis[axis].window_writes.fetch_add(1, Ordering::Relaxed);
            }
            (Job::Window { axis, .. }, _) => {
                self.window_pending[axis] = false;
                sh.window_write_failures.fetch_add(1, Ordering::Relaxed);
            }
            (job, r) => self.devices.job_done(sh, job, r.and_then(Result::ok)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use SubDeviceState::{None as Silent, Op, PreOp, SafeOp};

    #[test]
    fn a_shortfall_is_explained_only_by_the_subdevices_out_of_op() {
        let contrib = [3, 3, 3];
        let at = |states: [SubDeviceState; 3]| move |i: usize| states[i];
        // one in SAFE-OP read but not written (1 of 3), or counted fully
        assert!(explained(7, 9, &contrib, at([Op, SafeOp, Op])));
        assert!(explained(9, 9, &contrib, at([Op, SafeOp, Op])));
        // one in PRE-OP: nothing counted
        assert!(explained(6, 9, &contrib, at([Op, Op, PreOp])));
        // a silent one counted nothing: less short than that is not it
        assert!(explained(6, 9, &contrib, at([Op, Silent, Op])));
        assert!(!explained(7, 9, &contrib, at([Op, Silent, Op])));
        // a silent one and one in SAFE-OP: 3 to 6 short
        assert!(explained(4, 9, &contrib, at([Silent, SafeOp, Op])));
        assert!(explained(3, 9, &contrib, at([Silent, SafeOp, Op])));
        assert!(!explained(2, 9, &contrib, at([Silent, SafeOp, Op])));
        // all in OP: a shortfall is nobody's in particular
        assert!(!explained(6, 9, &contrib, at([Op, Op, Op])));
        // more than expected: not trusted
        assert!(!explained(10, 9, &contrib, at([Op, SafeOp, Op])));
    }
}
