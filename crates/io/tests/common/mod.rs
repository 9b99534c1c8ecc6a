//! Test harness: the real `motion-io` binary as a child process, a temp
//! config, and the supervisor played by the test over iceoryx2.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::prelude::ipc;
use motion_frames::{AxisCommand, CommandFrame, FeedbackFrame};
use motion_ipc::{
    cleanup_domain, cleanup_stale_domains, monotonic_ns, Domain, Sent, SupervisorPorts,
};
use nix::sys::signal::{kill, Signal};
use nix::unistd::Pid;

pub const BIN: &str = env!("CARGO_BIN_EXE_motion-io");

static COUNTER: AtomicU32 = AtomicU32::new(0);

/// `iotest_<pid>_<n>`: unique per test (and per test binary).
pub fn unique_prefix() -> String {
    format!(
        "iotest_{}_{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )
}

/// One-axis machine: X, 1000 counts/unit, markers every 10 at 2.5,
/// deceleration 500 units/s², enable delay 2 cycles.
pub fn one_axis_toml(prefix: &str, watchdog_cycles: u32) -> String {
    format!(
        r#"
[supervisor]
cycle_us = 1000
service_prefix = "{prefix}"
io_watchdog_cycles = {watchdog_cycles}

[[axis]]
name = "X"
counts_per_unit = 1000.0
marker = true
home_sequence = "marker"
home_direction = "unidirectional_forward"
home_speed = 30.0
home_return_speed = 3.0
home_acceleration = 500.0
home_deceleration = 500.0

[axis.sim]
start = 0.0
marker_every = 10.0
marker_at = 2.5
enable_delay_cycles = 2
"#
    )
}

/// A config file in the temp directory, removed on drop.
pub struct TempConfig {
    pub path: PathBuf,
}

impl TempConfig {
    pub fn new(tag: &str, text: &str) -> Self {
        let path = std::env::temp_dir().join(format!(
            "motion-io-test-{}-{}-{tag}.toml",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::write(&path, text).unwrap();
        Self { path }
    }

    pub fn arg(&self) -> String {
        self.path.display().to_string()
    }
}

impl Drop for TempConfig {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// The `motion-io` child: stderr collected line by line on a thread.
/// Killed (SIGKILL) and reaped on drop if still running.
pub struct Io {
    child: Option<Child>,
    rx: Receiver<(Instant, String)>,
    reader: Option<JoinHandle<()>>,
    /// Every stderr line so far, with the instant it was read.
    pub lines: Vec<(Instant, String)>,
    pub status: Option<ExitStatus>,
}

impl Io {
    pub fn spawn(args: &[&str]) -> Self {
        let mut child = Command::new(BIN)
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn motion-io");
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = mpsc::channel();
        let pid = child.id();
        let reader = std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines() {
                let Ok(line) = line else { break };
                println!("[motion-io {pid}] {line}");
                if tx.send((Instant::now(), line)).is_err() {
                    break;
                }
            }
        });
        Self {
            child: Some(child),
            rx,
            reader: Some(reader),
            lines: Vec::new(),
            status: None,
        }
    }

    pub fn pid(&self) -> Pid {
        Pid::from_raw(self.child.as_ref().expect("child").id() as i32)
    }

    pub fn signal(&self, sig: Signal) {
        kill(self.pid(), sig).unwrap();
    }

    /// Collects the lines that arrived, without waiting.
    pub fn poll_lines(&mut self) {
        while let Ok(l) = self.rx.try_recv() {
            self.lines.push(l);
        }
    }

    /// Index of the first collected line containing `needle`.
    pub fn find(&mut self, needle: &str) -> Option<usize> {
        self.poll_lines();
        self.lines.iter().position(|(_, l)| l.contains(needle))
    }

    pub fn count(&mut self, needle: &str) -> usize {
        self.poll_lines();
        self.lines
            .iter()
            .filter(|(_, l)| l.contains(needle))
            .count()
    }

    /// Waits for a line containing `needle`; returns when it was read.
    pub fn wait_line(&mut self, needle: &str, timeout: Duration) -> Option<(Instant, String)> {
        if let Some(i) = self.find(needle) {
            return Some(self.lines[i].clone());
        }
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.rx.recv_timeout(left) {
                Ok(l) => {
                    self.lines.push(l.clone());
                    if l.1.contains(needle) {
                        return Some(l);
                    }
                }
                Err(RecvTimeoutError::Timeout) | Err(RecvTimeoutError::Disconnected) => {
                    return None
                }
            }
        }
    }

    /// Waits for the child to exit; collects all of its stderr.
    pub fn wait_exit(&mut self, timeout: Duration) -> Option<ExitStatus> {
        let deadline = Instant::now() + timeout;
        let child = self.child.as_mut()?;
        loop {
            if let Some(st) = child.try_wait().unwrap() {
                self.status = Some(st);
                self.child = None;
                if let Some(r) = self.reader.take() {
                    r.join().unwrap();
                }
                self.poll_lines();
                return Some(st);
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    pub fn stderr(&mut self) -> String {
        self.poll_lines();
        self.lines
            .iter()
            .map(|(_, l)| l.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// SIGKILL + reap (test failure paths).
    pub fn kill9(&mut self) -> Option<ExitStatus> {
        let mut child = self.child.take()?;
        let _ = child.kill();
        let st = child.wait().ok();
        self.status = st;
        st
    }
}

impl Drop for Io {
    fn drop(&mut self) {
        self.kill9();
    }
}

/// The supervisor's side, played by the test: it claims the prefix (the
/// session file motion-io joins through) and creates the services.
pub struct Sup {
    pub ports: SupervisorPorts,
    pub node: Node<ipc::Service>,
    pub domain: Domain,
}

impl Drop for Sup {
    fn drop(&mut self) {
        self.domain.withdraw();
    }
}

/// One answered command.
pub struct Answer {
    pub sent: Sent,
    /// `monotonic_ns()` right before the command was sent.
    pub sent_ns: u64,
    pub rtt: Duration,
    pub fb: Box<FeedbackFrame>,
}

impl Sup {
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

    /// Sends disabled one-axis frames until motion-io answers (it may attach
    /// after us). Returns the first answer.
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
}

/// `/dev/shm` entries of the iceoryx2 domains of `prefix`.
pub fn shm_entries(prefix: &str) -> Vec<String> {
    Domain::shm_files_of_prefix(prefix)
}

/// After a test: the supervisor side is dropped first, then the domain is
/// cleaned with the same helper the processes use; nothing may remain.
pub fn finish(sup: Option<Sup>, prefix: &str) {
    let domain = sup.as_ref().map(|s| s.domain.clone());
    drop(sup);
    // a killed peer shows as dead only after a moment: retry briefly
    let deadline = Instant::now() + Duration::from_secs(5);
    loop {
        let gone = match &domain {
            Some(d) => {
                let r = cleanup_domain(d);
                println!("cleanup_domain({prefix}): {r}");
                r.domain_gone()
            }
            None => true,
        };
        cleanup_stale_domains(prefix, &motion_ipc::default_runtime_dir());
        if (gone && shm_entries(prefix).is_empty()) || Instant::now() >= deadline {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let left = shm_entries(prefix);
    assert!(left.is_empty(), "left in /dev/shm: {left:?}");
}

/// Declared right after the prefix (so dropped after the child and the
/// supervisor ports): if the test panicked, tidies the domain anyway so that
/// a failed run leaves nothing in /dev/shm.
pub struct DomainGuard(pub String);

impl Drop for DomainGuard {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            return;
        }
        let dir = motion_ipc::default_runtime_dir();
        let deadline = Instant::now() + Duration::from_secs(2);
        while !shm_entries(&self.0).is_empty() && Instant::now() < deadline {
            cleanup_stale_domains(&self.0, &dir);
            std::thread::sleep(Duration::from_millis(50));
        }
    }
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

/// p-quantile of sorted samples.
pub fn quantile(sorted: &[Duration], q: f64) -> Duration {
    let i = ((sorted.len() as f64 - 1.0) * q).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}
