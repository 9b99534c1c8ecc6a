//! The fault campaign's multi-process subset: real processes, real motion,
//! each process killed or stopped at a random moment, the outcome read
//! from the drive itself.
//!
//! One axis X (immediate homing at raw 0, soft limits ±20 while homed,
//! `max_speed` 20), homed and enabled by a daemon, runs one of three
//! motions, each driven by a client process: a jog (`motionctl jog`, its
//! lease renewed every 100 ms), a move (`motionctl move`, following it) or
//! a stream (`motionctl stream`, a program on `motion_control::stream`).
//! At a random moment of that motion one process — `motion-io`, the daemon
//! `motion-supervisor`, or the client — is killed (SIGKILL), stopped for
//! good (SIGSTOP, never continued) or stopped and continued (SIGSTOP, then
//! SIGCONT after a random pause longer than the watchdog that must notice
//! it). On the EtherCAT emulator two more events: the drive short on
//! process data (SAFE-OP with an AL error, OP refused, later accepted
//! again) and a power cycle of the drive.
//!
//! The oracle reads the drive: on EtherCAT the emulated CiA 402 drive
//! (`ecat_emu`'s view: its state, position and velocity, sampled every
//! 2 ms); on the sim what the sim reports through the daemon's status
//! (its position, velocity and enable as fed back), and where the daemon
//! is gone, `motion-io`'s own report of its watchdog stop. It checks:
//! * the axis comes to rest (a state awaited, never a wall-clock bound);
//! * never beyond a travel limit (±20, plus a count);
//! * the power stage off where it must be (a dead or stopped daemon or
//!   `motion-io`, a drive short on data, a power cycle): Switch on disabled,
//!   Ready to switch on or Fault on the drive, `enabled` false on the sim;
//! * once off, never enabled again (the test asks for nothing);
//! * a dead or stopped client's jog stops within its lease: at most
//!   v × (lease + renewal period + status period) + v² / (2 d) beyond
//!   where it was.
//!
//! Seeded: the seed is printed and `MOTION_MP_CAMPAIGN_SEED` sets it, so a
//! failure runs again the same way; `MOTION_MP_CAMPAIGN_TRIALS` (one by
//! default) runs more trials per cell. Each trial has its own service
//! prefix and leaves nothing in /dev/shm. The EtherCAT cells need root
//! (`SKIPPED: …` otherwise).

use std::time::{Duration, Instant};

use ecat_emu::{al, Dropped, State};
use motion_harness::ecat::Bus;
use motion_harness::*;
use motion_report::AxisStatus;
use nix::sys::signal::Signal;

/// The axis: X of the operations' fixture, alone.
const MACHINE: &str = r#"
[[axis]]
name = "X"
counts_per_unit = 1000.0
home_sequence = "immediate"
home_position = 0.0
home_speed = 10.0
home_return_speed = 2.0
home_acceleration = 100.0
home_deceleration = 100.0
max_speed = 20.0
max_deceleration = 100.0
travel_limits = [-20.0, 20.0]
position_error_tolerance = 0.5
stream_timeout_ms = 200
[axis.sim]
start = 0.0
hard_stop = [-40.0, 40.0]
"#;

/// The travel limit (units; raw = axis position: homed at raw 0).
const LIMIT: f64 = 20.0;
/// The jog's speed and the axis' deceleration.
const JOG_SPEED: f64 = 5.0;
const DECEL: f64 = 100.0;
/// `motionctl jog`: lease 500 ms renewed every 100 ms; the status every
/// 10 ms (the sim's position read a status period late).
const JOG_LEASE_S: f64 = 0.5 + 0.1 + 0.05;

/// A small seeded generator (SplitMix64): the campaign's moments.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[lo, hi)` milliseconds.
    fn ms(&mut self, lo: u64, hi: u64) -> Duration {
        Duration::from_millis(lo + self.next() % (hi - lo))
    }
    fn pick<T: Copy>(&mut self, of: &[T]) -> T {
        of[(self.next() % of.len() as u64) as usize]
    }
}

/// The seed (`MOTION_MP_CAMPAIGN_SEED`, or the clock), printed.
fn seed(which: &str) -> Rng {
    let s = std::env::var("MOTION_MP_CAMPAIGN_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(1, |d| d.as_nanos() as u64)
        });
    eprintln!("{which}: MOTION_MP_CAMPAIGN_SEED={s}");
    Rng(s)
}

