//! A spy on one I/O process's frames: a subscriber on its command topic and
//! one on its feedback topic (the frames' services admit the peer plus one
//! observer each), woken by `command_ready`. It records every frame with the
//! sender's own `CLOCK_MONOTONIC` send time (`header.timestamp_ns`), so what
//! it shows does not depend on when the spy itself ran; frames it missed
//! show as gaps in the sequence numbers.

use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{ipc, ServiceName, ZeroCopySend};
use iceoryx2::service::port_factory::publish_subscribe::PortFactory;
use motion_frames::{CommandFrame, FeedbackFrame};
use motion_ipc::ports::{open_topic, SUBSCRIBER_BUFFER};
use motion_ipc::wait::ppoll_until;
use motion_ipc::{monotonic_ns, Domain, IoServiceNames};
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::thread::JoinHandle;
use std::time::Duration;

/// One command frame as the spy saw it (axis 0 only).
#[derive(Clone, Copy, Debug)]
pub struct Cmd {
    pub seq: u64,
    /// The supervisor's CLOCK_MONOTONIC right before sending, ns.
    pub ts: u64,
    /// Axis 0: velocity set-point, counts/s, and control word.
    pub velocity: f64,
    pub control_word: u16,
    /// Axis 0: position set-point, counts (the setpoint-latency bench finds
    /// the frame that carries a setpoint by it).
    pub position: i64,
}

/// One feedback frame as the spy saw it.
#[derive(Clone, Copy, Debug)]
pub struct Fb {
    pub seq: u64,
    /// motion-io's CLOCK_MONOTONIC right before sending, ns.
    pub ts: u64,
    /// The command sequence it answers.
    pub answers: u64,
    /// When motion-io took that command, ns.
    pub io_received: u64,
    /// Axis 0's status word.
    pub status_word: u16,
}

/// What the spy recorded.
#[derive(Default)]
pub struct Recording {
    pub cmds: Vec<Cmd>,
    pub fbs: Vec<Fb>,
    pub error: Option<String>,
}

impl Recording {
    /// Writes both streams as one CSV, ordered by send time:
    /// `kind,seq,ts_ns,answers,io_received_ns,velocity,control_word,status_word`
    /// (`C` command, `F` feedback).
    pub fn write_csv(&self, path: &Path) -> std::io::Result<()> {
        let mut rows: Vec<(u64, String)> = Vec::with_capacity(self.cmds.len() + self.fbs.len());
        for c in &self.cmds {
            rows.push((
                c.ts,
                format!("C,{},{},,,{},{},", c.seq, c.ts, c.velocity, c.control_word),
            ));
        }
        for f in &self.fbs {
            rows.push((
                f.ts,
                format!(
                    "F,{},{},{},{},,,{}",
                    f.seq, f.ts, f.answers, f.io_received, f.status_word
                ),
            ));
        }
        rows.sort_by_key(|r| r.0);
        let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(
            w,
            "kind,seq,ts_ns,answers,io_received_ns,velocity,control_word,status_word"
        )?;
        for (_, r) in rows {
            writeln!(w, "{r}")?;
        }
        w.flush()
    }
}

type PubSub<T> = PortFactory<ipc::Service, T, ()>;

/// A running spy thread.
pub struct Spy {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Recording>>,
}

fn service(name: &str) -> Result<ServiceName, String> {
    ServiceName::new(name).map_err(|e| format!("service name {name:?}: {e:?}"))
}

fn subscribe<T: std::fmt::Debug + ZeroCopySend>(
    topic: &PubSub<T>,
    what: &str,
) -> Result<Subscriber<ipc::Service, T, ()>, String> {
    topic
        .subscriber_builder()
        .buffer_size(SUBSCRIBER_BUFFER)
        .create()
        .map_err(|e| format!("{what} subscriber: {e:?}"))
}

impl Spy {
    /// Starts the spy on I/O process `io` of the supervisor under `prefix`,
    /// pinned to `cpu` at SCHED_FIFO `priority` (0: normal scheduling),
    /// recording at most `capacity` frames of each kind. `on_cmd` runs in
    /// the spy thread for every command frame. Returns once it subscribed.
    pub fn start<F>(
        prefix: &str,
        io: &str,
        cpu: usize,
        priority: i32,
        capacity: usize,
        on_cmd: F,
    ) -> Result<Spy, String>
    where
        F: FnMut(&Cmd) + Send + 'static,
    {
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = mpsc::channel();
        let thread = {
            let (prefix, io, stop) = (prefix.to_string(), io.to_string(), stop.clone());
            std::thread::Builder::new()
                .name("mb-spy".into())
                .spawn(move || run(&prefix, &io, cpu, priority, capacity, &stop, tx, on_cmd))
                .map_err(|e| format!("spy thread: {e}"))?
        };
        let mut spy = Spy {
            stop,
            thread: Some(thread),
        };
        match rx.recv_timeout(Duration::from_secs(10)) {
            Ok(Ok(())) => Ok(spy),
            Ok(Err(e)) => {
                spy.finish();
                Err(format!("spy: {e}"))
            }
            Err(_) => {
                spy.finish();
                Err("the spy did not start".into())
            }
        }
    }

