//! The bus thread: ethercrab's `MainDevice` on the raw socket, start-up,
//! then the cycle.
//!
//! One cycle (period = the supervisor's cycle; with DC the wake-up follows
//! the reference clock, SYNC0 + half a cycle):
//!
//! 1. wait for the deadline on the socket (`ppoll`), progressing a
//!    background job meanwhile (recovery of a SubDevice, an SDO write);
//! 2. take the newest commands from `motion-io` (seqlock, never blocks);
//! 3. write the outputs prepared last cycle into the process image, exchange
//!    it (LRW + AL status of every SubDevice in one frame, + the DC time with
//!    DC) with a deadline of `reply_timeout`;
//! 4. per axis: data valid only if the frame came back, the SubDevice is in
//!    OP and the working counter matches (a shortfall exactly explained by
//!    SubDevices that did not answer their AL status read leaves the others
//!    valid); [`AxisLogic`] turns command + inputs into the next outputs and
//!    the feedback (`SW_NO_DATA` and the last values otherwise, counted per
//!    cause);
//! 5. publish the feedback (seqlock).
//!
//! A SubDevice out of OP is brought back when it answers again: an AL error
//! is acknowledged, SAFE-OP is asked for OP (every 20 ms, one register
//! access per cycle at most). A SubDevice found in INIT/PRE-OP has lost its
//! configuration (power cycle): counted in `needs_restart`, left alone.

use std::pin::pin;
use std::sync::atomic::Ordering;
use std::sync::mpsc::Sender;
use std::sync::Arc;
use std::time::Duration;

use ethercrab::error::Error;
use ethercrab::{
    DefaultLock, MainDevice, MainDeviceConfig, PduStorage, RetryBehaviour, SubDevicePdi,
    SubDeviceRef, SubDeviceState, Timeouts,
};
use motion_frames::{AxisCommand, AxisFeedback};
use motion_rt::{enter_realtime, now_ns, RtConfig};

use crate::axis::{AxisLogic, Mode};
use crate::config::EthercatConfig;
use crate::io::BusIo;
use crate::pdo::DriveOutputs;
use crate::startup::{self, AxisPlan, OpGroup, StartupError, StartupReport};
use crate::status::{
    Shared, AXIS_WORDS, FLAG_RUNNING, HEADER_WORDS, MODE_EMERGENCY, MODE_WATCHDOG_STOP,
};

/// Most SubDevices on the bus (and axes of one backend).
pub const MAX_SUBDEVICES: usize = 32;
/// Most process-image bytes.
pub const MAX_PDI: usize = 2048;
const MAX_FRAMES: usize = 32;
const MAX_PDU_DATA: usize = PduStorage::element_size(1100);

const STARTUP_IDLE_NS: u64 = 200_000;
const JOB_IDLE_NS: u64 = 100_000;
const OP_TIMEOUT_NS: u64 = 10_000_000_000;
const RECOVERY_INTERVAL_NS: u64 = 20_000_000;
const JOB_TIMEOUT_NS: u64 = 500_000_000;
const EXIT_TIMEOUT_NS: u64 = 3_000_000_000;
/// Cycles after which the bus thread's allocations are counted.
pub const WARM_UP_CYCLES: u64 = 200;

const _: () = {
    assert!(size_of::<AxisCommand>() == AXIS_WORDS * 8);
    assert!(size_of::<AxisFeedback>() == AXIS_WORDS * 8);
};

/// Frame words → command. The frames are `#[repr(C)]`, 48 bytes without
/// padding (pinned in motion-frames), made of integers and floats only.
pub(crate) fn command_from_words(w: &[u64]) -> AxisCommand {
    let mut a = [0u64; AXIS_WORDS];
    a.copy_from_slice(&w[..AXIS_WORDS]);
    // SAFETY: same size, no padding, every bit pattern is a valid value.
    unsafe { core::mem::transmute::<[u64; AXIS_WORDS], AxisCommand>(a) }
}

