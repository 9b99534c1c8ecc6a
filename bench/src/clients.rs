//! The clients of a deployed machine, attached to a running supervisor for
//! the rest of a run (the control-plane cost bench's load): an HMI
//! (`motionctl status --watch`, output to /dev/null), a PLC polling
//! `motionctl status --json`, a `motionctl stats --json` now and then, and
//! if asked `motionctl home X --json` back to back. Every request is a
//! `motionctl` process, as an operator's or a script's would be, counted as
//! made, failed, or cut off by the run's end (failed after the
//! supervisor's `--duration` ran out: it was stopping), with how long it
//! took from start to exit. The caller polls them every few ms; every
//! `motionctl` started has ended when [`Attached::detach`] returns.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::homing::{last_json, rows_of};
use crate::proc::{tail, Ended, Running};

/// The kinds of request, in the order of [`Clients`]: `status --watch`
/// (one per slice; failed = ended by itself while the supervisor ran),
/// `status --json` every `--status-every-ms`, `stats --json` every
/// `--stats-every-ms`, and `home X --json` (variant c; failed = no row,
/// or X not homed with PC set).
pub const WATCH: usize = 0;
pub const STATUS: usize = 1;
pub const STATS: usize = 2;
pub const HOME: usize = 3;

/// How long one status or stats request may take before it is ended and
/// counted as failed (motionctl itself gives up after 2 s without an answer).
const REQUEST_TIMEOUT: Duration = Duration::from_secs(10);
/// `home X` (X homes in about 2 s): motionctl gives up after 30 s, the
/// bench ends it after 60.
const HOME_ARGS: &[&str] = &["home", "X", "--json", "--timeout", "30"];
const HOME_WAIT: Duration = Duration::from_secs(60);
/// At most this many problem lines are kept per kind of request.
const MAX_DETAILS: usize = 20;

/// One kind of request, counted.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
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

/// Every kind of request in one slice (or summed over slices), indexed by
/// [`WATCH`], [`STATUS`], [`STATS`], [`HOME`].
#[derive(Clone, Debug, Default)]
pub struct Clients(pub [Count; 4]);

impl Clients {
    pub fn merge(&mut self, o: &Clients) {
        self.0.iter_mut().zip(&o.0).for_each(|(a, b)| a.merge(b));
    }

    /// Requests made by every client (a watch counts once).
    pub fn made(&self) -> u64 {
        self.0.iter().map(|c| c.made).sum()
    }

    pub fn failed(&self) -> u64 {
        self.0.iter().map(|c| c.failed).sum()
    }

    pub fn cut_off(&self) -> u64 {
        self.0.iter().map(|c| c.cut_off).sum()
    }

