//! IPC bench: the command/feedback round trip through iceoryx2 between two
//! processes, measured as the supervisor's cycle measures it, with
//!
//! * (a) a real `motion-io --backend sim` waiting on the event,
//! * (b) the same with `--spin` (busy-polling on its own CPU),
//! * (c) a bare iceoryx2 echo of the same payload sizes (this binary re-run
//!   with `--role echo`), event-waiting and spinning.
//!
//! One message per period, not back to back. See `bench/README.md`.

use hdrhistogram::Histogram;
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{ipc, BackpressureStrategy, ServiceName};
use iceoryx2::sample::Sample;
use motion_bench::args::Args;
use motion_bench::hist::{self, new_hist, thousands, us};
use motion_bench::machine::{self, Supervisor};
use motion_bench::proc::{self, Running};
use motion_bench::sys::{self, now_ns};
use motion_frames::ports::{
    MAX_LISTENERS, MAX_SUBSCRIBERS, SUBSCRIBER_BUFFER, SUBSCRIBER_MAX_BORROWED,
};
use motion_frames::wait::{ppoll_until, PollWake};
use motion_frames::{cleanup_domain, Domain};
const HISTORY: usize = 0;
const MAX_NOTIFIERS: usize = 1;
const MAX_PUBLISHERS: usize = 1;
use motion_frames::{CommandFrame, FeedbackFrame, SupervisorPorts};
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

const USAGE: &str = "\
usage: ipc [--count N] [--period-us N] [--cpu N] [--peer-cpu N] [--priority P]
           [--warmup N] [--modes LIST] [--io PATH]

Round trip command → feedback through iceoryx2, one message per period, with
(a) motion-io waiting on the event, (b) motion-io --spin, and (c) a bare
iceoryx2 echo of the same payload sizes (event-waiting and spinning).

  --count N       measured messages per mode (default 10000)
  --period-us N   one message per period, µs (default 1000)
  --cpu N         CPU of the measuring thread, SCHED_FIFO (default 1)
  --peer-cpu N    CPU of the peer (default: the other one, 0)
  --priority P    SCHED_FIFO priority of the measuring thread (default 80);
                  event-waiting peers run at P-10, spinning peers SCHED_OTHER
  --warmup N      answered messages before measuring (default 200)
  --modes LIST    comma-separated subset of io-event,bare-event,io-spin,bare-spin
  --io PATH       motion-io binary (default: next to this binary, or $MOTION_IO_BIN)
  --cpu-dma-latency US
                  hold /dev/cpu_dma_latency at US during the bench, as the
                  supervisor does (default 0; negative: leave it alone)";

/// Bare payloads: the sizes of the frames.
const PING: usize = std::mem::size_of::<CommandFrame>();
const PONG: usize = std::mem::size_of::<FeedbackFrame>();

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    IoEvent,
    BareEvent,
    IoSpin,
    BareSpin,
}

impl Mode {
    const ALL: [Mode; 4] = [Mode::IoEvent, Mode::BareEvent, Mode::IoSpin, Mode::BareSpin];

    fn key(self) -> &'static str {
        match self {
            Mode::IoEvent => "io-event",
            Mode::BareEvent => "bare-event",
            Mode::IoSpin => "io-spin",
            Mode::BareSpin => "bare-spin",
        }
    }

    fn label(self) -> &'static str {
        match self {
            Mode::IoEvent => "(a) motion-io, event",
            Mode::BareEvent => "(c) bare echo, event",
            Mode::IoSpin => "(b) motion-io --spin",
            Mode::BareSpin => "(c) bare echo, spin",
        }
    }

    fn spin(self) -> bool {
        matches!(self, Mode::IoSpin | Mode::BareSpin)
    }

    fn bare(self) -> bool {
        matches!(self, Mode::BareEvent | Mode::BareSpin)
    }
}

struct Opts {
    count: u64,
    period_us: u32,
    cpu: usize,
    peer_cpu: usize,
    priority: i32,
    warmup: u64,
    modes: Vec<Mode>,
    io: Option<PathBuf>,
    cpu_dma_latency: i32,
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--role") {
        std::process::exit(echo_main(Args::new(args.into_iter().skip(2))));
    }
    std::process::exit(bench_main());
}