pub(crate) fn command_to_words(c: &AxisCommand, w: &mut [u64]) {
    // SAFETY: as above; a fully initialised value of the same size.
    let a = unsafe { core::mem::transmute::<AxisCommand, [u64; AXIS_WORDS]>(*c) };
    w[..AXIS_WORDS].copy_from_slice(&a);
}

pub(crate) fn feedback_from_words(w: &[u64]) -> AxisFeedback {
    let mut a = [0u64; AXIS_WORDS];
    a.copy_from_slice(&w[..AXIS_WORDS]);
    // SAFETY: as for commands.
    unsafe { core::mem::transmute::<[u64; AXIS_WORDS], AxisFeedback>(a) }
}

pub(crate) fn feedback_to_words(f: &AxisFeedback, w: &mut [u64]) {
    // SAFETY: as for commands.
    let a = unsafe { core::mem::transmute::<AxisFeedback, [u64; AXIS_WORDS]>(*f) };
    w[..AXIS_WORDS].copy_from_slice(&a);
}

type Pdi<'a> = SubDeviceRef<'a, SubDevicePdi<'a, MAX_PDI, DefaultLock>>;

impl OpGroup {
    fn subdevice<'a>(&'a self, md: &'a MainDevice<'a>, i: usize) -> Result<Pdi<'a>, Error> {
        match self {
            OpGroup::FreeRun(g) => g.subdevice(md, i),
            OpGroup::Dc(g) => g.subdevice(md, i),
        }
    }

    fn len(&self) -> usize {
        match self {
            OpGroup::FreeRun(g) => g.len(),
            OpGroup::Dc(g) => g.len(),
        }
    }
}

struct Exchanged {
    wkc: u16,
    states: heapless::Vec<SubDeviceState, MAX_SUBDEVICES>,
    next_wait: Option<Duration>,
}

async fn exchange(group: &OpGroup, md: &MainDevice<'_>) -> Result<Exchanged, Error> {
    match group {
        OpGroup::FreeRun(g) => {
            let r = g.tx_rx(md).await?;
            Ok(Exchanged {
                wkc: r.working_counter,
                states: r.subdevice_states,
                next_wait: None,
            })
        }
        OpGroup::Dc(g) => {
            let r = g.tx_rx_dc(md).await?;
            Ok(Exchanged {
                wkc: r.working_counter,
                states: r.subdevice_states,
                next_wait: Some(r.extra.next_cycle_wait),
            })
        }
    }
}

/// Background jobs between cycles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Job {
    Recover(usize),
    Window { axis: usize, value: u32 },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Done {
    Acknowledged,
    OpRequested,
    AlreadyOp,
    LostConfiguration,
    WindowWritten,
}

async fn run_job(
    job: Job,
    sd_of_axis: &[usize],
    group: &OpGroup,
    md: &MainDevice<'_>,
) -> Result<Done, Error> {
    match job {
        Job::Recover(i) => {
            let sd = group.subdevice(md, i)?;
            let st: u16 = sd.register_read(0x0130u16).await?;
            if st & 0x10 != 0 {
                sd.register_write(0x0120u16, (st & 0x0F) | 0x10).await?;
                return Ok(Done::Acknowledged);
            }
            match st & 0x0F {
                0x08 => Ok(Done::AlreadyOp),
                0x04 => {
                    sd.register_write(0x0120u16, 0x0008u16).await?;
                    Ok(Done::OpRequested)
                }
                _ => Ok(Done::LostConfiguration),
            }
        }
        Job::Window { axis, value } => {
            let sd = group.subdevice(md, sd_of_axis[axis])?;
            sd.sdo_write(0x6065, 0, value).await?;
            Ok(Done::WindowWritten)
        }
    }
}

