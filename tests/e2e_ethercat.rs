//! The supervisor homing real(istic) drives end to end:
//! `motion-supervisor` → `motion-io --backend ethercat` (spawned by the
//! supervisor, ethercrab on its bus thread) → a veth pair → `ecat-emu`'s
//! CiA 402 drives, each over the same `motion_plant::Plant` the `sim`
//! backend uses, configured from the axis' own `[axis.sim]` table.
//!
//! The axes and the expected values are those of `e2e_sequences.rs` (the
//! arithmetic is there); each axis gets `ethercat_position` = its drive.
//! Latched events (markers, hard stops) must be exact to the count as in
//! the sim. A switch sampled once per cycle is placed at the midpoint of
//! the two samples around its edge; with the sim backend those samples are
//! one cycle apart (error ≤ speed × cycle / 2), over EtherCAT the bus cycle
//! and the supervisor's cycle are two clocks of the same period with an
//! arbitrary phase, so a sample can be one bus cycle old: error ≤ speed ×
//! cycle (noted at each such check). Where a move ends, the drive's plant
//! must rest at the expected position exactly; the reported `final_raw` /
//! `final_position` are the feedback of the cycle the engine's profile
//! ended in, which over EtherCAT may trail the last set-points by a few
//! counts ([`IN_FLIGHT`]).
//!
//! Needs root (raw sockets, `ip netns`): otherwise every test prints
//! `SKIPPED: …` and passes. The emulator runs in this process, its end of
//! the veth pair in a network namespace of its own (unique names per test);
//! `motion-io` opens the other end in the root namespace. The tests take
//! turns (`serial()`): each runs a SCHED_FIFO supervisor, a bus thread and
//! the emulator on a 2-core machine.

use std::time::{Duration, Instant};

use ecat_emu::{DriveConfig, Emulator, EmulatorConfig, State, VethPair};
use motion_config::EthercatDrive;
use motion_tests::*;
use nix::sys::signal::Signal;

const COMMON: &str = "counts_per_unit = 1000.0\nhome_timeout = 30.0\n";

/// One test's bus: the veth pair, the emulated drives, the config. Dropped
/// in this order: emulator, config file, namespace and pair.
struct Bus {
    emu: Emulator,
    cfg: TempConfig,
    pair: VethPair,
}

/// `axes` with `ethercat_position = k` added to every axis but the virtual
/// ones, k = 0, 1, … in config order.
fn on_the_bus(axes: &str) -> String {
    let mut out = String::new();
    let mut k = 0;
    for (i, block) in axes.split("[[axis]]").enumerate() {
        if i == 0 {
            out += block;
            continue;
        }
        out += "[[axis]]";
        let head_end = block.find("\n[").unwrap_or(block.len());
        let (head, rest) = block.split_at(head_end);
        out += head;
        if !head.contains("configuration = \"virtual\"") {
            out += &format!("\nethercat_position = {k}");
            k += 1;
        }
        out += rest;
    }
    out
}

/// Sets up pair, config and emulator; `None` (reason printed) without root.
/// `tweak` may change the drives (built from the config's `[axis.sim]`).
fn bus(
    tag: &str,
    supervisor_extra: &str,
    axes: &str,
    tweak: impl FnOnce(&mut [DriveConfig]),
) -> Option<Bus> {
    let pair = match VethPair::new() {
        Ok(p) => p,
        Err(skip) => {
            eprintln!("{skip}");
            return None;
        }
    };
    let io = format!(
        "[[io]]\nname = \"bus0\"\nspawn = \"supervisor\"\nbackend = \"ethercat\"\n\
         interface = \"{}\"\n",
        pair.master
    );
    let cfg = config(
        tag,
        supervisor_extra,
        &format!("{io}\n{}", on_the_bus(axes)),
    );
    let (m, _) = motion_config::load(Some(&cfg.path)).unwrap_or_else(|p| panic!("{p:#?}"));
    let mut drives: Vec<(u16, DriveConfig)> = m
        .axes
        .iter()
        .filter_map(|a| {
            let e = a.ethercat.as_ref()?;
            let EthercatDrive::Position(p) = e.drive else {
                return None;
            };
            let mut d = DriveConfig::new(&format!("EMU-{}", a.name));
            d.counts_per_unit = a.engine.counts_per_unit;
            d.plant = a.sim;
            d.serial = u32::from(p) + 1;
            Some((p, d))
        })
        .collect();
    drives.sort_by_key(|(p, _)| *p);
    let mut drives: Vec<DriveConfig> = drives.into_iter().map(|(_, d)| d).collect();
    tweak(&mut drives);
    let emu = Emulator::start(EmulatorConfig {
        interface: pair.subdevice.clone(),
        netns: Some(pair.netns.clone()),
        drives,
        priority: Some(60),
    })
    .expect("emulator");
    Some(Bus { emu, cfg, pair })
}

