//! The main loop: wait for a command, apply it, answer; the watchdog; the
//! orderly stop on SIGINT/SIGTERM.
//!
//! # Timing
//!
//! Event mode sleeps in [`IoPorts::wait_until`] (`ppoll` on the listener,
//! an hrtimer-exact timeout) until the supervisor's `command_ready` wake-up
//! or the next *tick*; `--spin` polls the subscriber instead. Ticks are the clock of everything that happens without a command.
//! While commands flow there is one tick, at the watchdog's deadline: the
//! missed cycles are the time since the last command divided by the cycle,
//! and `io_watchdog_cycles` of them trip it. Once tripped, every tick (one per
//! cycle) is one cycle of the controlled stop. Before the first command and
//! after the stop the loop ticks at [`IDLE_PERIOD_NS`] only (a command still
//! wakes it at once).
//!
//! (iceoryx2's own `timed_wait` counts its timeout in jiffies — 4 ms at
//! HZ=250 — and is therefore not used.)

use std::time::Duration;

use motion_frames::backend::Backend;
use motion_frames::FeedbackFrame;
use motion_ipc::{monotonic_ns, Domain, IoPorts, IpcError};

use crate::say::{Once, Say};
use motion_rt::termination as signals;

/// Tick period while nothing is under command (before the first command,
/// after the watchdog stop): the status heartbeat and the exit checks.
pub const IDLE_PERIOD_NS: u64 = 100_000_000;
/// `--exit-with-supervisor`: exit when no command arrived this long after start.
pub const FIRST_COMMAND_TIMEOUT_NS: u64 = 10_000_000_000;
/// `--exit-with-supervisor`: exit this long after the watchdog stop completed.
pub const EXIT_AFTER_STOP_NS: u64 = 1_000_000_000;
/// Shortest timeout handed to `Ports::wait`: iceoryx2 passes it on as
/// `SO_RCVTIMEO` with µs resolution, and 0 there means "block forever".
const MIN_WAIT_NS: u64 = 2_000;

/// What the loop needs from the config and the command line.
#[derive(Clone, Debug)]
pub struct Settings {
    pub cycle_ns: u64,
    pub watchdog_cycles: u32,
    pub spin: bool,
    pub exit_with_supervisor: bool,
    pub say: Say,
    /// Where the supervisor's session file is, to notice a new session.
    pub prefix: String,
    pub runtime_dir: std::path::PathBuf,
}

/// Why the loop ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// SIGINT/SIGTERM: every axis stopped. Exit 0.
    Signal,
    /// `--exit-with-supervisor`: the supervisor went silent, every axis was
    /// stopped. Exit 0.
    SupervisorGone,
    /// `--exit-with-supervisor`: no command ever arrived. Exit 1.
    NoSupervisor,
    /// The supervisor was restarted (a new session): join it.
    Rejoin,
}

impl Outcome {
    pub fn exit_code(self) -> i32 {
        match self {
            Outcome::Signal | Outcome::SupervisorGone | Outcome::Rejoin => 0,
            Outcome::NoSupervisor => 1,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// No command ever arrived; the watchdog is not armed.
    Waiting,
    /// Commands are flowing.
    Running,
    /// The watchdog tripped: stopping every axis, one cycle per tick.
    Stopping,
    /// Every axis at rest and disabled since `since` (ns).
    Stopped { since: u64 },
}

/// Failures reported once per episode.
#[derive(Default)]
struct Faults {
    forged: Once,
    wait: Once,
    receive: Once,
    bad_frame: Once,
    mismatch: Once,
    publish: Once,
    notify: Once,
    connect: Once,
}

struct Loop<'a> {
    /// Id of the session joined.
    session_id: String,
    ports: &'a mut IoPorts,
    backend: &'a mut dyn Backend,
    s: &'a Settings,
    phase: Phase,
    start_ns: u64,
    last_command_ns: u64,
    next_tick_ns: u64,
    /// Feedback written here when no shared-memory sample could be loaned, so
    /// that the drives are still served.
    scratch: Box<FeedbackFrame>,
    faults: Faults,
    commands: u64,
}

/// Runs until a signal arrives or (with `--exit-with-supervisor`) the
/// supervisor is gone. Never panics on bad frames or IPC failures: they are
/// reported once and the loop carries on.
pub fn run(
    ports: &mut IoPorts,
    backend: &mut dyn Backend,
    s: &Settings,
    session_id: &str,
) -> Outcome {
    let now = monotonic_ns();
    let mut l = Loop {
        session_id: session_id.to_string(),
        ports,
        backend,
        s,
        phase: Phase::Waiting,
        start_ns: now,
        last_command_ns: now,
        next_tick_ns: now + IDLE_PERIOD_NS,
        scratch: Box::new(FeedbackFrame::ZERO),
        faults: Faults::default(),
        commands: 0,
    };
    l.run()
}

impl Loop<'_> {
    fn say(&self) -> Say {
        self.s.say
    }

