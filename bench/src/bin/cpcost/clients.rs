//! The clients of a deployed machine, attached to a running supervisor for
//! the rest of its slice: an HMI (`motionctl status --watch`, output to
//! /dev/null), a PLC polling `motionctl status --json`, a `motionctl stats
//! --json` now and then, and with `--homing` `motionctl home X --json` back
//! to back. Every request is a `motionctl` process, as an operator's or a
//! script's would be; each is counted as made, failed, or cut off by the
//! slice's end (failed after the supervisor's `--duration` ran out: it was
//! stopping), with how long it took from start to exit.
//!
//! The periodic clients run on threads of the bench (waiting for their
//! `motionctl` in 5 ms steps); every `motionctl` started is ended before
//! [`Attached::detach`] returns.

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
        o.details.iter().for_each(|d| self.note(d.clone()));
    }

    fn note(&mut self, s: String) {
        if self.details.len() < MAX_DETAILS {
            self.details.push(s);
        }
    }

    /// Median and maximum of [`Count::ms`].
    pub fn ms_p50_max(&self) -> Option<(f64, f64)> {
        let mut v = self.ms.clone();
        v.sort_by(f64::total_cmp);
        Some((*v.get(v.len() / 2)?, *v.last()?))
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
    fn all(&self) -> [&Count; 4] {
        [&self.watch, &self.status, &self.stats, &self.home]
    }

    pub fn merge(&mut self, o: &Clients) {
        self.watch.merge(&o.watch);
        self.status.merge(&o.status);
        self.stats.merge(&o.stats);
        self.home.merge(&o.home);
    }

    /// Requests made by every client (a watch counts once).
    pub fn made(&self) -> u64 {
        self.all().iter().map(|c| c.made).sum()
    }

    pub fn failed(&self) -> u64 {
        self.all().iter().map(|c| c.failed).sum()
    }

    pub fn cut_off(&self) -> u64 {
        self.all().iter().map(|c| c.cut_off).sum()
    }

    /// The first problems of every kind of request.
    pub fn details(&self) -> impl Iterator<Item = &String> {
        self.all().into_iter().flat_map(|c| c.details.iter())
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
    /// The status and stats pollers and the homing client.
    threads: [Option<JoinHandle<Count>>; 3],
}

/// Attaches every client to the supervisor of `prefix`, whose `--duration`
/// runs out at `cut` at the earliest.
pub fn attach(motionctl: &Path, prefix: &str, p: &Plan, cut: Instant) -> Result<Attached, String> {
    let end = Arc::new(AtomicBool::new(false));
    let mut cmd = Command::new(motionctl);
    cmd.args(["--service-prefix", prefix, "status", "--watch"]);
    // not captured: stdout stays /dev/null, stderr is still read
    cmd.stdout(Stdio::null()).stderr(Stdio::piped());
    let watch = Running::spawn(&mut cmd, "motionctl status --watch", false, false)?;
    let ctx = || (motionctl.to_path_buf(), prefix.to_string(), end.clone());
    let (every, (m, pf, e)) = (p.status_every, ctx());
    let status = client(move || periodic(&m, &pf, &["status", "--json"], every, cut, &e))?;
    let (every, (m, pf, e)) = (p.stats_every, ctx());
    let stats = client(move || periodic(&m, &pf, &["stats", "--json"], every, cut, &e))?;
    let (m, pf, e) = ctx();
    let home = p
        .homing
        .then(|| client(move || homing(&m, &pf, cut, &e)))
        .transpose()?;
    let threads = [Some(status), Some(stats), home];
    Ok(Attached {
        end,
        cut,
        watch: Some(watch),
        watch_ended: None,
        threads,
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
        let [status, stats, home] = self.threads.each_mut().map(|h| {
            let panicked = || Count {
                details: vec!["client thread panicked".into()],
                failed: 1,
                ..Count::default()
            };
            h.take()
                .map(|h| h.join().unwrap_or_else(|_| panicked()))
                .unwrap_or_default()
        });
        Clients {
            status,
            stats,
            home,
            ..c
        }
    }
}

impl Drop for Attached {
    fn drop(&mut self) {
        // detach() not reached (an error on the way): the threads still end
        // after their request; the watch ends with its Running.
        self.end.store(true, Ordering::Release);
    }
}

/// Runs a client on a thread of its own.
fn client(f: impl FnOnce() -> Count + Send + 'static) -> Result<JoinHandle<Count>, String> {
    let b = std::thread::Builder::new().name("cpcost-client".into());
    b.spawn(f)
        .map_err(|e| format!("cannot start a client thread: {e}"))
}

/// Whether a client goes on: not ended, not interrupted.
fn going(end: &AtomicBool) -> bool {
    !end.load(Ordering::Acquire) && !proc::stop_requested()
}

/// `motionctl --service-prefix P ARGS...` every `every` (a request that
/// takes longer delays the next one: no burst to catch up) until `end`.
fn periodic(
    m: &Path,
    prefix: &str,
    args: &[&str],
    every: Duration,
    cut: Instant,
    end: &AtomicBool,
) -> Count {
    let mut c = Count::default();
    let mut next = Instant::now();
    while going(end) {
        let started = Instant::now();
        c.add(request(m, prefix, args), started, cut, end);
        next = (next + every).max(Instant::now());
        // in steps of at most 20 ms, to see `end` and a stop request
        while Instant::now() < next && going(end) {
            std::thread::sleep((next - Instant::now()).min(Duration::from_millis(20)));
        }
    }
    c
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
    let errors = json.as_ref().and_then(|j| j.get("errors"));
    match (ended.success(), &json, errors) {
        (false, _, _) => {
            let said = errors.map_or_else(|| drive::tail(&ended.stderr, 2), |e| e.to_string());
            Err(format!("{what}: {}; {said}", ended.describe()))
        }
        (true, Some(_), None) => Ok(()),
        (true, Some(_), Some(e)) => Err(format!("{what}: errors {e}")),
        (true, None, _) => Err(format!("{what}: no JSON object on its stdout")),
    }
}

/// `motionctl home X --json` back to back until `end`, none started past
/// `cut` (it would only be cut off: X takes ~3 s to home).
fn homing(motionctl: &Path, prefix: &str, cut: Instant, end: &AtomicBool) -> Count {
    let mut c = Count::default();
    while going(end) && Instant::now() < cut {
        let started = Instant::now();
        let run = drive::ctl_home(motionctl, prefix, &["X"], false, HOME_TIMEOUT_S);
        let r = run.and_then(|run| {
            match !run.rows.is_empty() && run.rows.iter().all(|x| x.succeeded()) {
                true => Ok(()),
                false => {
                    let rows: Vec<String> = (run.rows.iter())
                        .map(|x| {
                            format!(
                                "{} pc {} er {} homed {} err {}/{}",
                                x.name, x.pc, x.er, x.homed, x.err, x.exerr
                            )
                        })
                        .collect();
                    let (how, tail) = (run.ended.describe(), drive::tail(&run.ended.stderr, 2));
                    Err(format!("home X: {how}; rows {}; {tail}", rows.join(", ")))
                }
            }
        });
        c.add(r, started, cut, end);
    }
    c
}