/// Per-cycle state of the bus.
struct Engine {
    shared: Arc<Shared>,
    axes: Vec<AxisLogic>,
    plans: Vec<AxisPlan>,
    sd_of_axis: Vec<usize>,
    outputs: Vec<DriveOutputs>,
    /// Working-counter contribution of each SubDevice (1 inputs, 2 outputs).
    contrib: Vec<u16>,
    expected_wkc: u16,
    cmd_words: Vec<u64>,
    fb_words: Vec<u64>,
    cmds: Vec<AxisCommand>,
    mode: Mode,
    window_written: Vec<Option<u32>>,
    window_pending: Vec<bool>,
    /// Per SubDevice: not in OP since (ns), last recovery attempt (ns).
    not_op_since: Vec<Option<u64>>,
    /// Per SubDevice: answered its AL status read last cycle.
    answering: Vec<bool>,
    last_recovery: Vec<u64>,
    given_up: Vec<bool>,
    period_ns: u64,
    reply_ns: u64,
    cycle: u64,
    /// Counting no-data causes (not while waiting for OP at start-up).
    counting: bool,
}

impl Engine {
    fn new(
        shared: Arc<Shared>,
        plans: Vec<AxisPlan>,
        cfg: &EthercatConfig,
        group: &OpGroup,
        md: &MainDevice<'_>,
    ) -> Engine {
        let n = plans.len();
        let cycle_s = cfg.cycle.as_secs_f64();
        let axes = plans
            .iter()
            .zip(&cfg.axes)
            .map(|(p, a)| AxisLogic::new(p.layout, cycle_s, a.index_pulse_bit))
            .collect();
        let count = group.len();
        let mut contrib = vec![0u16; count];
        for (i, c) in contrib.iter_mut().enumerate() {
            if let Ok(sd) = group.subdevice(md, i) {
                let io = sd.io_raw();
                *c = u16::from(!io.inputs().is_empty()) + 2 * u16::from(!io.outputs().is_empty());
            }
        }
        let words = HEADER_WORDS + n * AXIS_WORDS;
        let window_written = plans
            .iter()
            .map(|p| p.has_window.then_some(u32::MAX))
            .collect();
        Engine {
            axes,
            sd_of_axis: plans.iter().map(|p| p.sd).collect(),
            outputs: plans
                .iter()
                .map(|_| DriveOutputs {
                    mode: crate::pdo::MODE_CSP,
                    ..DriveOutputs::default()
                })
                .collect(),
            plans,
            expected_wkc: contrib.iter().sum(),
            contrib,
            cmd_words: vec![0; words],
            fb_words: vec![0; words],
            cmds: vec![AxisCommand::ZERO; n],
            mode: Mode::Normal,
            window_written,
            window_pending: vec![false; n],
            not_op_since: vec![None; count],
            answering: vec![true; count],
            last_recovery: vec![0; count],
            given_up: vec![false; count],
            period_ns: cfg.cycle.as_nanos() as u64,
            reply_ns: cfg.reply_timeout().as_nanos() as u64,
            cycle: 0,
            counting: false,
            shared,
        }
    }

    fn read_commands(&mut self) {
        if self.shared.commands.published() == 0 {
            return; // nothing from motion-io yet: disabled
        }
        if !self.shared.commands.read(&mut self.cmd_words) {
            self.shared
                .command_read_failures
                .fetch_add(1, Ordering::Relaxed);
            return; // keep the previous commands
        }
        self.mode = match self.cmd_words[1] {
            MODE_WATCHDOG_STOP => Mode::WatchdogStop,
            MODE_EMERGENCY => Mode::Emergency,
            _ => Mode::Normal,
        };
        for (i, c) in self.cmds.iter_mut().enumerate() {
            let at = HEADER_WORDS + i * AXIS_WORDS;
            *c = command_from_words(&self.cmd_words[at..at + AXIS_WORDS]);
        }
    }

    /// One exchange; returns the DC wait to the next cycle, if any.
    fn cycle(
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
            let fut = pin!(exchange(group, md));
            io.run(fut, Some(start + self.reply_ns), self.reply_ns)
        };
        let done = now_ns();
        let sh = &self.shared;
        sh.frames_sent.store(io.counters.sent, Ordering::Relaxed);
        sh.frames_received
            .store(io.counters.received, Ordering::Relaxed);
        sh.late_frames
            .store(io.counters.unmatched, Ordering::Relaxed);

