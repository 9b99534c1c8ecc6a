//! The clients of a deployed machine, attached to a running supervisor for
//! the rest of its slice: an HMI (`motionctl status --watch`, output to
//! /dev/null), a PLC polling `motionctl status --json`, a `motionctl stats
//! --json` now and then, and with `--homing` `motionctl home X --json` back
//! to back. Every request is a `motionctl` process, as an operator's or a
//! script's would be; each is counted as made, failed, or cut off by the
//! slice's end (failed after the supervisor's `--duration` ran out: it was
//! stopping), with how long it took from start to exit.
//!
//! The periodic clients run on threads of the bench (a request ends when
//! its `motionctl` exits; they wait for it in 5 ms steps); every `motionctl`
//! started is ended before [`Attached::detach`] returns.

use motion_bench::drive::{self, last_json};
use motion_bench::proc::{self, Running};
use serde::Serialize;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long one status or stats request may take before it is ended and
/// counted as failed (motionctl itself gives up after 2 s without an answer).
const REQUEST_TIMEOUT: Duration = Duration::from_secs(10);
/// How long one `home X` may take (X homes in about 2 s).
const HOME_TIMEOUT_S: f64 = 30.0;
/// At most this many problem lines are kept per kind of request.
const MAX_DETAILS: usize = 20;

/// One kind of request, counted.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Count {
    /// Requests made (`motionctl` processes started).
    pub made: u64,
    /// ... that failed while the supervisor ran.
    pub failed: u64,
    /// ... that failed once the supervisor's `--duration` had run out.
    pub cut_off: u64,
    /// Start → exit of the requests that succeeded, ms.
    #[serde(skip)]
    pub ms: Vec<f64>,
    /// What went wrong, one line per failure (the first few).
    pub details: Vec<String>,
}

impl Count {
    pub fn merge(&mut self, o: &Count) {
        self.made += o.made;
        self.failed += o.failed;
        self.cut_off += o.cut_off;
        self.ms.extend_from_slice(&o.ms);
        for d in &o.details {
            self.note(d.clone());
        }
    }

    fn note(&mut self, s: String) {
        if self.details.len() < MAX_DETAILS {
            self.details.push(s);
        }
    }

    /// Median and maximum of [`Count::ms`].
    pub fn ms_p50_max(&self) -> Option<(f64, f64)> {
        if self.ms.is_empty() {
            return None;
        }
        let mut v = self.ms.clone();
        v.sort_by(f64::total_cmp);
        Some((v[v.len() / 2], v[v.len() - 1]))
    }

    /// Counts one request's outcome: `end`ed means the supervisor is gone
    /// or past its `--duration` (`cut`).
    fn add(&mut self, r: Result<(), String>, started: Instant, cut: Instant, end: &AtomicBool) {
        self.made += 1;
        match r {
            Ok(()) => self.ms.push(started.elapsed().as_secs_f64() * 1e3),
            Err(_) if end.load(Ordering::Acquire) || Instant::now() >= cut => self.cut_off += 1,
            Err(e) => {
                self.failed += 1;
                self.note(e);
            }
        }
    }
}

/// Every client's requests in one slice (or summed over slices).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Clients {
    /// `motionctl status --watch`: one per slice; failed = ended by itself
    /// while the supervisor ran.
    pub watch: Count,
    /// `motionctl status --json`, every `--status-every-ms`.
    pub status: Count,
    /// `motionctl stats --json`, every `--stats-every-ms`.
    pub stats: Count,
    /// `motionctl home X --json` (variant c); failed = no row, or X not
    /// homed with PC set.
    pub home: Count,
}

impl Clients {
    pub fn merge(&mut self, o: &Clients) {
        self.watch.merge(&o.watch);
        self.status.merge(&o.status);
        self.stats.merge(&o.stats);
        self.home.merge(&o.home);
    }

    /// Requests made by every client (a watch counts once).
    pub fn made(&self) -> u64 {
        self.watch.made + self.status.made + self.stats.made + self.home.made
    }