    /// Stops the spy and returns what it recorded.
    pub fn finish(&mut self) -> Recording {
        self.stop.store(true, Ordering::Release);
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(r)) => r,
            Some(Err(_)) => Recording {
                error: Some("the spy thread panicked".into()),
                ..Recording::default()
            },
            None => Recording::default(),
        }
    }
}

impl Drop for Spy {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

#[allow(clippy::too_many_arguments)]
fn run<F: FnMut(&Cmd)>(
    prefix: &str,
    io: &str,
    cpu: usize,
    priority: i32,
    capacity: usize,
    stop: &AtomicBool,
    ready: mpsc::Sender<Result<(), String>>,
    mut on_cmd: F,
) -> Recording {
    let mut rec = Recording {
        cmds: Vec::with_capacity(capacity),
        fbs: Vec::with_capacity(capacity),
        error: None,
    };
    for w in crate::host::enter_rt(Some(cpu), (priority > 0).then_some(priority)) {
        eprintln!("spy: warning: {w}");
    }
    let setup = || -> Result<_, String> {
        let domain = Domain::join(prefix, None).map_err(|e| e.to_string())?;
        let node = domain.create_node("mb-spy").map_err(|e| e.to_string())?;
        let n = IoServiceNames::new(prefix, io);
        let cmd_topic = open_topic::<CommandFrame>(&node, &n.command).map_err(|e| e.to_string())?;
        let fb_topic =
            open_topic::<FeedbackFrame>(&node, &n.feedback).map_err(|e| e.to_string())?;
        let event = node
            .service_builder(&service(&n.command_ready)?)
            .event()
            .open()
            .map_err(|e| format!("open {}: {e:?}", n.command_ready))?;
        let cmd_sub = subscribe(&cmd_topic, "command")?;
        let fb_sub = subscribe(&fb_topic, "feedback")?;
        let listener = event
            .listener_builder()
            .create()
            .map_err(|e| format!("listener: {e:?}"))?;
        Ok((node, cmd_sub, fb_sub, listener))
    };
    let (_node, cmd_sub, fb_sub, listener) = match setup() {
        Ok(x) => x,
        Err(e) => {
            let _ = ready.send(Err(e.clone()));
            rec.error = Some(e);
            return rec;
        }
    };
    // SAFETY: only the number is kept; the listener owns the descriptor and
    // outlives every use below.
    let fd = unsafe {
        iceoryx2_bb_posix::file_descriptor::FileDescriptorBased::file_descriptor(&listener)
            .native_handle()
    };
    let _ = ready.send(Ok(()));
    while !stop.load(Ordering::Relaxed) {
        let _ = ppoll_until(fd, monotonic_ns() + 2_000_000);
        let _ = listener.try_wait(|_| {});
        loop {
            match cmd_sub.receive() {
                Ok(Some(s)) => {
                    let f = s.payload();
                    let a = f.axes[0];
                    let c = Cmd {
                        seq: f.header.sequence,
                        ts: f.header.timestamp_ns,
                        velocity: a.target_velocity,
                        control_word: a.control_word,
                        position: a.target_position,
                    };
                    on_cmd(&c);
                    if rec.cmds.len() < rec.cmds.capacity() {
                        rec.cmds.push(c);
                    }
                }
                Ok(None) => break,
                Err(e) => {
                    rec.error = Some(format!("receive command: {e:?}"));
                    return rec;
                }
            }
        }
        while let Ok(Some(s)) = fb_sub.receive() {
            let f = s.payload();
            if rec.fbs.len() < rec.fbs.capacity() {
                rec.fbs.push(Fb {
                    seq: f.header.sequence,
                    ts: f.header.timestamp_ns,
                    answers: f.answers_sequence,
                    io_received: f.io_received_ns,
                    status_word: f.axes[0].status_word,
                });
            }
        }
    }
    rec
}
