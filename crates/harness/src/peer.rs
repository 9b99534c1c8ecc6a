//! The supervisor's side of one I/O process, played by a test over
//! iceoryx2: it claims the prefix (the session file `motion-io` joins
//! through), creates the frame services, sends command frames and reads
//! the answers — so a test can drive a real `motion-io` frame by frame.

use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::prelude::ipc;
use motion_frames::{AxisCommand, CommandFrame, FeedbackFrame, CW_ENABLE};
use motion_ipc::{monotonic_ns, Domain, Sent, SupervisorPorts};

use crate::commands::spawn_io;
use crate::leftovers::{clean_and_assert_empty, DomainGuard};
use crate::machines::{Machine, TempConfig};
use crate::process::Running;
use crate::unique_prefix;

/// The played supervisor; its session is withdrawn on drop.
pub struct SupervisorPeer {
    pub ports: SupervisorPorts,
    pub node: Node<ipc::Service>,
    pub domain: Domain,
}

/// One answered command.
pub struct Answer {
    pub sent: Sent,
    /// `monotonic_ns()` right before the command was sent.
    pub sent_ns: u64,
    pub rtt: Duration,
    pub fb: Box<FeedbackFrame>,
}

impl SupervisorPeer {
    /// Establishes the domain of `prefix` and the services of the I/O
    /// process named `io`.
    pub fn new(prefix: &str) -> Self {
        let domain = Domain::establish(prefix, None).unwrap();
        let node = domain.create_node("test-supervisor").unwrap();
        let ports = SupervisorPorts::create(&node, &domain, "io").unwrap();
        Self {
            ports,
            node,
            domain,
        }
    }

    /// Sends one command frame and waits for the feedback answering it.
    pub fn exchange(
        &mut self,
        fill: impl FnOnce(&mut CommandFrame),
        timeout: Duration,
    ) -> Option<Answer> {
        let t0 = Instant::now();
        let sent_ns = monotonic_ns();
        let sent = self.ports.send(fill).unwrap();
        let deadline = t0 + timeout;
        loop {
            if let Some(f) = self.ports.receive_latest().unwrap() {
                if f.answers_sequence == sent.sequence {
                    return Some(Answer {
                        sent,
                        sent_ns,
                        rtt: t0.elapsed(),
                        fb: Box::new(*f),
                    });
                }
                assert!(
                    f.answers_sequence < sent.sequence,
                    "answer to a frame not sent yet"
                );
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return None;
            }
            let _ = self.ports.wait(left);
        }
    }

    /// Sends disabled frames of `axes` axes until motion-io answers (it may
    /// attach after us). Returns the first answer.
    pub fn connect(&mut self, axes: u32) -> Answer {
        let deadline = Instant::now() + Duration::from_secs(10);
        while Instant::now() < deadline {
            if let Some(a) = self.exchange(
                |f| {
                    f.header.axis_count = axes;
                    for a in &mut f.axes[..axes as usize] {
                        *a = AxisCommand::ZERO;
                    }
                },
                Duration::from_millis(50),
            ) {
                self.ports.update_connections().unwrap();
                return a;
            }
        }
        panic!("motion-io never answered");
    }

    /// Receives whatever feedback is there (newest only), without waiting.
    pub fn latest(&mut self) -> Option<Box<FeedbackFrame>> {
        self.ports.receive_latest().unwrap().map(|f| Box::new(*f))
    }

    /// Leaves (ports, node, session) and checks that the domain, cleaned
    /// with the processes' own helpers, left nothing in `/dev/shm`.
    #[track_caller]
    pub fn finish(self) {
        let (domain, prefix) = (self.domain.clone(), self.domain.prefix.clone());
        drop(self);
        clean_and_assert_empty(Some(&domain), &prefix);
    }
}

impl Drop for SupervisorPeer {
    fn drop(&mut self) {
        self.domain.withdraw();
    }
}

/// `motion-io --config <machine> --service-prefix P`, P a prefix of its own
/// (the command line wins over the config's), once it waits for its
/// supervisor, and the supervisor of P played for it. Bind all four
/// (`let (_cfg, _guard, mut io, mut sup) = …`): the peer and the child go
/// first, then the guard tidies the domain after a panic.
#[track_caller]
pub fn io_on_own_prefix(machine: &Machine) -> (TempConfig, DomainGuard, Running, SupervisorPeer) {
    let cfg = machine.write("iotest_cfg");
    let prefix = unique_prefix("iotest");
    let guard = DomainGuard(prefix.clone());
    let (io, sup) = io_with_peer(
        &["--config", cfg.arg(), "--service-prefix", &prefix],
        &prefix,
    );
    (cfg, guard, io, sup)
}

/// Axis command: enabled, full torque both ways, at `position` (counts)
/// moving at `velocity` (counts/s).
pub fn enabled(position: i64, velocity: f64) -> AxisCommand {
    AxisCommand {
        target_position: position,
        target_velocity: velocity,
        torque_limit_positive: 100.0,
        torque_limit_negative: 100.0,
        control_word: CW_ENABLE,
        ..AxisCommand::ZERO
    }
}

/// Fills a one-axis command frame with `axis`.
pub fn one_axis(axis: AxisCommand) -> impl FnOnce(&mut CommandFrame) {
    move |f| {
        f.header.axis_count = 1;
        f.axes[0] = axis;
    }
}

/// Starts `motion-io <args>`, waits until it waits for its supervisor, and
/// plays the supervisor of `prefix` for it.
#[track_caller]
pub fn io_with_peer(args: &[&str], prefix: &str) -> (Running, SupervisorPeer) {
    let io = spawn_io(args);
    let waiting = io.wait_line("waiting for the supervisor", Duration::from_secs(10));
    assert!(
        waiting.is_some(),
        "motion-io did not start: {}",
        io.stderr()
    );
    (io, SupervisorPeer::new(prefix))
}

/// Runs the calling thread — the test's, playing the supervisor — at
/// SCHED_FIFO 80 like the real supervisor's cycle, where the OS allows it
/// (root, `RLIMIT_RTPRIO`); elsewhere it stays as it is. Returns whether it
/// got it. For a test whose verdict hangs on the played supervisor's
/// cadence (20 ms of silence trips `motion-io`'s watchdog): on a loaded
/// 2-CPU machine a normal thread can be off the CPU that long.
pub fn pace_like_the_supervisor() -> bool {
    let got = motion_rt::enter_realtime(&motion_rt::RtConfig {
        cpu: None,
        priority: 80,
        lock_memory: false,
        prefault_stack: 0,
    });
    got.policy == motion_rt::SchedPolicy::Fifo
}

/// Paces a loop at `period` with absolute deadlines.
pub struct Pacer {
    next: Instant,
    period: Duration,
}

impl Pacer {
    pub fn new(period: Duration) -> Self {
        Self {
            next: Instant::now() + period,
            period,
        }
    }

    pub fn wait(&mut self) {
        let now = Instant::now();
        if self.next > now {
            std::thread::sleep(self.next - now);
        }
        self.next += self.period;
    }
}

/// The `q`-quantile of sorted samples.
pub fn quantile(sorted: &[Duration], q: f64) -> Duration {
    let i = ((sorted.len() as f64 - 1.0) * q).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}