impl Bus {
    fn path(&self) -> &str {
        self.cfg.path.to_str().unwrap()
    }

    fn drive(&self, position: usize) -> ecat_emu::SubDeviceView {
        self.emu.view(position).expect("SubDevice")
    }
}

/// `home --json` on the bus: exit 0, latency measured, nothing left behind.
/// Returns the JSON and motion-io's / the supervisor's stderr.
fn home(b: &Bus) -> (serde_json::Value, String) {
    let t0 = Instant::now();
    let run = supervisor(&["home", "--json", "--config", b.path()]);
    assert_eq!(
        run.code,
        Some(0),
        "home failed\nstdout: {}\nstderr: {}",
        run.stdout,
        run.stderr
    );
    let v = run.json();
    let lat = &v["latency"];
    assert!(lat["cycles"].as_u64().unwrap() > 500, "{lat}");
    for k in ["wakeup_us", "compute_us", "io_roundtrip_us"] {
        for p in ["min", "p50", "p99", "p999", "max"] {
            assert!(lat[k][p].is_number(), "{k}.{p} missing: {lat}");
        }
    }
    assert_clean(&b.cfg.prefix);
    eprintln!(
        "home over EtherCAT took {:.1} s; I/O round trip {}; stderr:\n{}",
        t0.elapsed().as_secs_f64(),
        lat["io_roundtrip_us"],
        run.stderr
    );
    (v, run.stderr)
}

fn homed(v: &serde_json::Value, name: &str) -> serde_json::Value {
    let a = axis(v, name).clone();
    assert_eq!(a["pc"], true, "{a}");
    assert_eq!(a["er"], false, "{a}");
    assert_eq!(a["homed"], true, "{a}");
    a
}

/// Set-points still on their way when the engine ended a move, at most:
/// `final_raw` / `final_position` are the feedback of the cycle in which
/// the profile ended, and a CSP drive over EtherCAT shows a set-point about
/// three cycles after the engine computed it (sim: one); the last cycles of
/// a deceleration are a few counts.
const IN_FLIGHT: f64 = 5.0 * COUNT;

/// The move ended at `want` (raw): the drive's plant rests there exactly,
/// the reported `final_raw` (and `final_position`, `want_position`) within
/// [`IN_FLIGHT`].
fn ended_at(b: &Bus, drive: usize, a: &serde_json::Value, want: f64, want_position: f64) {
    let d = b.drive(drive).drive;
    assert!(
        (d.position - want).abs() <= COUNT,
        "{}: the drive rests at {}, want {want}",
        a["name"],
        d.position
    );
    assert_eq!(d.velocity, 0.0, "{d:?}");
    close(a, "final_raw", want, IN_FLIGHT);
    close(a, "final_position", want_position, IN_FLIGHT);
}

/// The drive's plant ended where the supervisor says the axis is (raw), and
/// stands still (motion-io stopped every axis on its way out). `final_raw`
/// is the last feedback the engine used: at the end of a deceleration the
/// last set-points may still have been on their way (a few counts).
fn drive_at(b: &Bus, position: usize, a: &serde_json::Value) {
    let d = b.drive(position).drive;
    let raw = num(a, "final_raw");
    assert!(
        (d.position - raw).abs() <= IN_FLIGHT,
        "{}: plant at {}, final_raw {raw}",
        a["name"],
        d.position
    );
    assert_eq!(d.velocity, 0.0, "{d:?}");
}