fn parse_opts() -> Result<Option<Opts>, String> {
    let mut a = Args::from_env();
    if a.flag("--help") || a.flag("-h") {
        return Ok(None);
    }
    let cpu: usize = a.num("--cpu", 1)?;
    let o = Opts {
        count: a.num("--count", 10_000)?,
        period_us: a.num("--period-us", 1000)?,
        cpu,
        peer_cpu: a.num("--peer-cpu", if cpu == 0 { 1 } else { 0 })?,
        priority: a.num("--priority", 80)?,
        warmup: a.num("--warmup", 200)?,
        modes: match a.value("--modes")? {
            None => Mode::ALL.to_vec(),
            Some(list) => list
                .split(',')
                .map(|m| {
                    Mode::ALL
                        .into_iter()
                        .find(|x| x.key() == m.trim())
                        .ok_or_else(|| format!("--modes: unknown mode {m:?}"))
                })
                .collect::<Result<_, _>>()?,
        },
        io: a.value("--io")?.map(PathBuf::from),
        cpu_dma_latency: a.num("--cpu-dma-latency", 0)?,
    };
    a.finish()?;
    if o.count == 0 {
        return Err("--count must be at least 1".into());
    }
    if !(20..=100_000).contains(&o.period_us) {
        return Err("--period-us must be within 20..=100000".into());
    }
    if !(11..=99).contains(&o.priority) {
        return Err("--priority must be within 11..=99 (peers run at P-10)".into());
    }
    let n = sys::cpus();
    if o.cpu >= n || o.peer_cpu >= n {
        return Err(format!("this machine has {n} CPUs"));
    }
    Ok(Some(o))
}