    /// The first problems of every kind of request.
    pub fn details(&self) -> impl Iterator<Item = &String> {
        self.0.iter().flat_map(|c| &c.details)
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
    kind: usize,
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

impl Client {
    fn new(kind: usize, args: &'static [&'static str], every: Option<Duration>) -> Self {
        let (next, busy, count) = (Instant::now(), None, Count::default());
        Client {
            kind,
            args,
            every,
            next,
            busy,
            count,
        }
    }

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
            let ended = r.wait(
                self.timeout().saturating_sub(t.elapsed()),
                Duration::from_secs(1),
            );
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

/// The clients attached to one supervisor.
pub struct Attached {
    motionctl: PathBuf,
    prefix: String,
    /// When the supervisor's `--duration` runs out at the earliest.
    cut: Instant,
    watch: Running,
    /// When the watch was seen to have ended by itself.
    watch_ended: Option<Instant>,
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
    let mut clients = vec![
        Client::new(STATUS, &["status", "--json"], Some(p.status_every)),
        Client::new(STATS, &["stats", "--json"], Some(p.stats_every)),
    ];
    if p.homing {
        clients.push(Client::new(HOME, HOME_ARGS, None));
    }
    let (motionctl, prefix, watch_ended) = (motionctl.to_path_buf(), prefix.to_string(), None);
    Ok(Attached {
        motionctl,
        prefix,
        cut,
        watch,
        watch_ended,
        clients,
    })
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
        let mut c = Clients::default();
        for mut k in self.clients {
            k.end(true);
            c.0[k.kind] = k.count;
        }
        let (w, ended) = (
            &mut c.0[WATCH],
            self.watch.wait(Duration::ZERO, Duration::from_secs(3)),
        );
        w.made = 1;
        match self.watch_ended {
            None => {}
            Some(t) if t >= self.cut => w.cut_off = 1,
            Some(_) => {
                w.failed = 1;
                let (how, tail) = (ended.describe(), tail(&ended.stderr, 3));
                w.note(format!(
                    "status --watch ended while the supervisor ran: {how}; {tail}"
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
    if args == HOME_ARGS {
        let rows = json.as_ref().map(rows_of).unwrap_or_default();
        if !rows.is_empty() && rows.iter().all(|x| x.succeeded()) {
            return Ok(());
        }
        let row = |x: &motion_report::AxisResult| {
            format!(
                "{} pc {} er {} homed {} err {}/{}",
                x.name, x.pc, x.er, x.homed, x.err, x.exerr
            )
        };
        let rows: Vec<String> = rows.iter().map(row).collect();
        let (how, tail) = (ended.describe(), tail(&ended.stderr, 2));
        return Err(format!("home X: {how}; rows {}; {tail}", rows.join(", ")));
    }
    let what = args.join(" ");
    let errors = json.as_ref().and_then(|j| j.get("errors"));
    match (ended.success(), &json, errors) {
        (false, _, _) => {
            let said = errors.map_or_else(|| tail(&ended.stderr, 2), |e| e.to_string());
            Err(format!("{what}: {}; {said}", ended.describe()))
        }
        (true, Some(_), None) => Ok(()),
        (true, Some(_), Some(e)) => Err(format!("{what}: errors {e}")),
        (true, None, _) => Err(format!("{what}: no JSON object on its stdout")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    /// A `motionctl` stand-in: `status --watch` waits, `status` and `stats`
    /// answer (stats with an error when `$FAIL_STATS` is set), `home` homes X.
    fn fake_motionctl(dir: &Path) -> PathBuf {
        let p = dir.join("motionctl");
        let home = r#"{"axes":[{"name":"X","mode":"","sequence":"","direction":"","pc":true,"er":false,"err":0,"exerr":0,"homed":true}]}"#;
        let script = format!(
            "#!/bin/sh\ncase \"$3 $4\" in\n\
             'status --watch') exec sleep 30 ;;\n\
             'status --json') echo '{{}}' ;;\n\
             'stats --json') echo '{{\"errors\":[\"no\"]}}'; exit 1 ;;\n\
             'home X') echo '{home}' ;;\nesac\n"
        );
        std::fs::write(&p, script).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
        p
    }

    #[test]
    fn requests_are_made_on_time_counted_and_ended() {
        let dir = motion_harness::TempDir::new("clients");
        let motionctl = fake_motionctl(dir.path());
        let (status_every, stats_every) = (Duration::from_millis(50), Duration::from_millis(150));
        let plan = Plan {
            status_every,
            stats_every,
            homing: true,
        };
        let cut = Instant::now() + Duration::from_secs(30);
        let mut a = attach(&motionctl, "p", &plan, cut).unwrap();
        let t = Instant::now();
        // long enough for every kind to be made at least once on a loaded
        // host (a fork and exec of the fake motionctl per request)
        while t.elapsed() < Duration::from_millis(1500) {
            a.poll();
            std::thread::sleep(Duration::from_millis(5));
        }
        let c = a.detach();
        let [watch, status, stats, home] = &c.0;
        assert_eq!(
            (watch.made, watch.failed, watch.cut_off),
            (1, 0, 0),
            "{c:?}"
        );
        assert!(
            (3..=31).contains(&status.made) && status.failed == 0,
            "{c:?}"
        );
        assert_eq!(status.ms.len() as u64, status.made);
        assert!(stats.made >= 1 && stats.failed == stats.made, "{c:?}");
        assert!(
            stats.details[0].starts_with("stats --json: exit code 1; [\"no\"]"),
            "{c:?}"
        );
        assert!(home.made >= 1 && home.failed == 0, "{c:?}");
        assert_eq!(c.made(), watch.made + status.made + stats.made + home.made);
        assert_eq!((c.failed(), c.cut_off()), (stats.made, 0));
        let mut twice = c.clone();
        twice.merge(&c);
        assert_eq!(twice.made(), 2 * c.made());
        assert!(status.ms_p50_max().is_some_and(|(p50, max)| p50 <= max));
    }

    #[test]
    fn a_failure_past_the_cut_is_cut_off_and_details_are_capped() {
        let mut c = Count::default();
        for k in 0..30 {
            c.add(Err(format!("e{k}")), 0.0, k % 2 == 0);
        }
        assert_eq!(
            (c.made, c.failed, c.cut_off, c.details.len()),
            (30, 15, 15, 15)
        );
        for k in 0..30 {
            c.add(Err(format!("f{k}")), 0.0, false);
        }
        assert_eq!(c.details.len(), MAX_DETAILS);
        assert_eq!(Count::default().ms_p50_max(), None);
    }
}