fn trials() -> usize {
    std::env::var("MOTION_MP_CAMPAIGN_TRIALS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1)
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Motion {
    Jog,
    Move,
    Stream,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    Io,
    Daemon,
    Client,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Action {
    Kill,
    /// SIGSTOP, never continued (killed when the trial ends).
    Stop,
    /// SIGSTOP, SIGCONT after the pause.
    StopCont,
}

/// What a cell does to the running machine.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Event {
    Signal(Target, Action),
    /// EtherCAT: the drive in SAFE-OP with an AL error, OP refused; after
    /// the pause OP accepted again.
    DriveShort,
    /// EtherCAT: the drive's power off, on again after the pause.
    PowerCycle,
}

impl Event {
    /// Where the power stage must end off.
    fn must_switch_off(self) -> bool {
        !matches!(self, Event::Signal(Target::Client, _))
    }
}

fn signal_cells() -> Vec<Event> {
    let mut cells = Vec::new();
    for t in [Target::Io, Target::Daemon, Target::Client] {
        for a in [Action::Kill, Action::Stop, Action::StopCont] {
            cells.push(Event::Signal(t, a));
        }
    }
    cells
}

/// What one trial showed, for the summary.
#[derive(Debug)]
struct Outcome {
    /// From the event until at rest (and off where it must be).
    to_rest: Duration,
    /// Travel from the event until at rest.
    went: f64,
}

/// A trial's machine: the daemon and, on EtherCAT, the bus.
struct Rig {
    d: Daemon,
    bus: Option<Bus>,
    _cfg: Option<TempConfig>,
}

impl Rig {
    fn prefix(&self) -> &str {
        &self.d.prefix
    }
}

/// The drive as the oracle reads it: position, velocity, enabled, off.
#[derive(Clone, Copy, Debug)]
struct Drive {
    position: Option<f64>,
    velocity: f64,
    enabled: bool,
    /// Power stage off by the drive's own state (sim: not enabled).
    off: bool,
    /// Still moving by what the daemon commands (sim only).
    busy: bool,
}

/// The sim's drive through the status: enabled as its feedback says while
/// it reports; a sim that no longer reports (its `motion-io` gone or
/// stopped) counts as off once the daemon no longer asks for the power
/// stage (no servo action).
fn from_status(a: &AxisStatus) -> Drive {
    let reports = a.position.is_some();
    Drive {
        position: a.position,
        velocity: a.velocity.unwrap_or(0.0),
        enabled: reports && a.enabled,
        off: if reports { !a.enabled } else { !a.servo_action },
        busy: a.jogging || a.moving || a.streaming || a.stopping,
    }
}

/// The emulated drive as it sees itself: its power stage off in a CiA 402
/// state without one (Not ready / Switch on disabled / Ready to switch on)
/// or in Fault.
fn from_drive(b: &Bus) -> Drive {
    let v = b.drive(0).drive;
    Drive {
        position: Some(v.position),
        velocity: v.velocity,
        enabled: v.enabled,
        off: !v.enabled
            && matches!(
                v.state,
                State::NotReadyToSwitchOn
                    | State::SwitchOnDisabled
                    | State::ReadyToSwitchOn
                    | State::Fault
            ),
        busy: false,
    }
}

/// Reads the drive: the emulator's view, or the sim's through the status
/// (None: the daemon does not answer).
fn read(rig: &Rig) -> Option<Drive> {
    match &rig.bus {
        Some(b) => Some(from_drive(b)),
        None => daemon::status(&bins::test_bin("motionctl"), rig.prefix())
            .and_then(|s| s.axes.into_iter().find(|a| a.name == "X"))
            .map(|a| from_status(&a)),
    }
}

/// Starts the daemon (and the bus), homes and enables X.
fn start(tag: &str, ecat: bool) -> Option<Rig> {
    let machine = Machine::parse(MACHINE);
    let (d, bus, cfg) = if ecat {
        let b = Bus::start(tag, &machine, |_| {})?;
        (Daemon::start(&b.cfg, &["bus0"]), Some(b), None)
    } else {
        let cfg = machine.write(tag);
        (Daemon::start(&cfg, &["io"]), None, Some(cfg))
    };
    d.ctl(&["home", "X"]).expect_code(0);
    d.ctl(&["enable", "X"]).expect_code(0);
    assert!(
        wait_for(Duration::from_secs(10), || {
            let a = d.axis("X");
            a.homed && a.servo_action
        }),
        "X not ready: {:#?}\n{}",
        d.axis("X"),
        d.stderr()
    );
    Some(Rig { d, bus, _cfg: cfg })
}

/// The client of `motion`, started.
fn client(rig: &Rig, motion: Motion, dir: &TempDir) -> Running {
    let p = rig.prefix().to_string();
    match motion {
        Motion::Jog => spawn_motionctl(&["--service-prefix", &p, "jog", "X", "--speed", "5"]),
        Motion::Move => spawn_motionctl(&[
            "--service-prefix",
            &p,
            "move",
            "X",
            "--to",
            "8",
            "--speed",
            "5",
        ]),
        Motion::Stream => {
            // 0 → 19 over 8 s at 100 rows/s, starting and ending at rest
            // (3s² − 2s³: at most 3.6 u/s)
            let csv = dir.file("ramp.csv");
            let mut text = String::from("t,x\n");
            for k in 0..=800 {
                let t = k as f64 / 100.0;
                let s = t / 8.0;
                text += &format!("{t},{}\n", 19.0 * s * s * (3.0 - 2.0 * s));
            }
            std::fs::write(&csv, text).unwrap();
            spawn_motionctl(&["--service-prefix", &p, "stream", "X", "--csv", &csv])
        }
    }
}

/// The pid a signal goes to.
fn pid_of(rig: &Rig, t: Target, c: &Running) -> i32 {
    match t {
        Target::Io => find_process("motion-io", rig.prefix()).expect("motion-io"),
        Target::Daemon => rig.d.pid() as i32,
        Target::Client => c.pid() as i32,
    }
}

/// What the oracle saw while it waited.
struct Watch {
    /// Furthest out (|position|).
    furthest: f64,
    /// Power stage seen off since the event.
    was_off: bool,
    last: Option<Drive>,
}

impl Watch {
    /// One sample: checks the limits and that an axis once off stays off.
    #[track_caller]
    fn sample(&mut self, d: Drive, ctx: &str) {
        if let Some(p) = d.position {
            self.furthest = self.furthest.max(p.abs());
            assert!(
                p.abs() <= LIMIT + COUNT,
                "{ctx}: beyond a travel limit: {d:?}"
            );
        }
        if d.off {
            self.was_off = true;
        }
        assert!(
            !(self.was_off && d.enabled),
            "{ctx}: enabled again without a request: {d:?}"
        );
        self.last = Some(d);
    }
}

/// Waits until the drive rests (velocity 0, the position unchanged over
/// 100 ms, the daemon commanding nothing) and, where `off`, its power
/// stage is off; then watches 300 ms more. Returns when it was first seen
/// so and the position at rest.
#[track_caller]
fn rest(rig: &Rig, off: bool, w: &mut Watch, ctx: &str) -> (Instant, Option<f64>) {
    let t0 = Instant::now();
    let period = Duration::from_millis(if rig.bus.is_some() { 2 } else { 20 });
    let mut still_since: Option<(Instant, Option<f64>)> = None;
    let mut at_rest = None;
    while t0.elapsed() < Duration::from_secs(20) {
        if let Some(d) = read(rig) {
            w.sample(d, ctx);
            let resting = d.velocity == 0.0 && !d.busy && (!off || d.off);
            match still_since {
                Some((since, p)) if resting && p == d.position => {
                    if since.elapsed() >= Duration::from_millis(100) {
                        at_rest = Some((since, d.position));
                        break;
                    }
                }
                _ => still_since = resting.then(|| (Instant::now(), d.position)),
            }
        }
        std::thread::sleep(period);
    }
    let (took, at) = at_rest.unwrap_or_else(|| {
        panic!(
            "{ctx}: not at rest{}: {:?}\n{}",
            if off { " with its power stage off" } else { "" },
            w.last,
            rig.d.stderr()
        )
    });
    let until = Instant::now() + Duration::from_millis(300);
    while Instant::now() < until {
        if let Some(d) = read(rig) {
            w.sample(d, ctx);
            if let (Some(p), Some(a)) = (d.position, at) {
                assert!((p - a).abs() <= COUNT, "{ctx}: moved after rest: {d:?}");
            }
        }
        std::thread::sleep(period);
    }
    (took, at)
}

/// One trial of `event` during `motion` at a random moment.
fn trial(ecat: bool, event: Event, motion: Motion, rng: &mut Rng, n: usize) -> Option<Outcome> {
    let tag = format!("mpc{}{n}", if ecat { "e" } else { "s" });
    let rig = start(&tag, ecat)?;
    let dir = TempDir::new(&tag);
    let mut c = client(&rig, motion, &dir);
    let ctx = format!("{event:?} during a {motion:?} ({})", rig.prefix());
    assert!(
        wait_for(Duration::from_secs(10), || read(&rig)
            .and_then(|d| d.position)
            .is_some_and(|p| p > 0.2)),
        "{ctx}: never moving: {:?}\n{}",
        read(&rig),
        rig.d.stderr()
    );
    std::thread::sleep(rng.ms(0, 400));
    let before = read(&rig).and_then(|d| d.position).unwrap_or(0.0);
    let mut w = Watch {
        furthest: before.abs(),
        was_off: false,
        last: None,
    };
    let t0 = Instant::now();
    let mut stopped = None;
    match event {
        Event::Signal(t, a) => {
            let pid = pid_of(&rig, t, &c);
            match a {
                Action::Kill => signal_pid(pid, Signal::SIGKILL),
                Action::Stop => {
                    signal_pid(pid, Signal::SIGSTOP);
                    stopped = Some(pid);
                }
                Action::StopCont => {
                    signal_pid(pid, Signal::SIGSTOP);
                    // longer than what must notice it: the watchdogs (50 ms),
                    // the feedback timeout (20 ms), a jog's lease (500 ms)
                    let pause = match t {
                        Target::Client => rng.ms(700, 1200),
                        _ => rng.ms(100, 600),
                    };
                    if rig.bus.is_none() && t != Target::Daemon {
                        watch_for(&rig, &mut w, pause, &ctx);
                    } else if let Some(b) = &rig.bus {
                        watch_drive(b, &mut w, pause, &ctx);
                    } else {
                        std::thread::sleep(pause);
                    }
                    signal_pid(pid, Signal::SIGCONT);
                }
            }
        }
        Event::DriveShort => {
            let emu = rig.bus.as_ref().expect("bus").rig.emulator();
            emu.refuse_op(0, Some(al::SYNC_ERROR));
            emu.drop_out_of_op(0, Dropped::SafeOp(al::SYNC_ERROR));
        }
        Event::PowerCycle => rig.bus.as_ref().expect("bus").rig.emulator().power_off(0),
    }
    let outcome = settle(&rig, event, motion, &mut w, t0, before, rng, &ctx);
    eprintln!(
        "{ctx}: at rest {:.0} ms after the event, {:.3} units further, furthest {:.3}",
        outcome.to_rest.as_secs_f64() * 1e3,
        outcome.went,
        w.furthest
    );
    c.signal(Signal::SIGCONT);
    let _ = c.kill();
    end(rig, stopped);
    Some(outcome)
}

/// Samples the sim's drive for `pause` (the daemon answers).
fn watch_for(rig: &Rig, w: &mut Watch, pause: Duration, ctx: &str) {
    let until = Instant::now() + pause;
    while Instant::now() < until {
        if let Some(d) = read(rig) {
            w.sample(d, ctx);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Samples the emulated drive for `pause`.
fn watch_drive(b: &Bus, w: &mut Watch, pause: Duration, ctx: &str) {
    let until = Instant::now() + pause;
    while Instant::now() < until {
        w.sample(from_drive(b), ctx);
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// After the event: the outcome awaited and checked.
#[allow(clippy::too_many_arguments)]
fn settle(
    rig: &Rig,
    event: Event,
    motion: Motion,
    w: &mut Watch,
    t0: Instant,
    before: f64,
    rng: &mut Rng,
    ctx: &str,
) -> Outcome {
    let off = event.must_switch_off();
    let sim_daemon_gone = rig.bus.is_none()
        && matches!(
            event,
            Event::Signal(Target::Daemon, Action::Kill | Action::Stop)
        );
    if sim_daemon_gone {
        // the sim lives in motion-io: its watchdog's report is the outcome
        assert!(
            rig.d.wait_line(
                "watchdog: every axis stopped and disabled",
                Duration::from_secs(10)
            ),
            "{ctx}: motion-io never stopped its axes\n{}",
            rig.d.stderr()
        );
        return Outcome {
            to_rest: t0.elapsed(),
            went: f64::NAN,
        };
    }
    let (since, at) = rest(rig, off, w, ctx);
    let to_rest = since - t0;
    match event {
        Event::DriveShort | Event::PowerCycle => {
            // back after a pause: re-synchronised, never enabled by itself
            std::thread::sleep(rng.ms(100, 500));
            let emu = rig.bus.as_ref().expect("bus").rig.emulator();
            if event == Event::DriveShort {
                emu.refuse_op(0, None);
            } else {
                emu.power_on(0);
            }
            let b = rig.bus.as_ref().expect("bus");
            assert!(
                wait_for(Duration::from_secs(10), || b.drive(0).al_status == 0x08),
                "{ctx}: not back in OP: {:?}",
                b.drive(0)
            );
            let (_, again) = rest(rig, true, w, ctx);
            if let (Some(a), Some(p)) = (at, again) {
                assert!(
                    event == Event::PowerCycle || (a - p).abs() <= COUNT,
                    "{ctx}: moved when back: {a} → {p}"
                );
            }
        }
        _ => {}
    }
    let went = at.map_or(f64::NAN, |p| p - before);
    if let (Event::Signal(Target::Client, _), Motion::Jog) = (event, motion) {
        let bound = JOG_SPEED * JOG_LEASE_S + JOG_SPEED * JOG_SPEED / (2.0 * DECEL) + COUNT;
        assert!(
            went <= bound,
            "{ctx}: went {went} after the event, bound {bound}"
        );
    }
    Outcome { to_rest, went }
}

/// The trial's end: stopped processes killed, the daemon stopped, nothing
/// left behind.
fn end(rig: Rig, stopped: Option<i32>) {
    if let Some(pid) = stopped {
        signal_pid(pid, Signal::SIGKILL);
    }
    let prefix = rig.prefix().to_string();
    let Rig { d, bus, _cfg } = rig;
    drop(d);
    if let Some(pid) = find_process("motion-io", &prefix) {
        if !wait_for(Duration::from_secs(5), || {
            find_process("motion-io", &prefix).is_none()
        }) {
            signal_pid(pid, Signal::SIGKILL);
        }
    }
    assert!(
        wait_for(Duration::from_secs(5), || find_process(
            "motion-io",
            &prefix
        )
        .is_none()),
        "motion-io of {prefix} still runs"
    );
    assert_clean(&prefix);
    drop(bus);
}

/// Runs every cell `trials()` times, the motion chosen at random; prints
/// the cells' outcomes.
fn campaign(ecat: bool, cells: &[Event]) {
    let _serial = serial();
    let name = if ecat { "EtherCAT" } else { "sim" };
    let mut rng = seed(name);
    let motions = [Motion::Jog, Motion::Move, Motion::Stream];
    let mut n = 0;
    let mut rows = Vec::new();
    for &cell in cells {
        let mut worst: Option<Outcome> = None;
        for _ in 0..trials() {
            let motion = rng.pick(&motions);
            let Some(o) = trial(ecat, cell, motion, &mut rng, n) else {
                return; // SKIPPED (printed)
            };
            n += 1;
            worst = Some(match worst {
                Some(w) => Outcome {
                    to_rest: w.to_rest.max(o.to_rest),
                    went: w.went.max(o.went),
                },
                None => o,
            });
        }
        rows.push((cell, worst.expect("a trial")));
    }
    eprintln!(
        "{name} campaign: {} cells × {} trials, no violation",
        cells.len(),
        trials()
    );
    for (cell, o) in rows {
        eprintln!(
            "  {cell:?}: at rest within {:.0} ms, {:.3} units after the event (worst)",
            o.to_rest.as_secs_f64() * 1e3,
            o.went
        );
    }
}

#[test]
fn sim_every_process_killed_or_stopped_mid_motion() {
    campaign(false, &signal_cells());
}

#[test]
fn ethercat_every_process_killed_or_stopped_a_drive_short_or_power_cycled_mid_motion() {
    let mut cells = signal_cells();
    cells.extend([Event::DriveShort, Event::PowerCycle]);
    campaign(true, &cells);
}