/// The start-up report (shown even though the supervisor runs motion-io
/// with --quiet) names every SubDevice with its axis and sync mode.
fn reported(stderr: &str, position: usize, axis: &str, sync: &str) {
    let want = format!("SubDevice {position} \"EMU-{axis}\": axis {axis}, {sync}");
    assert!(stderr.contains(&want), "no {want:?} in\n{stderr}");
}

#[test]
fn switch_family() {
    let _serial = serial();
    let Some(b) = bus(
        "ecat_switch",
        "",
        &format!(
            r#"
[[axis]]
name = "A"
{COMMON}
home_sequence = "switch"
home_direction = "bidirectional_reverse"
home_position = 10.0
home_offset = 1.0
home_speed = 20.0
home_return_speed = 2.0
home_acceleration = 500.0
home_deceleration = 500.0
travel_limits = [-100.0, 100.0]
[axis.sim]
start = 20.0
switch = [0.0, 5.0]
hard_stop = [-100.0, 100.0]

[[axis]]
name = "B"
{COMMON}
marker = true
home_sequence = "switch_then_marker"
home_direction = "unidirectional_forward"
home_switch_normally_closed = true
home_speed = 20.0
home_acceleration = 500.0
home_deceleration = 500.0
[axis.sim]
start = -10.0
switch = [0.0, 2.0]
marker_every = 5.0
marker_at = 3.3
"#
        ),
        |_| {},
    ) else {
        return;
    };
    let (v, stderr) = home(&b);
    reported(&stderr, 0, "A", "dc");
    reported(&stderr, 1, "B", "dc");
    let a = homed(&v, "A");
    // sampled switch at 2 u/s: ± one cycle of travel (0.002), see the top
    close(&a, "event_raw", 5.0, 0.002 + COUNT);
    let e = num(&a, "event_raw");
    ended_at(&b, 0, &a, e + 1.0, 10.0);
    let bb = homed(&v, "B");
    close(&bb, "event_raw", 3.3, COUNT);
    // sim: rest in [3.7, 3.74] (stopping distance 0.4 + up to two cycles
    // of travel until the engine sees the latch). Over EtherCAT the latch
    // reaches the engine up to three cycles later (the drive's inputs lag
    // its outputs by a bus cycle; bus and supervisor clocks' phase on the
    // way in and out), and two more for a lost frame: up to 3.84.
    let raw = num(&bb, "final_raw");
    assert!((3.7 - COUNT..=3.84 + COUNT).contains(&raw), "{bb}");
    close(&bb, "final_position", raw - 3.3, COUNT);
    drive_at(&b, 1, &bb);
}

#[test]
fn marker_family_on_cyclic_axes() {
    let _serial = serial();
    let Some(b) = bus(
        "ecat_marker",
        "",
        &format!(
            r#"
[[axis]]
name = "C"
{COMMON}
travel = "cyclic"
unwind = 360.0
marker = true
home_sequence = "marker"
home_direction = "bidirectional_forward"
home_position = 90.0
home_speed = 90.0
home_return_speed = 10.0
home_acceleration = 720.0
home_deceleration = 720.0
[axis.sim]
start = 0.0
marker_every = 360.0
marker_at = 100.0

[[axis]]
name = "D"
{COMMON}
travel = "cyclic"
unwind = 360.0
marker = true
home_sequence = "marker"
home_direction = "unidirectional_reverse"
home_position = 0.0
home_offset = -45.0
home_speed = 90.0
home_acceleration = 720.0
home_deceleration = 720.0
[axis.sim]
start = 0.0
marker_every = 360.0
marker_at = 100.0
"#
        ),
        |_| {},
    ) else {
        return;
    };
    let (v, _) = home(&b);
    let c = homed(&v, "C");
    close(&c, "event_raw", 100.0, COUNT);
    ended_at(&b, 0, &c, 100.0, 90.0);
    let d = homed(&v, "D");
    close(&d, "event_raw", -260.0, COUNT);
    let p = num(&d, "final_position");
    // cyclic 0: 0 or just below 360
    let p = if p > 180.0 { p - 360.0 } else { p };
    let mut d = d.clone();
    d["final_position"] = p.into();
    ended_at(&b, 1, &d, -305.0, 0.0);
}