    /// When the watchdog trips if no command comes.
    fn watchdog_deadline(&self) -> u64 {
        self.last_command_ns + u64::from(self.s.watchdog_cycles) * self.s.cycle_ns
    }

    fn dt_s(&self) -> f64 {
        self.s.cycle_ns as f64 * 1e-9
    }

    fn run(&mut self) -> Outcome {
        loop {
            crate::stall::if_asked();
            if signals::received().is_some() {
                self.stop_on_signal();
                return Outcome::Signal;
            }
            let timeout = self.next_tick_ns.saturating_sub(monotonic_ns());
            if !self.s.spin && timeout >= MIN_WAIT_NS {
                match self.ports.wait_until(self.next_tick_ns) {
                    Ok(_) => {
                        self.faults.wait.clear();
                    }
                    // EINTR: a wake-up like any other; the flag is checked above
                    Err(IpcError::Interrupted { .. }) => continue,
                    Err(e) => {
                        let say = self.say();
                        self.faults.wait.fail(&say, format_args!("{e}"));
                        // do not turn a broken listener into a busy loop
                        std::thread::sleep(Duration::from_nanos(timeout.max(1_000_000)));
                    }
                }
            }
            self.poll_command();
            let now = monotonic_ns();
            if now >= self.next_tick_ns {
                if let Some(outcome) = self.tick(now) {
                    return outcome;
                }
            } else if self.s.spin {
                std::hint::spin_loop();
            }
        }
    }

    /// Takes the newest command, if any, and answers it.
    fn poll_command(&mut self) {
        let say = self.say();
        let sample = match self.ports.receive_latest() {
            Ok(Some(sample)) => sample,
            Ok(None) => {
                self.faults.receive.clear();
                return;
            }
            Err(e @ IpcError::Forged { .. }) => {
                self.faults.receive.clear();
                self.faults.forged.fail(
                    &say,
                    format_args!(
                        "{e}; refused {} so far, never applied",
                        self.ports.refused()
                    ),
                );
                return;
            }
            Err(e @ IpcError::Layout { .. }) => {
                self.faults.receive.clear();
                self.faults.bad_frame.fail(
                    &say,
                    format_args!("{e}: ignoring frames until a good one arrives"),
                );
                return;
            }
            Err(e) => {
                self.faults.receive.fail(&say, format_args!("{e}"));
                return;
            }
        };
        let taken = monotonic_ns();
        self.faults.receive.clear();
        self.faults.forged.clear();
        if self.faults.bad_frame.clear() {
            say.info(format_args!("good command frames again"));
        }
        let sequence = sample.header.sequence;
        match self.phase {
            Phase::Running => {}
            Phase::Waiting => {
                say.info(format_args!(
                    "first command (sequence {sequence}): serving the supervisor"
                ));
                self.connect();
            }
            Phase::Stopping | Phase::Stopped { .. } => {
                say.always(format_args!("commands resumed"));
                self.connect();
            }
        }
        self.phase = Phase::Running;
        self.commands += 1;
        self.last_command_ns = taken;
        self.next_tick_ns = self.watchdog_deadline();

        let backend = &mut *self.backend;
        let mut result = None;
        let published = self.ports.publish(|f| {
            result = Some(backend.exchange(&sample, f));
            f.answers_sequence = sequence;
            f.io_received_ns = taken;
        });
        if let Err(e) = &published {
            self.faults.publish.fail(&say, format_args!("{e}"));
        } else {
            self.faults.publish.clear();
        }
        // no sample could be loaned: still serve the drives
        let result = result.unwrap_or_else(|| backend.exchange(&sample, &mut self.scratch));
        drop(sample);
        if published.is_ok() {
            self.notify();
        }
        match result {
            Ok(()) => {
                self.faults.mismatch.clear();
            }
            Err(e) => self.faults.mismatch.fail(&say, format_args!("{e}")),
        }
    }

    fn connect(&mut self) {
        let say = self.say();
        match self.ports.update_connections() {
            Ok(()) => {
                self.faults.connect.clear();
            }
            Err(e) => self.faults.connect.fail(&say, format_args!("{e}")),
        }
    }

    fn notify(&mut self) {
        let say = self.say();
        match self.ports.notify() {
            Ok(_) => {
                self.faults.notify.clear();
            }
            Err(e) => self.faults.notify.fail(&say, format_args!("{e}")),
        }
    }

