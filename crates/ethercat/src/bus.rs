//! The bus thread: ethercrab's `MainDevice` on the raw socket, start-up,
//! then the cycle ([`crate::cycle`]) until the backend is dropped.
//!
//! One cycle (period = the supervisor's cycle; with DC the wake-up follows
//! the reference clock, SYNC0 + half a cycle):
//!
//! 1. wait for the deadline on the socket (`ppoll`), progressing a
//!    background job meanwhile ([`crate::jobs`]: recovery of a SubDevice,
//!    an SDO write);
//! 2. take the newest commands from `motion-io` (seqlock, never blocks);
//!    none new for twice motion-io's watchdog is the watchdog stop, run by
//!    the bus thread itself ([`crate::cycle::watchdog_cycles`]);
//! 3. write the outputs prepared last cycle into the process image, exchange
//!    it (LRW + AL status of every SubDevice in one frame, + the DC time with
//!    DC) with a deadline of `reply_timeout`;
//! 4. per axis: data valid only if the frame came back, the SubDevice is in
//!    OP and the working counter matches (a shortfall explained by the
//!    SubDevices out of OP — silent, or answering from SAFE-OP, PRE-OP —
//!    leaves the others valid: `cycle::explained`);
//!    [`crate::axis::AxisLogic`] turns command + inputs into the next
//!    outputs and the feedback (`SW_NO_DATA` and the last values otherwise,
//!    counted per cause; a stop is sent without data too);
//! 5. publish the feedback (seqlock).
//!
//! A lost SubDevice ([`crate::health`]) is brought back when it answers
//! again: an AL error is acknowledged, SAFE-OP is asked for OP (every 20 ms,
//! one register access per cycle at most); one that lost its configuration
//! (power-cycled) is re-configured ([`crate::reconfigure`]). Leaving at exit
//! is bounded by [`EXIT_TIMEOUT_NS`], lost SubDevices or not.

use std::pin::pin;
use std::sync::atomic::Ordering;
use std::sync::mpsc::Sender;
use std::sync::Arc;
use std::time::Duration;

use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, RetryBehaviour, Timeouts};
use motion_config::EthercatBus;
use motion_rt::{enter_realtime, now_ns, RtConfig};

use crate::capacity::{MAX_FRAMES, MAX_PDU_DATA};
use crate::cycle::Engine;
use crate::group::OpGroup;
use crate::io::BusIo;
use crate::jobs::{self, Job};
use crate::reconfigure::{self, Recovery};
use crate::report::{StartupError, StartupReport};
use crate::startup::{self, Started};
use crate::status::Shared;

const STARTUP_IDLE_NS: u64 = 200_000;
const JOB_IDLE_NS: u64 = 100_000;
const OP_TIMEOUT_NS: u64 = 10_000_000_000;
/// Leaving OP (OP → SAFE-OP → PRE-OP → INIT) at exit takes at most this
/// long: SubDevices that do not answer any more are not waited for.
pub const EXIT_TIMEOUT_NS: u64 = 1_000_000_000;
/// Cycles after which the bus thread's allocations are counted.
pub const WARM_UP_CYCLES: u64 = 200;

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
    cfg: EthercatBus,
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
    let warnings: Vec<String> = rt
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
            dc_static_sync_iterations: cfg.keys.dc_static_sync_iterations,
            retry_behaviour: RetryBehaviour::Count(2),
        },
    );
    let interface = &cfg.keys.interface;
    let mut io = match BusIo::new(interface, tx, rx) {
        Ok(io) => io,
        Err(e) => {
            let _ = started.send(Err(StartupError(format!(
                "cannot open a raw socket on {interface}: {e} (needs CAP_NET_RAW and an existing \
                 interface)"
            ))));
            return;
        }
    };
    let (mut engine, group, mut report, recovery) =
        match bring_up(&cfg, &shared, &md, &mut io, t0, warnings) {
            Ok(x) => x,
            Err(e) => {
                let _ = started.send(Err(e));
                return;
            }
        };
    shared.running.store(true, Ordering::Release);
    engine.counting = true;
    report.rt = rt.to_string();
    report.duration = Duration::from_nanos(now_ns() - t0);
    if started.send(Ok(report)).is_err() {
        shared.stop.store(true, Ordering::Relaxed);
    }

    run_cycles(&mut engine, &mut io, &group, &md, &recovery);
    shared.running.store(false, Ordering::Release);
    let fut = pin!(group.leave(&md));
    let _ = io.run(fut, Some(now_ns() + EXIT_TIMEOUT_NS), STARTUP_IDLE_NS);
}