#[test]
fn torque_family() {
    let _serial = serial();
    let Some(b) = bus(
        "ecat_torque",
        "",
        &format!(
            r#"
[[axis]]
name = "E"
{COMMON}
home_sequence = "torque"
home_direction = "bidirectional_forward"
home_offset = -3.0
home_speed = 10.0
home_return_speed = 2.0
home_acceleration = 200.0
home_deceleration = 200.0
home_torque_level = 40.0
home_torque_threshold = 25.0
home_torque_time = 0.02
position_error_tolerance = 0.5
[axis.sim]
start = 0.0
hard_stop = [-100.0, 50.0]

[[axis]]
name = "F"
{COMMON}
marker = true
home_sequence = "torque_then_marker"
home_direction = "bidirectional_reverse"
home_speed = 10.0
home_return_speed = 2.0
home_acceleration = 200.0
home_deceleration = 200.0
home_torque_level = 40.0
home_torque_threshold = 25.0
home_torque_time = 0.02
[axis.sim]
start = 0.0
hard_stop = [-20.0, 100.0]
marker_every = 4.0
marker_at = 1.0
"#
        ),
        |_| {},
    ) else {
        return;
    };
    let (v, _) = home(&b);
    let e = homed(&v, "E");
    close(&e, "event_raw", 50.0, COUNT);
    ended_at(&b, 0, &e, 47.0, 0.0);
    // the limits were restored on the drive (100 % → 0x60E0/0x60E1 = 1000 ‰)
    let d = b.drive(0).drive;
    assert_eq!(
        (d.torque_limit_positive, d.torque_limit_negative),
        (100.0, 100.0)
    );
    let f = homed(&v, "F");
    close(&f, "event_raw", -19.0, COUNT);
    ended_at(&b, 1, &f, -19.0, 0.0);
}

/// G is moved by "something else" from power-up: the emulator's plant moves
/// it whenever its drive is not enabled, in bus cycles (as the sim moves it
/// in command cycles), from 10 towards its switch at 3 (1.75 s).
#[test]
fn passive_and_immediate_family() {
    let _serial = serial();
    let Some(b) = bus(
        "ecat_passive",
        "",
        &format!(
            r#"
[[axis]]
name = "G"
{COMMON}
configuration = "feedback_only"
home_mode = "passive"
home_sequence = "switch"
home_position = 50.0
[axis.sim]
start = 10.0
switch = [2.0, 3.0]
external_speed = -4.0

[[axis]]
name = "H"
{COMMON}
home_sequence = "immediate"
home_position = 7.0
[axis.sim]
start = 12.5

[[axis]]
name = "V"
{COMMON}
configuration = "virtual"
home_sequence = "immediate"
home_position = 3.0
"#
        ),
        // H's drive has no distributed clocks: free run, reported as such
        |d| d[1].dc = false,
    ) else {
        return;
    };
    let (v, stderr) = home(&b);
    reported(&stderr, 0, "G", "dc");
    reported(&stderr, 1, "H", "free-run");
    assert!(
        stderr.contains("1 of 2 axes on distributed clocks (SYNC0), 1 free run"),
        "{stderr}"
    );
    let g = homed(&v, "G");
    // sampled switch at 4 u/s: ± one cycle of travel (0.004), see the top
    close(&g, "event_raw", 3.0, 0.004 + COUNT);
    let offset = 50.0 - num(&g, "event_raw");
    close(&g, "final_position", num(&g, "final_raw") + offset, COUNT);
    let h = homed(&v, "H");
    assert!(h["event_raw"].is_null());
    ended_at(&b, 1, &h, 12.5, 7.0);
    let vv = homed(&v, "V");
    close(&vv, "final_position", 3.0, 1e-9);
}

