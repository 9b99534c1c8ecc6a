//! A streaming program played by a bench: its axes homed and
//! enabled through the control service ([`home_and_enable`]), then a thread
//! of this process at the stream's rate ([`Streamer`]) that takes the axes
//! over and publishes one setpoint per axis per tick through
//! `motion_control`'s [`Stream`](motion_control::stream::Stream) — the
//! Rust client a program uses, so what is measured is what a program sees.

use motion_control::{Axes, Client, Operation, Request, RESULT_ACCEPTED};
use motion_rt::{enter_realtime, now_ns, PeriodicTimer, RtConfig};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Homes (immediate homing: no motion) and enables every axis of the
/// daemon under `prefix`, and waits until its first `n` axes are homed with
/// their drives enabled.
pub fn home_and_enable(prefix: &str, n: usize) -> Result<(), String> {
    let mut c = Client::connect(prefix, None).map_err(|e| e.to_string())?;
    let all = Axes::All;
    let home = Request::Home {
        axes: all.clone(),
        parallel: true,
        timeout_s: None,
    };
    let enable = Request::Operate {
        axes: all,
        op: Operation::Enable,
    };
    for r in [home, enable] {
        let resp = c
            .send(&r, Duration::from_secs(3))
            .map_err(|e| e.to_string())?;
        if resp.result != RESULT_ACCEPTED {
            return Err(format!("{r:?} refused: {}", resp.message_text()));
        }
    }
    let until = Instant::now() + Duration::from_secs(10);
    loop {
        let st = c
            .status(Duration::from_secs(2))
            .map_err(|e| e.to_string())?;
        let ready = (st.axes().iter().take(n)).all(|a| a.homed() && a.servo_action());
        if ready {
            return Ok(());
        }
        if Instant::now() > until {
            return Err("the axes were not homed and enabled within 10 s".into());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Positions of every axis at tick `k`.
pub type Shape = Box<dyn Fn(u64) -> Vec<f64> + Send>;

/// A streaming program: a thread that owns the axes and publishes one
/// frame per tick.
pub struct Streamer {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<Vec<u64>, String>>>,
}

impl Streamer {
    /// Starts streaming `names` under `prefix`: a frame every `period_ns`
    /// (program time `t_ns = k × period`), pinned to `cpu` at SCHED_FIFO
    /// `priority` (0: normal). The publish times are kept for the latency
    /// (`CLOCK_MONOTONIC` right before each publish).
    pub fn start(
        prefix: &str,
        names: Vec<String>,
        period_ns: u64,
        (cpu, priority): (usize, i32),
        shape: Shape,
    ) -> Streamer {
        let stop = Arc::new(AtomicBool::new(false));
        let (s, prefix) = (stop.clone(), prefix.to_string());
        let thread = std::thread::Builder::new()
            .name("mb-stream".into())
            .spawn(move || {
                let rt = RtConfig {
                    cpu: Some(cpu),
                    priority: priority.max(1),
                    lock_memory: false,
                    ..RtConfig::default()
                };
                if priority > 0 {
                    let _ = enter_realtime(&rt);
                } else {
                    let _ = motion_rt::thread::pin_to_cpu(cpu);
                }
                run(&prefix, &names, period_ns, &s, shape)
            })
            .ok();
        Streamer { stop, thread }
    }

    /// Stops and releases the stream; the publish time of every tick.
    pub fn finish(mut self) -> Result<Vec<u64>, String> {
        self.stop.store(true, Ordering::Release);
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(r)) => r,
            Some(Err(_)) => Err("the streaming thread panicked".into()),
            None => Err("the streaming thread did not start".into()),
        }
    }
}

/// The streaming thread's body.
fn run(
    prefix: &str,
    names: &[String],
    period_ns: u64,
    stop: &AtomicBool,
    shape: Shape,
) -> Result<Vec<u64>, String> {
    let mut c = Client::connect(prefix, None).map_err(|e| e.to_string())?;
    let mut s = c.stream("mb-stream", names).map_err(|e| e.to_string())?;
    let mut sent = Vec::with_capacity(1 << 20);
    let mut timer = PeriodicTimer::new(period_ns);
    let mut k = 0u64;
    while !stop.load(Ordering::Acquire) {
        timer.wait();
        k += 1;
        let p = shape(k);
        let t = now_ns();
        s.publish(k * period_ns, &p, None)
            .map_err(|e| e.to_string())?;
        if sent.len() < sent.capacity() {
            sent.push(t);
        }
    }
    s.release().map_err(|e| e.to_string())?;
    Ok(sent)
}