/// INIT → OP: start-up within its time limit from `t0`, then process data
/// cycled until every SubDevice reports OP. The report's `rt` and
/// `duration` are the caller's to fill.
fn bring_up(
    cfg: &EthercatBus,
    shared: &Arc<Shared>,
    md: &MainDevice<'_>,
    io: &mut BusIo<'_>,
    t0: u64,
    mut warnings: Vec<String>,
) -> Result<(Engine, OpGroup, StartupReport, Recovery), StartupError> {
    let deadline = t0 + cfg.startup_timeout().as_nanos() as u64;
    let result = {
        let fut = pin!(startup::startup(md, cfg, &mut warnings));
        io.run(fut, Some(deadline), STARTUP_IDLE_NS)
    };
    let Some(started) = result else {
        return Err(StartupError(format!(
            "start-up did not finish within {} s",
            cfg.startup_timeout().as_secs()
        )));
    };
    let Started {
        group,
        plans,
        reports,
        syncs,
    } = started?;
    let mut engine = Engine::new(shared.clone(), plans.clone(), cfg, &group, md);
    let op_deadline = now_ns() + OP_TIMEOUT_NS;
    let mut next = now_ns();
    loop {
        let start = now_ns();
        engine.cycle(io, &group, md, start);
        if engine.all_in_op() && engine.cycle > 1 {
            break;
        }
        if now_ns() > op_deadline {
            let stuck: Vec<String> = engine
                .devices
                .not_op_since
                .iter()
                .enumerate()
                .filter(|(_, s)| s.is_some())
                .map(|(i, _)| reports[i].name.clone())
                .collect();
            return Err(StartupError(format!(
                "SubDevices not in OP after {} s: {}",
                OP_TIMEOUT_NS / 1_000_000_000,
                stuck.join(", ")
            )));
        }
        next += engine.period_ns;
        io.receive(next);
    }
    let snapshots = {
        let fut = pin!(reconfigure::snapshot(&group, md, &engine.sd_of_axis));
        io.run(fut, Some(now_ns() + 1_000_000_000), STARTUP_IDLE_NS)
            .unwrap_or_default()
    };
    let recovery = Recovery {
        cfg: cfg.clone(),
        plans,
        syncs: syncs.clone(),
        names: reports.iter().map(|r| r.name.clone()).collect(),
        snapshots,
        shared: shared.clone(),
    };
    let report = StartupReport {
        axes: engine.sd_of_axis.iter().copied().zip(syncs).collect(),
        subdevices: reports,
        rt: String::new(),
        warnings,
        duration: Duration::ZERO,
    };
    Ok((engine, group, report, recovery))
}

/// The cycle loop, until `shared.stop`: wait for the deadline (a background
/// job progressing meanwhile), one cycle, the next deadline, the next job.
fn run_cycles(
    engine: &mut Engine,
    io: &mut BusIo<'_>,
    group: &OpGroup,
    md: &MainDevice<'_>,
    recovery: &Recovery,
) {
    let shared = engine.shared.clone();
    let sd_of_axis = engine.sd_of_axis.clone();
    let make = |job: Job| jobs::run(job, &sd_of_axis, recovery, group, md);
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
                } else if now_ns().saturating_sub(slot_started) > slot_job.timeout_ns() {
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