/// One slow switch axis, 20 units from its switch at 5 u/s (4 s of seek).
const SLOW: &str = r#"
[[axis]]
name = "S"
counts_per_unit = 1000.0
home_sequence = "switch"
home_direction = "bidirectional_forward"
home_speed = 5.0
home_return_speed = 1.0
home_acceleration = 100.0
home_deceleration = 100.0
home_timeout = 60.0
[axis.sim]
start = -20.0
switch = [0.0, 5.0]
"#;

fn status_of(d: &Daemon, name: &str) -> serde_json::Value {
    axis(&d.status(), name).clone()
}

/// Waits until axis `name` is in `phase` (status), or panics.
fn wait_phase(d: &Daemon, name: &str, phase: &str) {
    assert!(
        wait_for(Duration::from_secs(20), || status_of(d, name)["phase"]
            == phase),
        "{name} never reached {phase}: {}\n{}",
        status_of(d, name),
        d.stderr()
    );
}

/// Waits until axis `name` has ended its homing (`ip` false, `en` set).
fn wait_ended(d: &Daemon, name: &str) -> serde_json::Value {
    let mut last = serde_json::Value::Null;
    let ended = wait_for(Duration::from_secs(30), || {
        last = status_of(d, name);
        last["ip"] == false && (last["pc"] == true || last["er"] == true)
    });
    assert!(ended, "{name} did not end: {last}\n{}", d.stderr());
    last
}

#[test]
fn drive_fault_mid_homing_aborts_with_the_drive_error_code_kept() {
    let _serial = serial();
    let Some(b) = bus("ecat_fault", "", SLOW, |_| {}) else {
        return;
    };
    let d = Daemon::start(&b.cfg, &["bus0"]);
    let r = ctl(&b.cfg.prefix, &["home", "S", "--no-wait"]);
    assert_eq!(r.code, Some(0), "{}\n{}", r.stdout, r.stderr);
    wait_phase(&d, "S", "seek");
    std::thread::sleep(Duration::from_millis(300));
    // the drive faults on its own (0x603F = 0x2310, continuous over-current)
    b.emu.inject_fault(0, 0x2310);
    let s = wait_ended(&d, "S");
    assert_eq!(s["er"], true, "{s}");
    assert_eq!(
        (num(&s, "err"), num(&s, "exerr")),
        (12.0, 16.0),
        "drive fault: {s}"
    );
    assert_eq!(s["homed"], false, "{s}");
    assert_eq!(s["fault"], true, "{s}");
    assert_eq!(num(&s, "drive_error_code"), f64::from(0x2310), "{s}");
    let v = b.drive(0).drive;
    assert_eq!((v.state, v.error_code), (State::Fault, 0x2310), "{v:?}");
    assert!(!v.enabled);
    // kept while the drive reports the fault
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        num(&status_of(&d, "S"), "drive_error_code"),
        f64::from(0x2310)
    );

    // homing again: the enable handshake resets the fault, and it homes
    let r = ctl(&b.cfg.prefix, &["home", "S", "--json", "--timeout", "60"]);
    assert_eq!(
        r.code,
        Some(0),
        "{}\n{}\n{}",
        r.stdout,
        r.stderr,
        d.stderr()
    );
    let s = axis(&r.json(), "S").clone();
    // sampled switch at 1 u/s: ± one cycle of travel
    close(&s, "event_raw", 0.0, 0.001 + COUNT);
    let st = status_of(&d, "S");
    assert_eq!(
        (st["fault"].clone(), st["homed"].clone()),
        (false.into(), true.into())
    );
    assert_eq!(num(&st, "drive_error_code"), 0.0, "{st}");
    let run = d.stop();
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert_clean(&b.cfg.prefix);
}