    /// Publishes a feedback frame that answers no command, filled by `fill`
    /// (run on the scratch frame if no sample can be loaned). Returns what
    /// `fill` returned.
    fn publish_unsolicited(
        &mut self,
        mut fill: impl FnMut(&mut dyn Backend, &mut FeedbackFrame) -> bool,
    ) -> bool {
        let say = self.say();
        let backend = &mut *self.backend;
        let mut result = None;
        let published = self.ports.publish(|f| {
            result = Some(fill(backend, f));
            f.answers_sequence = 0;
            f.io_received_ns = 0;
        });
        match &published {
            Ok(_) => {
                self.faults.publish.clear();
            }
            Err(e) => self.faults.publish.fail(&say, format_args!("{e}")),
        }
        let result = result.unwrap_or_else(|| fill(backend, &mut self.scratch));
        if published.is_ok() {
            self.notify();
        }
        result
    }

    /// A supervisor with another session runs now under our prefix.
    fn new_session(&self) -> bool {
        matches!(
            Domain::read_session(&self.s.runtime_dir, &self.s.prefix),
            Ok(d) if d.id != self.session_id
        )
    }

    /// Everything that happens without a command.
    fn tick(&mut self, now: u64) -> Option<Outcome> {
        let say = self.say();
        let cycle = self.s.cycle_ns;
        if matches!(self.phase, Phase::Waiting | Phase::Stopped { .. }) && self.new_session() {
            say.info(format_args!(
                "a new supervisor session started under prefix {:?}: joining it",
                self.s.prefix
            ));
            return Some(Outcome::Rejoin);
        }
        match self.phase {
            Phase::Waiting => {
                if self.s.exit_with_supervisor
                    && now.saturating_sub(self.start_ns) >= FIRST_COMMAND_TIMEOUT_NS
                {
                    say.always(format_args!(
                        "error: no command from the supervisor within {} s of start; is it \
                         running with the same service_prefix? exiting",
                        FIRST_COMMAND_TIMEOUT_NS / 1_000_000_000
                    ));
                    return Some(Outcome::NoSupervisor);
                }
                self.next_tick_ns = now + IDLE_PERIOD_NS;
            }
            Phase::Running => {
                let silent = now.saturating_sub(self.last_command_ns);
                let missed = silent / cycle;
                if missed >= u64::from(self.s.watchdog_cycles) {
                    // the stop first: saying so can wait (and never blocks)
                    self.phase = Phase::Stopping;
                    let done = self.stop_cycle(now);
                    say.always(format_args!(
                        "watchdog: no command for {missed} cycles ({:.1} ms): stopping every axis",
                        silent as f64 * 1e-6
                    ));
                    if done {
                        self.say_stopped();
                    }
                    if self.phase == Phase::Stopping {
                        self.next_tick_ns = now + cycle;
                    }
                } else {
                    // (not reached: the tick is the watchdog deadline)
                    self.next_tick_ns = self.watchdog_deadline();
                }
            }
            Phase::Stopping => {
                if self.stop_cycle(now) {
                    self.say_stopped();
                }
                if self.phase == Phase::Stopping {
                    self.next_tick_ns += cycle;
                    if self.next_tick_ns <= now {
                        // fell behind (the process was not scheduled): keep
                        // the cycle length, drop the missed ticks
                        self.next_tick_ns = now + cycle;
                    }
                }
            }
            Phase::Stopped { since } => {
                if self.s.exit_with_supervisor && now.saturating_sub(since) >= EXIT_AFTER_STOP_NS {
                    say.info(format_args!(
                        "no command since the stop: the supervisor is gone; exiting"
                    ));
                    return Some(Outcome::SupervisorGone);
                }
                // status heartbeat for a supervisor that attaches now
                self.publish_unsolicited(|b, f| {
                    b.status(f);
                    true
                });
                self.next_tick_ns = now + IDLE_PERIOD_NS;
            }
        }
        None
    }

    /// One cycle of the watchdog stop; `true` when it completed now.
    fn stop_cycle(&mut self, now: u64) -> bool {
        let dt = self.dt_s();
        let done = self.publish_unsolicited(|b, f| b.watchdog_stop(dt, f));
        if done {
            self.phase = Phase::Stopped { since: now };
            // first exit check / heartbeat one idle period from now
            self.next_tick_ns = now + IDLE_PERIOD_NS.min(EXIT_AFTER_STOP_NS);
        }
        done
    }

    fn say_stopped(&self) {
        self.say()
            .always(format_args!("watchdog: every axis stopped and disabled"));
    }

    /// SIGINT/SIGTERM: controlled stop of every axis (simulated at once,
    /// bounded), one last feedback frame; said after the stop.
    fn stop_on_signal(&mut self) {
        let say = self.say();
        let dt = self.dt_s();
        let controlled = self.publish_unsolicited(|b, f| b.shutdown(dt, f));
        say.info(format_args!(
            "{} received after {} commands: stopping every axis",
            signals::received_name().unwrap_or("signal"),
            self.commands
        ));
        if controlled {
            say.info(format_args!("signal: every axis stopped"));
        } else {
            say.always(format_args!(
                "signal: every axis stopped (some could not be ramped down in time and \
                 were disabled at once)"
            ));
        }
    }
}