        // validity per SubDevice
        let count = self.contrib.len();
        let mut valid = [false; MAX_SUBDEVICES];
        let mut cause_not_op = [false; MAX_SUBDEVICES];
        let mut next_wait = None;
        let frame_ok = match &result {
            Some(Ok(ex)) => {
                sh.record_roundtrip(done.saturating_sub(start));
                next_wait = ex.next_wait;
                let state = |i: usize| ex.states.get(i).copied().unwrap_or(SubDeviceState::None);
                let silent: u16 = (0..count)
                    .filter(|&i| state(i) == SubDeviceState::None)
                    .map(|i| self.contrib[i])
                    .sum();
                let all_ok = ex.wkc == self.expected_wkc;
                let explained = !all_ok && self.expected_wkc.checked_sub(ex.wkc) == Some(silent);
                if !all_ok && self.counting {
                    sh.wkc_errors.fetch_add(1, Ordering::Relaxed);
                }
                for i in 0..count {
                    self.answering[i] = state(i) != SubDeviceState::None;
                    let op = state(i) == SubDeviceState::Op;
                    cause_not_op[i] = !op;
                    valid[i] = op && (all_ok || explained);
                    match (op, self.not_op_since[i]) {
                        (true, Some(_)) => {
                            self.not_op_since[i] = None;
                            self.given_up[i] = false;
                        }
                        (false, None) => self.not_op_since[i] = Some(done),
                        _ => {}
                    }
                }
                true
            }
            _ => {
                if self.counting {
                    sh.lost_frames.fetch_add(1, Ordering::Relaxed);
                }
                false
            }
        };