/// R on the first drive, S and T behind it: pulling the cable in front of
/// S's drive takes S and T off the bus. S was homing: ERR 12 / EXERR 40;
/// T was homed: HomedStatus cleared; R homes on. Plugged in again, the bus
/// brings both drives back to OP and they home again.
#[test]
fn unplugged_subdevice_aborts_its_axes_and_homes_again_after_replug() {
    let _serial = serial();
    let Some(b) = bus(
        "ecat_unplug",
        "",
        &format!(
            r#"
# R: switch 20 units away at 10 u/s (about 3 s)
[[axis]]
name = "R"
{COMMON}
home_sequence = "switch"
home_direction = "bidirectional_forward"
home_speed = 10.0
home_return_speed = 2.0
home_acceleration = 200.0
home_deceleration = 200.0
[axis.sim]
start = -20.0
switch = [0.0, 5.0]

# S: cyclic, one marker per revolution at 100, 30 deg/s: 3.3 s to the
# first one
[[axis]]
name = "S"
{COMMON}
travel = "cyclic"
unwind = 360.0
marker = true
home_sequence = "marker"
home_direction = "bidirectional_forward"
home_position = 90.0
home_speed = 30.0
home_return_speed = 10.0
home_acceleration = 360.0
home_deceleration = 360.0
[axis.sim]
start = 0.0
marker_every = 360.0
marker_at = 100.0

[[axis]]
name = "T"
{COMMON}
home_sequence = "immediate"
home_position = 1.0
[axis.sim]
start = 4.0
"#
        ),
        |_| {},
    ) else {
        return;
    };
    let p = b.cfg.prefix.clone();
    let d = Daemon::start(&b.cfg, &["bus0"]);
    let r = ctl(&p, &["home", "T"]);
    assert_eq!(r.code, Some(0), "{}\n{}", r.stdout, r.stderr);
    assert_eq!(status_of(&d, "T")["homed"], true);

    // two requests: one home request's axes fail together
    for a in ["R", "S"] {
        let r = ctl(&p, &["home", a, "--no-wait"]);
        assert_eq!(r.code, Some(0), "{}\n{}", r.stdout, r.stderr);
    }
    wait_phase(&d, "S", "seek");
    std::thread::sleep(Duration::from_millis(500));
    let pulled = Instant::now();
    b.emu.unplug(1);
    let s = wait_ended(&d, "S");
    eprintln!("S ended {:?} after the cable was pulled", pulled.elapsed());
    assert_eq!(
        (num(&s, "err"), num(&s, "exerr")),
        (12.0, 40.0),
        "feedback lost: {s}"
    );
    assert_eq!(s["homed"], false, "{s}");
    let t = status_of(&d, "T");
    assert_eq!(
        t["homed"], false,
        "HomedStatus cleared by the feedback loss: {t}"
    );
    let r_ = wait_ended(&d, "R");
    assert_eq!(
        (r_["pc"].clone(), r_["homed"].clone()),
        (true.into(), true.into()),
        "{r_}"
    );
    // the unplugged drives stopped on their own (SM watchdog)
    assert!(wait_for(Duration::from_secs(5), || {
        let v = b.drive(1);
        v.al_code == 0x001B && v.drive.velocity == 0.0
    }));
    let stopped_at = b.drive(1).drive.position;
    let io = &d.status()["io"][0];
    assert_eq!(
        io["attached"], true,
        "motion-io itself stays attached: {io}"
    );

    // plugged in again: acknowledged, back to OP, feedback again
    b.emu.replug(1);
    assert!(
        wait_for(Duration::from_secs(10), || {
            b.drive(1).al_status == 0x08 && b.drive(2).al_status == 0x08
        }),
        "not back in OP: {:?}",
        b.drive(1)
    );
    assert!(wait_for(Duration::from_secs(5), || status_of(&d, "S")
        ["raw"]
        .is_number()));
    let r = ctl(&p, &["home", "S", "T", "--json", "--timeout", "60"]);
    assert_eq!(
        r.code,
        Some(0),
        "{}\n{}\n{}",
        r.stdout,
        r.stderr,
        d.stderr()
    );
    let v = r.json();
    let s = axis(&v, "S");
    // the first marker ahead of where the drive stopped, latched exactly
    let e = 100.0 + 360.0 * ((stopped_at - 100.0) / 360.0).ceil();
    close(s, "event_raw", e, COUNT);
    ended_at(&b, 1, s, e, 90.0);
    let t = axis(&v, "T");
    ended_at(&b, 2, t, num(t, "final_raw"), 1.0);
    let st = d.status();
    for a in ["R", "S", "T"] {
        assert_eq!(axis(&st, a)["homed"], true, "{a}: {}", axis(&st, a));
    }
    let run = d.stop();
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert_clean(&p);
}