    pub fn failed(&self) -> u64 {
        self.watch.failed + self.status.failed + self.stats.failed + self.home.failed
    }

    pub fn cut_off(&self) -> u64 {
        self.watch.cut_off + self.status.cut_off + self.stats.cut_off + self.home.cut_off
    }
}

/// What attaches: the periods of the pollers, and whether X is homed.
pub struct Plan {
    pub status_every: Duration,
    pub stats_every: Duration,
    pub homing: bool,
}

/// The clients attached to one supervisor.
pub struct Attached {
    end: Arc<AtomicBool>,
    cut: Instant,
    watch: Option<Running>,
    /// When the watch was seen to have ended by itself.
    watch_ended: Option<Instant>,
    status: Option<JoinHandle<Count>>,
    stats: Option<JoinHandle<Count>>,
    home: Option<JoinHandle<Count>>,
}

/// Attaches every client to the supervisor of `prefix`, whose `--duration`
/// runs out at `cut` at the earliest.
pub fn attach(motionctl: &Path, prefix: &str, p: &Plan, cut: Instant) -> Result<Attached, String> {
    let end = Arc::new(AtomicBool::new(false));
    let mut cmd = Command::new(motionctl);
    cmd.args(["--service-prefix", prefix, "status", "--watch"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    // not captured: stdout stays /dev/null, stderr is still read
    let watch = Running::spawn(&mut cmd, "motionctl status --watch", false, false)?;
    let poller = |args: &'static [&'static str], every: Duration| {
        let (m, pf, e) = (motionctl.to_path_buf(), prefix.to_string(), end.clone());
        std::thread::Builder::new()
            .name("cpcost-client".into())
            .spawn(move || periodic(&m, &pf, args, every, cut, &e))
            .map_err(|e| format!("cannot start a client thread: {e}"))
    };
    let status = poller(&["status", "--json"], p.status_every)?;
    let stats = poller(&["stats", "--json"], p.stats_every)?;
    let home = if p.homing {
        let (m, pf, e) = (motionctl.to_path_buf(), prefix.to_string(), end.clone());
        Some(
            std::thread::Builder::new()
                .name("cpcost-home".into())
                .spawn(move || homing(&m, &pf, cut, &e))
                .map_err(|e| format!("cannot start a client thread: {e}"))?,
        )
    } else {
        None
    };
    Ok(Attached {
        end,
        cut,
        watch: Some(watch),
        watch_ended: None,
        status: Some(status),
        stats: Some(stats),
        home,
    })
}

impl Attached {
    /// Notes when the watch ended by itself (call it now and then while the
    /// supervisor runs).
    pub fn poll(&mut self) {
        if self.watch_ended.is_none() && self.watch.as_mut().is_some_and(|w| !w.running()) {
            self.watch_ended = Some(Instant::now());
        }
    }

    /// Ends every client (the watch with SIGTERM, the pollers after their
    /// request in flight) and returns the counts.
    pub fn detach(mut self) -> Clients {
        self.poll();
        self.end.store(true, Ordering::Release);
        let mut c = Clients::default();
        if let Some(w) = self.watch.take() {
            c.watch.made = 1;
            let ended = w.wait(Duration::ZERO, Duration::from_secs(3));
            match self.watch_ended {
                None => {}
                Some(t) if t >= self.cut => c.watch.cut_off = 1,
                Some(_) => {
                    c.watch.failed = 1;
                    c.watch.note(format!(
                        "status --watch ended while the supervisor ran: {}; {}",
                        ended.describe(),
                        drive::tail(&ended.stderr, 3)
                    ));
                }
            }
        }
        let join = |h: Option<JoinHandle<Count>>| {
            h.map(|h| {
                h.join().unwrap_or_else(|_| Count {
                    details: vec!["client thread panicked".into()],
                    failed: 1,
                    ..Count::default()
                })
            })
            .unwrap_or_default()
        };
        c.status = join(self.status.take());
        c.stats = join(self.stats.take());
        c.home = join(self.home.take());
        c
    }
}

impl Drop for Attached {
    fn drop(&mut self) {
        // detach() not reached (an error on the way): the threads still end
        // after their request; the watch ends with its Running.
        self.end.store(true, Ordering::Release);
    }
}

/// `motionctl --service-prefix P ARGS...` every `every` (a request that
/// takes longer delays the next one: no burst to catch up) until `end`.
fn periodic(
    motionctl: &Path,
    prefix: &str,
    args: &[&str],
    every: Duration,
    cut: Instant,
    end: &AtomicBool,
) -> Count {
    let mut c = Count::default();
    let mut next = Instant::now();
    while !end.load(Ordering::Acquire) && !proc::stop_requested() {
        let started = Instant::now();
        let r = request(motionctl, prefix, args);
        c.add(r, started, cut, end);
        next += every;
        let now = Instant::now();
        if next <= now {
            next = now;
        } else {
            sleep_until(next, end);
        }
    }
    c
}

/// Sleeps until `t` in steps of at most 20 ms, returning early on `end` or
/// a stop request.
fn sleep_until(t: Instant, end: &AtomicBool) {
    loop {
        let now = Instant::now();
        if now >= t || end.load(Ordering::Acquire) || proc::stop_requested() {
            return;
        }
        std::thread::sleep((t - now).min(Duration::from_millis(20)));
    }
}

/// One `motionctl --service-prefix P ARGS... --json` to its end: Ok if it
/// exited 0 and printed a JSON object without `errors`.
fn request(motionctl: &Path, prefix: &str, args: &[&str]) -> Result<(), String> {
    let what = args.join(" ");
    let mut cmd = Command::new(motionctl);
    cmd.args(["--service-prefix", prefix]).args(args);
    let mut r = Running::spawn(&mut cmd, "motionctl", true, false)?;
    let until = Instant::now() + REQUEST_TIMEOUT;
    while r.running() && Instant::now() < until && !proc::stop_requested() {
        std::thread::sleep(Duration::from_millis(5));
    }
    // ended: collects its output; still running: terminated (timed out)
    let ended = r.wait(Duration::ZERO, Duration::from_secs(1));
    let json = last_json(&ended.stdout);
    if !ended.success() {
        let said = json
            .as_ref()
            .and_then(|j| j.get("errors"))
            .map(|e| e.to_string())
            .unwrap_or_else(|| drive::tail(&ended.stderr, 2));
        return Err(format!("{what}: {}; {said}", ended.describe()));
    }
    match json {
        Some(j) if j.get("errors").is_none() => Ok(()),
        Some(j) => Err(format!("{what}: errors {}", j["errors"])),
        None => Err(format!("{what}: no JSON object on its stdout")),
    }
}

/// `motionctl home X --json` back to back until `end`, none started past
/// `cut` (it would only be cut off: X takes ~3 s to home).
fn homing(motionctl: &Path, prefix: &str, cut: Instant, end: &AtomicBool) -> Count {
    let mut c = Count::default();
    while !end.load(Ordering::Acquire) && !proc::stop_requested() && Instant::now() < cut {
        let started = Instant::now();
        let r = drive::ctl_home(motionctl, prefix, &["X"], false, HOME_TIMEOUT_S).and_then(|run| {
            if !run.rows.is_empty() && run.rows.iter().all(|x| x.succeeded()) {
                Ok(())
            } else {
                Err(format!(
                    "home X: {}; rows {}; {}",
                    run.ended.describe(),
                    run.rows
                        .iter()
                        .map(|x| format!(
                            "{} pc {} er {} homed {} err {}/{}",
                            x.name, x.pc, x.er, x.homed, x.err, x.exerr
                        ))
                        .collect::<Vec<_>>()
                        .join(", "),
                    drive::tail(&run.ended.stderr, 2)
                ))
            }
        });
        c.add(r, started, cut, end);
    }
    c
}