        // axes
        let mut rest_mask = 0u64;
        for k in 0..self.axes.len() {
            let sdi = self.sd_of_axis[k];
            let ok = frame_ok && valid[sdi];
            let inputs = if ok {
                group
                    .subdevice(md, sdi)
                    .ok()
                    .map(|sd| self.plans[k].layout.unpack_inputs(&sd.inputs_raw()))
            } else if !self.counting {
                None
            } else {
                let a = &sh.axis[k];
                if !frame_ok {
                    a.lost.fetch_add(1, Ordering::Relaxed);
                } else if cause_not_op[sdi] {
                    a.not_op.fetch_add(1, Ordering::Relaxed);
                } else {
                    a.wkc.fetch_add(1, Ordering::Relaxed);
                }
                None
            };
            let (out, fb) = self.axes[k].step(&self.cmds[k], self.mode, inputs.as_ref());
            self.outputs[k] = out;
            if self.axes[k].at_rest_and_disabled() {
                rest_mask |= 1 << k;
            }
            sh.axis[k]
                .rejected
                .store(self.axes[k].counters.rejected_setpoints, Ordering::Relaxed);
            let at = HEADER_WORDS + k * AXIS_WORDS;
            feedback_to_words(&fb, &mut self.fb_words[at..at + AXIS_WORDS]);
        }
        self.fb_words[0] = self.cycle;
        self.fb_words[1] = done;
        self.fb_words[2] = FLAG_RUNNING;
        self.fb_words[3] = rest_mask;
        sh.feedback.write(&self.fb_words);
        sh.cycles.store(self.cycle, Ordering::Relaxed);
        next_wait
    }

    /// The next background job, if one is due.
    fn next_job(&mut self, now: u64) -> Option<Job> {
        for i in 0..self.contrib.len() {
            if let Some(since) = self.not_op_since[i] {
                if !self.given_up[i]
                    && self.answering[i]
                    && now.saturating_sub(since) >= RECOVERY_INTERVAL_NS / 4
                    && now.saturating_sub(self.last_recovery[i]) >= RECOVERY_INTERVAL_NS
                {
                    self.last_recovery[i] = now;
                    return Some(Job::Recover(i));
                }
            }
        }
        for (k, a) in self.axes.iter().enumerate() {
            if let Some(written) = self.window_written[k] {
                let want = a.following_error_window();
                if want != written
                    && !self.window_pending[k]
                    && self.not_op_since[self.sd_of_axis[k]].is_none()
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

    fn job_done(&mut self, job: Job, r: Option<Result<Done, Error>>) {
        let sh = &self.shared;
        match (job, r) {
            (Job::Recover(_), Some(Ok(Done::OpRequested))) => {
                sh.recoveries.fetch_add(1, Ordering::Relaxed);
            }
            (Job::Recover(i), Some(Ok(Done::LostConfiguration))) => {
                sh.needs_restart.fetch_add(1, Ordering::Relaxed);
                self.given_up[i] = true;
            }
            (Job::Recover(_), Some(Ok(_))) => {}
            (Job::Recover(_), _) => {
                sh.recovery_failures.fetch_add(1, Ordering::Relaxed);
            }
            (Job::Window { axis, value }, Some(Ok(_))) => {
                self.window_written[axis] = Some(value);
                self.window_pending[axis] = false;
                sh.axis[axis].window_writes.fetch_add(1, Ordering::Relaxed);
            }
            (Job::Window { axis, .. }, _) => {
                self.window_pending[axis] = false;
                sh.window_write_failures.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}

fn timeouts() -> Timeouts {
    Timeouts {
        state_transition: Duration::from_secs(10),
        pdu: Duration::from_millis(100),
        eeprom: Duration::from_millis(100),
        wait_loop_delay: Duration::from_micros(200),
        mailbox_echo: Duration::from_millis(500),
        mailbox_response: Duration::from_secs(2),
    }
}

/// The thread body. Sends the start-up result, then cycles until
/// `shared.stop`.
pub(crate) fn thread_main(
    cfg: EthercatConfig,
    shared: Arc<Shared>,
    started: Sender<Result<StartupReport, StartupError>>,
) {
    let t0 = now_ns();
    let rt = enter_realtime(&RtConfig {
        cpu: cfg.cpu,
        priority: cfg.priority,
        lock_memory: cfg.lock_memory,
        prefault_stack: 256 * 1024,
    });
    let mut warnings: Vec<String> = rt
        .warnings
        .iter()
        .map(|w| format!("bus thread: {w}"))
        .collect();

    let storage: Box<PduStorage<MAX_FRAMES, MAX_PDU_DATA>> = Box::new(PduStorage::new());
    let Ok((tx, rx, pdu_loop)) = storage.try_split() else {
        let _ = started.send(Err(StartupError("frame storage already in use".into())));
        return;
    };
    let md = MainDevice::new(
        pdu_loop,
        timeouts(),
        MainDeviceConfig {
            dc_static_sync_iterations: cfg.dc_static_sync_iterations,
            retry_behaviour: RetryBehaviour::Count(2),
        },
    );
    let mut io = match BusIo::new(&cfg.interface, tx, rx) {
        Ok(io) => io,
        Err(e) => {
            let _ = started.send(Err(StartupError(format!(
                "cannot open a raw socket on {}: {e} (needs CAP_NET_RAW and an existing \
                 interface)",
                cfg.interface
            ))));
            return;
        }
    };

    let deadline = t0 + cfg.startup_timeout.as_nanos() as u64;
    let result = {
        let fut = pin!(startup::startup(&md, &cfg, &mut warnings));
        io.run(fut, Some(deadline), STARTUP_IDLE_NS)
    };
    let (group, plans, reports, syncs) = match result {
        None => {
            let _ = started.send(Err(StartupError(format!(
                "start-up did not finish within {} s",
                cfg.startup_timeout.as_secs()
            ))));
            return;
        }
        Some(Err(e)) => {
            let _ = started.send(Err(e));
            return;
        }
        Some(Ok(x)) => x,
    };

    let mut engine = Engine::new(shared.clone(), plans, &cfg, &group, &md);
    // cycle until every SubDevice is in OP
    let op_deadline = now_ns() + OP_TIMEOUT_NS;
    let mut next = now_ns();
    loop {
        let start = now_ns();
        engine.cycle(&mut io, &group, &md, start);
        if engine.not_op_since.iter().all(Option::is_none) && engine.cycle > 1 {
            break;
        }
        if now_ns() > op_deadline {
            let stuck: Vec<String> = engine
                .not_op_since
                .iter()
                .enumerate()
                .filter(|(_, s)| s.is_some())
                .map(|(i, _)| reports[i].name.clone())
                .collect();
            let _ = started.send(Err(StartupError(format!(
                "SubDevices not in OP after {} s: {}",
                OP_TIMEOUT_NS / 1_000_000_000,
                stuck.join(", ")
            ))));
            return;
        }
        next += engine.period_ns;
        io.receive(next);
    }

    shared.running.store(true, Ordering::Release);
    engine.counting = true;
    let report = StartupReport {
        axes: engine.sd_of_axis.iter().copied().zip(syncs).collect(),
        subdevices: reports,
        rt: rt.to_string(),
        warnings,
        duration: Duration::from_nanos(now_ns() - t0),
    };
    if started.send(Ok(report)).is_err() {
        shared.stop.store(true, Ordering::Relaxed);
    }

    run_cycles(&mut engine, &mut io, &group, &md);
    shared.running.store(false, Ordering::Release);

    // leave orderly: the drives see their outputs go invalid (OP → SAFE-OP)
    // and stop on their own ramp; then INIT
    let fut = pin!(async {
        match group {
            OpGroup::FreeRun(g) => {
                let g = g.into_safe_op(&md).await?;
                let g = g.into_pre_op(&md).await?;
                g.into_init(&md).await.map(|_| ())
            }
            OpGroup::Dc(g) => {
                let g = g.into_safe_op(&md).await?;
                let g = g.into_pre_op(&md).await?;
                g.into_init(&md).await.map(|_| ())
            }
        }
    });
    let _ = io.run(fut, Some(now_ns() + EXIT_TIMEOUT_NS), STARTUP_IDLE_NS);
}

fn run_cycles(engine: &mut Engine, io: &mut BusIo<'_>, group: &OpGroup, md: &MainDevice<'_>) {
    let shared = engine.shared.clone();
    let sd_of_axis = engine.sd_of_axis.clone();
    let make = |job: Job| run_job(job, &sd_of_axis, group, md);
    let mut slot = pin!(if false {
        Some(make(Job::Recover(0)))
    } else {
        None
    });
    let mut slot_job = Job::Recover(0);
    let mut slot_started = 0u64;
    let period = engine.period_ns;
    let mut deadline = now_ns() + period;
    let mut cycles = 0u64;
    let mut alloc_base = 0u64;
    while !shared.stop.load(Ordering::Relaxed) {
        cycles += 1;
        let allocs = motion_rt::counting::system_calls_on_this_thread();
        if cycles == WARM_UP_CYCLES {
            alloc_base = allocs;
        } else if cycles > WARM_UP_CYCLES {
            shared
                .bus_allocations
                .store(allocs.wrapping_sub(alloc_base), Ordering::Relaxed);
        }
        // wait, with the background job progressing
        loop {
            if let Some(f) = slot.as_mut().as_pin_mut() {
                if let Some(r) = io.poll_once(f) {
                    slot.set(None);
                    engine.job_done(slot_job, Some(r));
                } else if now_ns().saturating_sub(slot_started) > JOB_TIMEOUT_NS {
                    slot.set(None);
                    engine.job_done(slot_job, None);
                }
            }
            let now = now_ns();
            if now >= deadline {
                break;
            }
            let wake = if slot.is_some() {
                deadline.min(now + JOB_IDLE_NS)
            } else {
                deadline
            };
            io.receive(wake);
        }
        let start = now_ns();
        engine.read_commands();
        let dc_wait = engine.cycle(io, group, md, start);
        // next deadline: the DC reference clock, else the free-running period
        let now = now_ns();
        deadline = match dc_wait {
            Some(w) => start + w.as_nanos() as u64,
            None => deadline + period,
        };
        if deadline <= now {
            let behind = (now - deadline) / period + 1;
            shared.overruns.fetch_add(behind, Ordering::Relaxed);
            deadline += behind * period;
        }
        if slot.is_none() {
            if let Some(job) = engine.next_job(now) {
                slot_job = job;
                slot_started = now;
                slot.set(Some(make(job)));
            }
        }
    }
}