#[test]
fn killed_motion_io_the_drives_watchdog_stops_the_axis() {
    let _serial = serial();
    let Some(b) = bus("ecat_killio", "", SLOW, |_| {}) else {
        return;
    };
    let w = Watched::new(spawn_supervisor(&["home", "--json", "--config", b.path()]));
    assert!(
        w.wait_line("home S: accepted", Duration::from_secs(20)),
        "homing never started"
    );
    // into the seek, moving at 5 u/s
    assert!(wait_for(Duration::from_secs(10), || b
        .drive(0)
        .drive
        .velocity
        > 4.0));
    let io = find_process("motion-io", &b.cfg.prefix).expect("motion-io");
    signal(io, Signal::SIGKILL);
    let killed = Instant::now();
    let mut stopped = None;
    while killed.elapsed() < Duration::from_secs(5) {
        let v = b.drive(0);
        if v.drive.state == State::Fault && v.drive.velocity == 0.0 {
            stopped = Some((killed.elapsed(), v));
            break;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let (after, v) = stopped.unwrap_or_else(|| panic!("drive not stopped: {:?}", b.drive(0)));
    eprintln!("drive stopped {after:?} after motion-io was killed: {v:?}");
    assert_eq!(v.al_status, 0x14, "SAFE-OP + error");
    assert_eq!(v.al_code, 0x001B, "SM watchdog");
    assert_eq!(v.drive.error_code, 0x8130, "communication lost");
    assert!(!v.drive.enabled);
    let at = v.drive.position;
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(b.drive(0).drive.position, at, "stands still");

    let run = w.finish();
    assert_eq!(run.code, Some(1), "{}\n{}", run.stdout, run.stderr);
    let v = run.json();
    let s = axis(&v, "S");
    assert_eq!(s["er"], true, "{s}");
    assert_eq!(
        (num(s, "err"), num(s, "exerr")),
        (12.0, 40.0),
        "feedback lost: {s}"
    );
    assert_eq!(s["homed"], false);
    assert!(run.stderr.contains("motion-io"), "{}", run.stderr);
    assert_clean(&b.cfg.prefix);
}

#[test]
fn a_drive_without_touch_probe_is_refused_with_the_object_named() {
    let _serial = serial();
    let Some(b) = bus("ecat_notp", "", SLOW, |d| d[0].touch_probe = false) else {
        return;
    };
    let run = supervisor(&["home", "--json", "--config", b.path()]);
    assert_eq!(run.code, Some(1), "{}\n{}", run.stdout, run.stderr);
    let want = "SubDevice 0 (EMU-S): object 0x60B8 touch probe function not supported \
                (SDO abort 0x06020000)";
    assert!(run.stderr.contains(want), "{}", run.stderr);
    let v = run.json();
    let e = v["errors"][0]["message"]
        .as_str()
        .unwrap_or_default()
        .to_string();
    assert!(
        e.contains("I/O process bus0") && e.contains("exit status: 1"),
        "{v}"
    );
    // motion-io alone says the same and exits 1
    let out = std::process::Command::new(bin("motion-io"))
        .args(["--config", b.path(), "--backend", "ethercat", "--interface"])
        .arg(&b.pair.master)
        .output()
        .expect("motion-io");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(want), "{err}");
    assert_clean(&b.cfg.prefix);
}