/// A `[u8; N]` topic with the frames' QoS (the same settings as
/// `motion_frames::ipc`'s ports, so the bare peer differs only in payload type).
fn open_topic<const N: usize>(
    node: &Node<ipc::Service>,
    name: &str,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, [u8; N], ()>,
    String,
> {
    node.service_builder(&service(name)?)
        .publish_subscribe::<[u8; N]>()
        .enable_safe_overflow(true)
        .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
        .subscriber_max_borrowed_samples(SUBSCRIBER_MAX_BORROWED)
        .history_size(HISTORY)
        .max_publishers(MAX_PUBLISHERS)
        .max_subscribers(MAX_SUBSCRIBERS)
        .open_or_create()
        .map_err(|x| format!("open topic {name}: {x:?}"))
}

/// Result of one mode.
struct Measured {
    hist: Histogram<u64>,
    sent: u64,
    late: u64,
}

fn bench_main() -> i32 {
    let o = match parse_opts() {
        Ok(Some(o)) => o,
        Ok(None) => {
            println!("{USAGE}");
            return 0;
        }
        Err(e) => {
            eprintln!("ipc: {e}\n\n{USAGE}");
            return 2;
        }
    };
    proc::install_stop_handler();
    let io_bin =
        o.io.clone()
            .or_else(|| std::env::var_os("MOTION_IO_BIN").map(PathBuf::from))
            .or_else(|| sys::sibling_exe("motion-io"));
    if o.modes.iter().any(|m| !m.bare()) && !io_bin.as_deref().is_some_and(sys::is_executable) {
        eprintln!(
            "ipc: motion-io not found next to this binary; build it first: \
             `cargo build --release --workspace --bins` (same CARGO_TARGET_DIR), or pass --io PATH"
        );
        return 1;
    }
    for w in sys::enter_rt(None, None) {
        eprintln!("ipc: warning: {w}");
    }
    // as the supervisor does by default (cpu_dma_latency_us = 0)
    let _idle = match o.cpu_dma_latency {
        us if us >= 0 => match sys::hold_cpu_dma_latency(us) {
            Ok(f) => Some(f),
            Err(e) => {
                eprintln!("ipc: warning: {e}");
                None
            }
        },
        _ => None,
    };
    let others = sys::other_rt_tasks();
    for t in &others {
        eprintln!("ipc: WARNING: another real-time thread is running: {t}");
    }

    let pid = std::process::id();
    let tmp = std::env::temp_dir().join(format!("motion-bench-ipc-{pid}"));
    if let Err(e) = std::fs::create_dir_all(&tmp) {
        eprintln!("ipc: cannot create {}: {e}", tmp.display());
        return 1;
    }
    let mut results: Vec<(Mode, Measured)> = Vec::new();
    let mut failures: Vec<String> = Vec::new();
    let mut leftovers: Vec<String> = Vec::new();
    for (k, &mode) in o.modes.iter().enumerate() {
        if proc::stop_requested() {
            break;
        }
        let prefix = format!("mbi{pid}m{k}");
        eprintln!(
            "ipc: {} ({}): {} messages at {} µs ...",
            mode.label(),
            mode.key(),
            o.count,
            o.period_us
        );
        match run_mode(&o, mode, &prefix, io_bin.as_deref(), &tmp) {
            Ok(m) => results.push((mode, m)),
            Err(e) => {
                eprintln!("ipc: {}: FAILED: {e}", mode.key());
                failures.push(format!("{}: {e}", mode.key()));
            }
        }
        let left = Domain::shm_files_of_prefix(&prefix);
        if !left.is_empty() {
            leftovers.push(format!("{prefix}: {}", left.join(", ")));
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);

    // --- report
    println!(
        "== ipc: round trip command → feedback, {} messages per mode, one per {} µs; \
         measuring thread SCHED_FIFO {} on CPU {}, peer on CPU {}",
        thousands(o.count),
        o.period_us,
        o.priority,
        o.cpu,
        o.peer_cpu
    );
    println!(
        "kernel {} | {} | {} CPUs | payload {PING} B → {PONG} B (CommandFrame → FeedbackFrame; bare: [u8; {PING}] → [u8; {PONG}])",
        sys::kernel(),
        sys::preemption().0,
        sys::cpus()
    );
    println!(
        "event peers: SCHED_FIFO {} on CPU {}, ppoll on the listener fd; spinning peers: SCHED_OTHER on CPU {}; /dev/cpu_dma_latency {}",
        o.priority - 10,
        o.peer_cpu,
        o.peer_cpu,
        if o.cpu_dma_latency >= 0 {
            format!("held at {} µs", o.cpu_dma_latency)
        } else {
            "not held".to_string()
        }
    );
    println!();
    let cols = ["min", "p50", "p99", "p99.9", "max"];
    let mut head = format!("{:<26}", "round trip (µs)");
    for c in cols {
        head += &format!("{c:>9}");
    }
    head += &format!("{:>9}", "late");
    println!("{head}");
    let vals = |h: &Histogram<u64>| -> [f64; 5] {
        if h.is_empty() {
            return [0.0; 5];
        }
        let q = |x: f64| h.value_at_quantile(x) as f64 / 1000.0;
        [
            h.min() as f64 / 1000.0,
            q(0.5),
            q(0.99),
            q(0.999),
            h.max() as f64 / 1000.0,
        ]
    };
    let find = |m: Mode| results.iter().find(|r| r.0 == m).map(|r| &r.1);
    for (ours, bare) in [
        (Mode::IoEvent, Mode::BareEvent),
        (Mode::IoSpin, Mode::BareSpin),
    ] {
        let (a, b) = (find(ours), find(bare));
        for (mode, m) in [(ours, a), (bare, b)] {
            if let Some(m) = m {
                let mut s = format!("{:<26}", mode.label());
                for v in vals(&m.hist) {
                    s += &format!("{:>9}", us(v));
                }
                s += &format!("{:>9}", m.late);
                println!("{s}");
            }
        }
        if let (Some(a), Some(b)) = (a, b) {
            let (va, vb) = (vals(&a.hist), vals(&b.hist));
            let mut s = format!("{:<26}", "  ratio motion-io / bare");
            for i in 0..5 {
                s += &format!("{:>9}", hist::ratio((vb[i] > 0.0).then(|| va[i] / vb[i])));
            }
            println!("{s}");
        }
    }
    println!(
        "late = no answer within half a period (not in the percentiles); sent per mode: {}",
        results
            .iter()
            .map(|(m, r)| format!("{} {}", m.key(), r.sent))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if !others.is_empty() {
        println!(
            "WARNING: other real-time threads were running: {}",
            others
                .iter()
                .map(|t| t.to_string())
                .collect::<Vec<_>>()
                .join("; ")
        );
    }
    if leftovers.is_empty() {
        println!("/dev/shm: nothing left behind");
    } else {
        println!("/dev/shm: LEFT BEHIND: {}", leftovers.join("; "));
    }
    if proc::stop_requested() {
        eprintln!("ipc: interrupted");
        return 130;
    }
    if failures.is_empty() {
        0
    } else {
        for f in &failures {
            println!("ipc: FAILED: {f}");
        }
        1
    }
}

/// Starts the peer, measures in a pinned SCHED_FIFO thread, stops the peer.
fn run_mode(
    o: &Opts,
    mode: Mode,
    prefix: &str,
    io_bin: Option<&std::path::Path>,
    tmp: &std::path::Path,
) -> Result<Measured, String> {
    let (toml, machine) = machine::demo_with(&Supervisor {
        cycle_us: o.period_us,
        cpu: o.cpu,
        priority: o.priority,
        service_prefix: prefix.to_string(),
    })?;
    let axes = machine.axes.len() as u32;
    let peer_prio = (o.priority - 10).to_string();
    let peer_cpu = o.peer_cpu.to_string();
    let mut cmd;
    if mode.bare() {
        let exe = std::env::current_exe().map_err(|e| format!("own executable: {e}"))?;
        cmd = Command::new(exe);
        cmd.args(["--role", "echo", "--prefix", prefix, "--cpu", &peer_cpu]);
        if mode.spin() {
            cmd.arg("--spin");
        } else {
            cmd.args(["--priority", &peer_prio]);
        }
    } else {
        let cfg = tmp.join(format!("{prefix}.toml"));
        std::fs::write(&cfg, toml).map_err(|e| format!("{}: {e}", cfg.display()))?;
        cmd = Command::new(io_bin.ok_or("no motion-io binary")?);
        cmd.arg("--backend")
            .arg("sim")
            .arg("--config")
            .arg(&cfg)
            .args(["--service-prefix", prefix, "--cpu", &peer_cpu, "--quiet"])
            .arg("--exit-with-supervisor");
        if mode.spin() {
            cmd.arg("--spin");
        } else {
            cmd.args(["--priority", &peer_prio]);
        }
    }
    // This process plays the supervisor: it claims the prefix first, the
    // peer joins through the session file.
    let domain = Domain::establish(prefix, None).map_err(|e| e.to_string())?;
    let mut peer = Running::spawn(&mut cmd, mode.key(), true, false)?;

    let (count, period_ns, warmup, cpu, prio) = (
        o.count,
        u64::from(o.period_us) * 1000,
        o.warmup,
        o.cpu,
        o.priority,
    );
    let prefix_owned = prefix.to_string();
    let bare = mode.bare();
    let d = domain.clone();
    let worker = std::thread::Builder::new()
        .name("ipc-measure".into())
        .spawn(move || -> Result<Measured, String> {
            let refused = sys::enter_rt(Some(cpu), Some(prio));
            if !refused.is_empty() {
                return Err(refused.join("; "));
            }
            let node = d.create_node("motion-bench").map_err(|e| e.to_string())?;
            if bare {
                let mut x = BareSide::<PING, PONG>::create(&node, &prefix_owned, "ping", "pong")?;
                measure(&mut x, count, period_ns, warmup)
            } else {
                let ports = SupervisorPorts::create(&node, &d, "io").map_err(|e| e.to_string())?;
                let mut x = FrameSide {
                    ports,
                    axes,
                    pending: None,
                };
                measure(&mut x, count, period_ns, warmup)
            }
        })
        .map_err(|e| format!("cannot start the measuring thread: {e}"))?;
    let result = worker
        .join()
        .unwrap_or_else(|_| Err("the measuring thread panicked".into()));
    let _ = cleanup_domain(&domain);
    domain.withdraw();
    let still_running = peer.running();
    let ended = peer.wait(Duration::ZERO, Duration::from_secs(3));
    if !still_running {
        return Err(format!(
            "the peer ended early: {}; {}",
            ended.describe(),
            ended.stderr.trim()
        ));
    }
    result
}

/// The measuring side of one exchange.
trait Exchange {
    /// Clears wake-ups left over from earlier answers.
    fn clear(&mut self);
    /// Publishes one message and notifies; returns its sequence number.
    fn send(&mut self) -> Result<u64, String>;
    /// Waits for a wake-up until the absolute monotonic `deadline_ns`.
    fn wait_until(&mut self, deadline_ns: u64) -> bool;
    /// The sequence number answered by the newest reply, if one arrived.
    fn answer(&mut self) -> Option<u64>;
}

/// As the supervisor: `SupervisorPorts` with real frames.
struct FrameSide {
    ports: SupervisorPorts,
    axes: u32,
    pending: Option<Sample<ipc::Service, FeedbackFrame, ()>>,
}

impl Exchange for FrameSide {
    fn clear(&mut self) {
        let _ = self.ports.try_wait();
    }
    fn send(&mut self) -> Result<u64, String> {
        let n = self.axes;
        let sent = self
            .ports
            .publish(|f| f.header.axis_count = n)
            .map_err(|e| e.to_string())?;
        let _ = self.ports.notify();
        Ok(sent.sequence)
    }
    fn wait_until(&mut self, deadline_ns: u64) -> bool {
        // Err (e.g. EINTR) counts as a wake-up, as in the cycle
        !matches!(self.ports.wait_until(deadline_ns), Ok(false))
    }
    fn answer(&mut self) -> Option<u64> {
        let s = self.ports.receive_latest().ok()??;
        let a = s.payload().answers_sequence;
        self.pending = Some(s); // kept until the next answer, as the cycle does
        Some(a)
    }
}

/// Plain iceoryx2 ports for `[u8; TX]` out and `[u8; RX]` in; the first 8
/// bytes carry the sequence number.
struct BareSide<const TX: usize, const RX: usize> {
    publisher: Publisher<ipc::Service, [u8; TX], ()>,
    subscriber: Subscriber<ipc::Service, [u8; RX], ()>,
    notifier: Notifier<ipc::Service>,
    listener: Listener<ipc::Service>,
    fd: i32,
    next: u64,
    pending: Option<Sample<ipc::Service, [u8; RX], ()>>,
}

fn service(name: &str) -> Result<ServiceName, String> {
    ServiceName::new(name).map_err(|e| format!("service name {name:?}: {e:?}"))
}

impl<const TX: usize, const RX: usize> BareSide<TX, RX> {
    /// Publishes on `{prefix}/{tx}` (+ `_ready` event), subscribes to
    /// `{prefix}/{rx}` (+ `_ready`), with the frames' QoS.
    fn create(node: &Node<ipc::Service>, prefix: &str, tx: &str, rx: &str) -> Result<Self, String> {
        let topic_tx = open_topic::<TX>(node, &format!("{prefix}/{tx}"))?;
        let topic_rx = open_topic::<RX>(node, &format!("{prefix}/{rx}"))?;
        let event = |name: String| {
            node.service_builder(&service(&name)?)
                .event()
                .max_notifiers(MAX_NOTIFIERS)
                .max_listeners(MAX_LISTENERS)
                .open_or_create()
                .map_err(|x| format!("open event: {x:?}"))
        };
        let ev_tx = event(format!("{prefix}/{tx}_ready"))?;
        let ev_rx = event(format!("{prefix}/{rx}_ready"))?;
        let publisher = topic_tx
            .publisher_builder()
            .max_loaned_samples(1)
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .create()
            .map_err(|x| format!("publisher: {x:?}"))?;
        let subscriber = topic_rx
            .subscriber_builder()
            .buffer_size(SUBSCRIBER_BUFFER)
            .create()
            .map_err(|x| format!("subscriber: {x:?}"))?;
        let notifier = ev_tx
            .notifier_builder()
            .create()
            .map_err(|x| format!("notifier: {x:?}"))?;
        let listener = ev_rx
            .listener_builder()
            .create()
            .map_err(|x| format!("listener: {x:?}"))?;
        // SAFETY: only the number is kept; the listener owns the descriptor
        // and lives as long as `self`.
        let fd = unsafe {
            iceoryx2_bb_posix::file_descriptor::FileDescriptorBased::file_descriptor(&listener)
                .native_handle()
        };
        Ok(Self {
            publisher,
            subscriber,
            notifier,
            listener,
            fd,
            next: 1,
            pending: None,
        })
    }

    fn try_wait(&mut self) -> bool {
        matches!(self.listener.try_wait(|_| {}), Ok(n) if n > 0)
    }

    /// Loans, zeroes (as `placement_default` does for a frame), stamps
    /// `seq`, sends, notifies.
    fn publish(&mut self, seq: u64) -> Result<(), String> {
        let mut u = self
            .publisher
            .loan_uninit()
            .map_err(|e| format!("loan: {e:?}"))?;
        // SAFETY: the loaned payload is TX bytes, exclusively ours; every
        // byte is written before `assume_init`.
        let mut s = unsafe {
            std::ptr::write_bytes(u.payload_mut().as_mut_ptr() as *mut u8, 0, TX);
            u.assume_init()
        };
        s.payload_mut()[..8].copy_from_slice(&seq.to_le_bytes());
        s.send().map_err(|e| format!("send: {e:?}"))?;
        let _ = self.notifier.notify();
        Ok(())
    }

    /// The newest received message's sequence number (older ones dropped).
    fn receive_latest(&mut self) -> Option<u64> {
        let mut latest = None;
        while let Ok(Some(s)) = self.subscriber.receive() {
            latest = Some(s);
        }
        let s = latest?;
        let mut b = [0u8; 8];
        b.copy_from_slice(&s.payload()[..8]);
        self.pending = Some(s);
        Some(u64::from_le_bytes(b))
    }

    /// As `motion_frames::Ports::wait_until`: `try_wait`, else `ppoll` on
    /// the listener's descriptor until the deadline.
    fn wait_fd_until(&mut self, deadline_ns: u64) -> bool {
        loop {
            if self.try_wait() {
                return true;
            }
            if ppoll_until(self.fd, deadline_ns) == PollWake::Deadline {
                return self.try_wait();
            }
        }
    }
}

impl<const TX: usize, const RX: usize> Exchange for BareSide<TX, RX> {
    fn clear(&mut self) {
        let _ = self.try_wait();
    }
    fn send(&mut self) -> Result<u64, String> {
        let seq = self.next;
        self.next += 1;
        self.publish(seq)?;
        Ok(seq)
    }
    fn wait_until(&mut self, deadline_ns: u64) -> bool {
        self.wait_fd_until(deadline_ns)
    }
    fn answer(&mut self) -> Option<u64> {
        self.receive_latest()
    }
}

/// One cycle as `rt_thread` does it: clear stale wake-ups, timestamp,
/// publish + notify, wait (at most half a period after the deadline, at most
/// 4 wake-ups) for the answer to *this* message. Returns the round trip, ns.
fn cycle<X: Exchange>(x: &mut X, deadline: u64, period_ns: u64) -> Result<Option<u64>, String> {
    x.clear();
    let t_send = now_ns();
    let seq = x.send()?;
    let budget_end = deadline + period_ns / 2;
    for _ in 0..4 {
        if !x.wait_until(budget_end) {
            break;
        }
        if x.answer() == Some(seq) {
            return Ok(Some(now_ns() - t_send));
        }
    }
    Ok(None)
}

fn measure<X: Exchange>(
    x: &mut X,
    count: u64,
    period_ns: u64,
    warmup: u64,
) -> Result<Measured, String> {
    let mut deadline = now_ns() + period_ns;
    let next = |deadline: &mut u64| {
        *deadline += period_ns;
        // keep the phase; skip whole periods that already passed
        let now = now_ns();
        if now > *deadline {
            *deadline += (now - *deadline) / period_ns * period_ns + period_ns;
        }
    };
    // warm-up: until `warmup` answers in a row (peer started, connected)
    let started = Instant::now();
    let mut in_row = 0;
    while in_row < warmup {
        if started.elapsed() > Duration::from_secs(15) {
            return Err(format!(
                "the peer did not answer {warmup} messages in a row within 15 s"
            ));
        }
        if proc::stop_requested() {
            return Err("interrupted".into());
        }
        sys::sleep_until(deadline);
        in_row = if cycle(x, deadline, period_ns)?.is_some() {
            in_row + 1
        } else {
            0
        };
        next(&mut deadline);
    }
    let mut m = Measured {
        hist: new_hist(),
        sent: 0,
        late: 0,
    };
    while m.sent < count {
        if m.sent % 1000 == 0 && proc::stop_requested() {
            return Err("interrupted".into());
        }
        sys::sleep_until(deadline);
        m.sent += 1;
        match cycle(x, deadline, period_ns)? {
            Some(rt) => m.hist.saturating_record(rt.max(1)),
            None => m.late += 1,
        }
        next(&mut deadline);
    }
    Ok(m)
}

// ---------------------------------------------------------------------------
// The bare echo peer (`ipc --role echo`)
// ---------------------------------------------------------------------------

fn echo_main(mut a: Args) -> i32 {
    let parsed = (|| -> Result<(String, usize, Option<i32>, bool), String> {
        let prefix = a.value("--prefix")?.ok_or("--prefix missing")?;
        let cpu = a.num("--cpu", 0usize)?;
        let prio = a.value("--priority")?.map(|p| p.parse::<i32>()).transpose();
        let prio = prio.map_err(|_| "--priority: not a number".to_string())?;
        let spin = a.flag("--spin");
        a.finish()?;
        Ok((prefix, cpu, prio, spin))
    })();
    let (prefix, cpu, prio, spin) = match parsed {
        Ok(p) => p,
        Err(e) => {
            eprintln!("ipc echo: {e}");
            return 2;
        }
    };
    // SAFETY: prctl with integer arguments only.
    unsafe {
        libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
    }
    proc::install_stop_handler();
    for w in sys::enter_rt(Some(cpu), prio) {
        eprintln!("ipc echo: warning: {w}");
    }
    let code = match echo(&prefix, spin) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("ipc echo: {e}");
            1
        }
    };
    code
}

/// Answers every ping with a pong carrying its sequence number, until
/// SIGTERM/SIGINT. Event mode sleeps in `ppoll` on the listener's
/// descriptor; spin mode polls the subscriber.
fn echo(prefix: &str, spin: bool) -> Result<(), String> {
    let until = std::time::Instant::now() + Duration::from_secs(10);
    let domain = loop {
        match Domain::join(prefix, None) {
            Ok(d) => break d,
            Err(e) if std::time::Instant::now() > until => return Err(e.to_string()),
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    };
    let node = domain
        .create_node("bench-echo")
        .map_err(|e| e.to_string())?;
    let mut x = BareSide::<PONG, PING>::create(&node, prefix, "pong", "ping")?;
    let r = echo_loop(&mut x, spin);
    drop(x);
    drop(node);
    let _ = cleanup_domain(&domain);
    r
}

fn echo_loop(x: &mut BareSide<PONG, PING>, spin: bool) -> Result<(), String> {
    while !proc::stop_requested() {
        if !spin {
            // bounded, so that the stop flag is seen even without pings
            x.wait_fd_until(now_ns() + 100_000_000);
        }
        match x.receive_latest() {
            Some(seq) => {
                x.pending = None;
                x.publish(seq)?;
            }
            None => {
                if spin {
                    std::hint::spin_loop();
                }
            }
        }
    }
    Ok(())
}
