//! The clients of a deployed machine, attached to a running supervisor for
//! the rest of its slice: an HMI (`motionctl status --watch`, output to
//! /dev/null), a PLC polling `motionctl status --json`, a `motionctl stats
//! --json` now and then, and with `--homing` `motionctl home X --json` back
//! to back. Every request is a `motionctl` process, as an operator's or a
//! script's would be; each is counted as made, failed, or cut off by the
//! slice's end (failed after the supervisor's `--duration` ran out: it was
//! stopping), with how long it took from start to exit.
//!
//! The bench's thread polls them every few ms ([`Attached::poll`]): a
//! request ends, the next one starts when it is due; every `motionctl`
//! started has ended when [`Attached::detach`] returns.

use motion_bench::drive::{self, last_json, rows_of};
use motion_bench::proc::{Ended, Running};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How long one status or stats request may take before it is ended and
/// counted as failed (motionctl itself gives up after 2 s without an answer).
const REQUEST_TIMEOUT: Duration = Duration::from_secs(10);
/// `home X` (X homes in about 2 s): motionctl gives up after 30 s, the
/// bench ends it after 60.
const HOME: &[&str] = &["home", "X", "--json", "--timeout", "30"];
const HOME_WAIT: Duration = Duration::from_secs(60);
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

    /// Counts one request's outcome, `ms` long; `cut`: the supervisor is
    /// gone or past its `--duration`.
    fn add(&mut self, r: Result<(), String>, ms: f64, cut: bool) {
        self.made += 1;
        match r {
            Ok(()) => self.ms.push(ms),
            Err(_) if cut => self.cut_off += 1,
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

/// One client: the same request again and again, one at a time.
struct Client {
    /// `motionctl`'s arguments after `--service-prefix P`.
    args: &'static [&'static str],
    /// From one start to the next (a request that takes longer delays the
    /// next one: no burst to catch up); None: back to back, none started
    /// past the cut (it would only be cut off: X takes ~3 s to home).
    every: Option<Duration>,
    next: Instant,
    /// The request in flight, since when.
    busy: Option<(Running, Instant)>,
    count: Count,
}

/// The clients attached to one supervisor.
pub struct Attached {
    motionctl: PathBuf,
    prefix: String,
    /// When the supervisor's `--duration` runs out at the earliest.
    cut: Instant,
    watch: Running,
    /// When the watch was seen to have ended by itself.
    watch_ended: Option<Instant>,
    /// status, stats, and home X.
    clients: Vec<Client>,
}

/// Attaches every client to the supervisor of `prefix`, whose `--duration`
/// runs out at `cut` at the earliest.
pub fn attach(motionctl: &Path, prefix: &str, p: &Plan, cut: Instant) -> Result<Attached, String> {
    let mut cmd = Command::new(motionctl);
    cmd.args(["--service-prefix", prefix, "status", "--watch"]);
    // not captured: stdout stays /dev/null, stderr is still read
    cmd.stdout(Stdio::null()).stderr(Stdio::piped());
    let watch = Running::spawn(&mut cmd, "motionctl status --watch", false, false)?;
    let client = |args, every| Client {
        args,
        every,
        next: Instant::now(),
        busy: None,
        count: Count::default(),
    };
    let mut clients = vec![
        client(&["status", "--json"], Some(p.status_every)),
        client(&["stats", "--json"], Some(p.stats_every)),
    ];
    if p.homing {
        clients.push(client(HOME, None));
    }
    let (motionctl, prefix) = (motionctl.to_path_buf(), prefix.to_string());
    Ok(Attached {
        motionctl,
        prefix,
        cut,
        watch,
        watch_ended: None,
        clients,
    })
}

impl Client {
    /// The longest one request may take.
    fn timeout(&self) -> Duration {
        self.every.map_or(HOME_WAIT, |_| REQUEST_TIMEOUT)
    }

    fn start(&mut self, motionctl: &Path, prefix: &str) {
        let mut cmd = Command::new(motionctl);
        cmd.args(["--service-prefix", prefix]).args(self.args);
        match Running::spawn(&mut cmd, "motionctl", true, false) {
            Ok(r) => self.busy = Some((r, Instant::now())),
            Err(e) => self.counted(Err(e), 0.0, false),
        }
    }

    /// The request in flight to its end (ended at its timeout), counted;
    /// `cut`: the supervisor is gone or past its `--duration`.
    fn end(&mut self, cut: bool) {
        if let Some((r, t)) = self.busy.take() {
            let left = self.timeout().saturating_sub(t.elapsed());
            let ended = r.wait(left, Duration::from_secs(1));
            let ms = t.elapsed().as_secs_f64() * 1e3;
            self.counted(check(self.args, &ended), ms, cut);
        }
    }

    /// Counts a request; the next one is due a period after this one was,
    /// at once if that has passed (back to back: at once).
    fn counted(&mut self, r: Result<(), String>, ms: f64, cut: bool) {
        self.count.add(r, ms, cut);
        let now = Instant::now();
        self.next = self.every.map_or(now, |every| (self.next + every).max(now));
    }
}

impl Attached {
    /// Counts the requests that ended, starts those that are due, notes
    /// when the watch ended by itself (call it every few ms while the
    /// supervisor runs).
    pub fn poll(&mut self) {
        self.note_watch();
        for c in &mut self.clients {
            if let Some((r, t)) = &mut c.busy {
                if r.running() && t.elapsed() < c.timeout() {
                    continue;
                }
                c.end(Instant::now() >= self.cut);
            }
            let now = Instant::now();
            if c.busy.is_none() && now >= c.next && (c.every.is_some() || now < self.cut) {
                c.start(&self.motionctl, &self.prefix);
            }
        }
    }

    fn note_watch(&mut self) {
        if self.watch_ended.is_none() && !self.watch.running() {
            self.watch_ended = Some(Instant::now());
        }
    }

    /// Ends every client (the requests in flight once they end, counted as
    /// cut off if they fail; the watch with SIGTERM) and returns the counts.
    pub fn detach(mut self) -> Clients {
        self.note_watch();
        let mut counts = self.clients.into_iter().map(|mut c| {
            c.end(true);
            c.count
        });
        let mut c = Clients {
            status: counts.next().unwrap_or_default(),
            stats: counts.next().unwrap_or_default(),
            home: counts.next().unwrap_or_default(),
            ..Clients::default()
        };
        c.watch.made = 1;
        let ended = self.watch.wait(Duration::ZERO, Duration::from_secs(3));
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
        c
    }
}

/// Whether a request of `args` succeeded: `home X` if X homed, every other
/// if motionctl exited 0 and printed a JSON object without `errors`.
fn check(args: &[&str], ended: &Ended) -> Result<(), String> {
    let json = last_json(&ended.stdout);
    if args == HOME {
        let rows = json.as_ref().map(rows_of).unwrap_or_default();
        if !rows.is_empty() && rows.iter().all(|x| x.succeeded()) {
            return Ok(());
        }
        let rows: Vec<String> = (rows.iter())
            .map(|x| {
                format!(
                    "{} pc {} er {} homed {} err {}/{}",
                    x.name, x.pc, x.er, x.homed, x.err, x.exerr
                )
            })
            .collect();
        let (how, tail) = (ended.describe(), drive::tail(&ended.stderr, 2));
        return Err(format!("home X: {how}; rows {}; {tail}", rows.join(", ")));
    }
    let what = args.join(" ");
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
