//! The supervisor homing real(istic) drives end to end:
//! `motion-supervisor` → `motion-io --backend ethercat` (spawned by the
//! supervisor, ethercrab on its bus thread) → a veth pair → `ecat-emu`'s
//! CiA 402 drives, each over the same `motion_plant::Plant` the `sim`
//! backend uses, configured from the axis' own `[axis.sim]` table.
//!
//! The machines and the expected values are those of `e2e_sequences.rs`
//! (`tests/machines/`, where the arithmetic is); each axis with hardware
//! gets `ethercat_position` = its drive.
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

use ecat_emu::{al, Dropped, State};
use motion_harness::ecat::Bus;
use motion_harness::{assert_close, *};
use motion_report::{AxisResult, AxisStatus, CtlHomeReport, HomeReport, StatsReport};
use nix::sys::signal::Signal;

/// `home --json` on the bus: exit 0, latency measured, nothing left behind.
/// Returns the report and motion-io's / the supervisor's stderr.
fn home(b: &Bus) -> (HomeReport, String) {
    let t0 = Instant::now();
    let (v, stderr) = home_unbroken(b);
    assert!(v.run.latency.cycles > 500, "{:#?}", v.run.latency);
    eprintln!(
        "home over EtherCAT took {:.1} s; I/O round trip {:?}; stderr:\n{}",
        t0.elapsed().as_secs_f64(),
        v.run.latency.io_roundtrip_us,
        stderr
    );
    (v, stderr)
}

/// `home --json` on the bus, exit 0, nothing left behind. A homing the
/// host broke — the emulator or the bus thread descheduled for longer than
/// the feedback timeout, so an axis ended with its feedback or its drive
/// lost (ERR 12 / EXERR 40, 45; 46 homing by the drive) and motion-io
/// counted the loss — is made again, at most twice more: the subject is
/// the homing, not a starved host. Any other failure, or a third broken
/// homing, fails the test.
fn home_unbroken(b: &Bus) -> (HomeReport, String) {
    let mut attempt = 0;
    loop {
        attempt += 1;
        let run = supervisor(&["home", "--json", "--config", b.cfg.arg()]);
        assert_clean(&b.cfg.prefix);
        if run.code() == Some(1) && attempt < 3 && broken_by_the_host(&run) {
            eprintln!(
                "attempt {attempt}: the host broke the homing (a loss), again:\n{}",
                run.stderr
            );
            continue;
        }
        let v: HomeReport = run.expect_code(0).report();
        return (v, run.stderr.clone());
    }
}

/// An axis ended with its feedback or its drive lost (a drive homing
/// itself: also with its homing mode left, 46 — a lost drive comes back in
/// its own mode), and motion-io counted lost frames or a lost drive in
/// that run.
fn broken_by_the_host(run: &Ended) -> bool {
    let Ok(v) = serde_json::from_str::<HomeReport>(run.stdout.trim()) else {
        return false;
    };
    let lost_axis = v
        .axes
        .iter()
        .any(|a| a.er && a.err == 12 && matches!(a.exerr, 40 | 45 | 46));
    let counted = !run.stderr.contains(" 0 drive loss(es)") || bus_summary(&run.stderr).0 > 0;
    lost_axis && counted
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
#[track_caller]
fn ended_at(b: &Bus, drive: usize, a: &AxisResult, want: f64, want_position: f64) {
    let d = b.drive(drive).drive;
    assert!(
        (d.position - want).abs() <= COUNT,
        "{}: the drive rests at {}, want {want}",
        a.name,
        d.position
    );
    assert_eq!(d.velocity, 0.0, "{d:?}");
    assert_close!(a, final_raw, want, IN_FLIGHT);
    assert_close!(a, final_position, want_position, IN_FLIGHT);
}

/// The drive's plant ended where the supervisor says the axis is (raw), and
/// stands still (motion-io stopped every axis on its way out). `final_raw`
/// is the last feedback the engine used: at the end of a deceleration the
/// last set-points may still have been on their way (a few counts).
#[track_caller]
fn drive_at(b: &Bus, position: usize, a: &AxisResult) {
    let d = b.drive(position).drive;
    let raw = value(a.final_raw, a);
    assert!(
        (d.position - raw).abs() <= IN_FLIGHT,
        "{}: plant at {}, final_raw {raw}",
        a.name,
        d.position
    );
    assert_eq!(d.velocity, 0.0, "{d:?}");
}

/// The start-up report (shown even though the supervisor runs motion-io
/// with --quiet) names every SubDevice with its axis and sync mode.
#[track_caller]
fn reported(stderr: &str, position: usize, axis: &str, sync: &str) {
    let want = format!("SubDevice {position} \"EMU-{axis}\": axis {axis}, {sync}");
    assert!(stderr.contains(&want), "no {want:?} in\n{stderr}");
}

/// The fixture `machine` on a bus, its drives as built from the machine.
fn family(machine: &str) -> Option<Bus> {
    Bus::start(
        &format!("ecat_{machine}"),
        &Machine::fixture(machine),
        |_| {},
    )
}

/// Cycles by which this run's host delayed what the drives reported, as
/// the run counted them: motion-io's lost frames and its worst bus round
/// trip beyond one cycle, the supervisor's deadline misses.
/// (The machines' cycle: 1 ms.)
fn host_delay_cycles(v: &HomeReport, stderr: &str) -> u64 {
    const CYCLE_US: f64 = 1000.0;
    let (lost, max_us) = bus_summary(stderr);
    let round_trip = (max_us / CYCLE_US).ceil().max(1.0) as u64 - 1;
    lost + round_trip + v.run.latency.deadline_misses
}

/// motion-io's lost frames and worst bus round trip (us), from the summary
/// it logs at exit (`…, N lost frame(s), … / max X us`); 0 where absent.
fn bus_summary(stderr: &str) -> (u64, f64) {
    let Some(line) = stderr.lines().rev().find(|l| l.contains("lost frame(s)")) else {
        return (0, 0.0);
    };
    let lost = (line.split(", "))
        .find(|p| p.ends_with("lost frame(s)"))
        .and_then(|p| p.split_whitespace().next()?.parse().ok())
        .unwrap_or(0);
    let max_us = (line.rsplit("/ max ").next())
        .and_then(|t| t.split_whitespace().next()?.parse().ok())
        .unwrap_or(0.0);
    (lost, max_us)
}

#[test]
fn switch_family() {
    let _serial = serial();
    let Some(b) = family("switch") else {
        return;
    };
    let (v, stderr) = home(&b);
    reported(&stderr, 0, "A", "dc");
    reported(&stderr, 1, "B", "dc");
    let a = homed(&v, "A");
    // sampled switch at 2 u/s: ± one cycle of travel (0.002), see the top
    assert_close!(a, event_raw, 5.0, 0.002 + COUNT);
    let e = value(a.event_raw, a);
    ended_at(&b, 0, a, e + 1.0, 10.0);
    let bb = homed(&v, "B");
    assert_close!(bb, event_raw, 3.3, COUNT);
    // sim: rest in [3.7, 3.74] (stopping distance 0.4 + up to two cycles
    // of travel until the engine sees the latch). Over EtherCAT the latch
    // reaches the engine up to three cycles later (the drive's inputs lag
    // its outputs by a bus cycle; bus and supervisor clocks' phase on the
    // way in and out), and two more for a lost frame: up to 3.84.
    // A loaded host delays the latch further, by what the run counted:
    // each frame lost, each bus round trip beyond a cycle, each cycle the
    // supervisor woke late is a cycle more of travel (0.02) before the
    // engine can see it — never less than the stopping distance.
    let raw = value(bb.final_raw, bb);
    let late = host_delay_cycles(&v, &stderr);
    let most = 3.84 + 0.02 * late as f64;
    assert!(
        (3.7 - COUNT..=most + COUNT).contains(&raw),
        "rest {raw} beyond [3.7, {most}] ({late} cycles of host delay counted)\n{bb:#?}"
    );
    assert_close!(bb, final_position, raw - 3.3, COUNT);
    drive_at(&b, 1, bb);
}

#[test]
fn marker_family_on_cyclic_axes() {
    let _serial = serial();
    let Some(b) = family("marker") else {
        return;
    };
    let (v, _) = home(&b);
    let c = homed(&v, "C");
    assert_close!(c, event_raw, 100.0, COUNT);
    ended_at(&b, 0, c, 100.0, 90.0);
    let d = homed(&v, "D");
    assert_close!(d, event_raw, -260.0, COUNT);
    // cyclic 0: 0 or just below 360
    let p = value(d.final_position, d);
    let p = if p > 180.0 { p - 360.0 } else { p };
    let d = AxisResult {
        final_position: Some(p),
        ..d.clone()
    };
    ended_at(&b, 1, &d, -305.0, 0.0);
}

#[test]
fn torque_family() {
    let _serial = serial();
    let Some(b) = family("torque") else {
        return;
    };
    let (v, _) = home(&b);
    let e = homed(&v, "E");
    assert_close!(e, event_raw, 50.0, COUNT);
    ended_at(&b, 0, e, 47.0, 0.0);
    // the limits were restored on the drive (100 % → 0x60E0/0x60E1 = 1000 ‰)
    let d = b.drive(0).drive;
    assert_eq!(
        (d.torque_limit_positive, d.torque_limit_negative),
        (100.0, 100.0)
    );
    let f = homed(&v, "F");
    assert_close!(f, event_raw, -19.0, COUNT);
    ended_at(&b, 1, f, -19.0, 0.0);
}

/// G is moved by "something else" from power-up: the emulator's plant moves
/// it whenever its drive is not enabled, in bus cycles (as the sim moves it
/// in command cycles), from 10 towards its switch at 3 (1.75 s).
#[test]
fn passive_and_immediate_family() {
    let _serial = serial();
    // H's drive has no distributed clocks: free run, reported as such
    let Some(b) = Bus::start("ecat_passive", &Machine::fixture("passive"), |d| {
        d[1].dc = false
    }) else {
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
    assert_close!(g, event_raw, 3.0, 0.004 + COUNT);
    let offset = 50.0 - value(g.event_raw, g);
    assert_close!(g, final_position, value(g.final_raw, g) + offset, COUNT);
    let h = homed(&v, "H");
    assert!(h.event_raw.is_none(), "{h:#?}");
    ended_at(&b, 1, h, 12.5, 7.0);
    let vv = homed(&v, "V");
    assert_close!(vv, final_position, 3.0, 1e-9);
}

/// One slow switch axis, 20 units from its switch at 5 u/s (4 s of seek),
/// on a bus whose drives `tweak` may change.
fn slow(tag: &str, tweak: impl FnOnce(&mut [ecat_emu::DriveConfig])) -> Option<Bus> {
    let machine = Machine::fixture("slow_switch").set("axis.S.sim.start", -20.0);
    Bus::start(tag, &machine, tweak)
}

/// `slow(tag, tweak)` homed by `motion-supervisor home`, once its drive
/// seeks at 5 u/s: the bus and the running supervisor.
fn seeking(tag: &str, tweak: impl FnOnce(&mut [ecat_emu::DriveConfig])) -> Option<(Bus, Running)> {
    let b = slow(tag, tweak)?;
    let w = spawn_supervisor(&["home", "--json", "--config", b.cfg.arg()]);
    assert!(
        wait_for(Duration::from_secs(30), || b.drive(0).drive.velocity > 4.0),
        "homing never started: {:?}\n{}",
        b.drive(0),
        w.stderr()
    );
    Some((b, w))
}

/// How long from now until `done` holds (polled every millisecond), at
/// most 5 s.
fn time_until(mut done: impl FnMut() -> bool) -> Option<Duration> {
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(5) {
        if done() {
            return Some(t0.elapsed());
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    None
}

/// `sig` to the bus's `motion-io`.
fn signal_io(b: &Bus, sig: Signal) {
    let io = find_process("motion-io", &b.cfg.prefix).expect("motion-io");
    signal_pid(io, sig);
}

/// `motion-io` of `prefix` is gone within 10 s.
#[track_caller]
fn io_gone(prefix: &str) {
    assert!(
        wait_for(Duration::from_secs(10), || find_process(
            "motion-io",
            prefix
        )
        .is_none()),
        "motion-io still runs"
    );
}

/// Waits until axis `name` is in `phase` (status), or panics.
#[track_caller]
fn wait_phase(d: &Daemon, name: &str, phase: &str) {
    assert!(
        wait_for(Duration::from_secs(20), || d.axis(name).phase == phase),
        "{name} never reached {phase}: {:#?}\n{}",
        d.axis(name),
        d.stderr()
    );
}

/// Waits until axis `name` has ended its homing (`ip` false, `pc` or `er`).
#[track_caller]
fn wait_ended(d: &Daemon, name: &str) -> AxisStatus {
    let mut last = AxisStatus::default();
    let ended = wait_for(Duration::from_secs(30), || {
        last = d.axis(name);
        !last.ip && (last.pc || last.er)
    });
    assert!(ended, "{name} did not end: {last:#?}\n{}", d.stderr());
    last
}

/// `motionctl home AXES… --json --timeout 60` on the daemon: every one homes.
#[track_caller]
fn home_again(d: &Daemon, axes: &[&str]) -> CtlHomeReport {
    let mut args = vec!["home"];
    args.extend_from_slice(axes);
    args.extend_from_slice(&["--json", "--timeout", "60"]);
    let r = d.ctl(&args);
    assert_eq!(
        r.code(),
        Some(0),
        "{}\n{}\n{}",
        r.stdout,
        r.stderr,
        d.stderr()
    );
    r.report()
}

/// `motionctl reset AXIS`, the axis fault seen cleared within 5 s, then
/// [`home_again`]: an axis fault needs a reset before the next homing.
#[track_caller]
fn reset_and_home_again(d: &Daemon, axis: &str) -> CtlHomeReport {
    d.ctl(&["reset", axis]).expect_code(0);
    // A drive back from a loss may still latch the loss's fault after a
    // reset taken in the same moment (a loaded host stretches it): the
    // state is awaited, resetting again while the axis still shows a fault.
    let cleared = wait_for(Duration::from_secs(15), || {
        wait_for(Duration::from_secs(1), || !d.axis(axis).faulted) || {
            d.ctl(&["reset", axis]);
            false
        }
    });
    assert!(cleared, "{:#?}\n{}", d.axis(axis), d.stderr());
    home_again(d, &[axis])
}

#[test]
fn drive_fault_mid_homing_aborts_with_the_drive_error_code_kept() {
    let _serial = serial();
    let Some(b) = slow("ecat_fault", |_| {}) else {
        return;
    };
    let d = Daemon::start(&b.cfg, &["bus0"]);
    d.ctl(&["home", "S", "--no-wait"]).expect_code(0);
    wait_phase(&d, "S", "seek");
    std::thread::sleep(Duration::from_millis(300));
    // the drive faults on its own (0x603F = 0x2310, continuous over-current)
    b.rig.emulator().inject_fault(0, 0x2310);
    let s = wait_ended(&d, "S");
    assert!(s.er, "{s:#?}");
    assert_eq!((s.err, s.exerr), (12, 16), "drive fault: {s:#?}");
    assert!(!s.homed, "{s:#?}");
    assert!(s.fault, "{s:#?}");
    assert_eq!(s.drive_error_code, 0x2310, "{s:#?}");
    let v = b.drive(0).drive;
    assert_eq!((v.state, v.error_code), (State::Fault, 0x2310), "{v:?}");
    assert!(!v.enabled);
    // kept while the drive reports the fault
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(d.axis("S").drive_error_code, 0x2310);

    // a drive fault needs a reset before the next homing (as
    // Logix: MAH on a faulted axis is ERR 20): refused, then reset (MAFR:
    // CiA 402 control word bit 7), then it homes
    let r = d.ctl(&["home", "S", "--no-wait", "--json"]);
    r.expect_code(1);
    assert!(r.stdout.contains("\"err\":20"), "{}", r.stdout);
    let r = reset_and_home_again(&d, "S");
    // sampled switch at 1 u/s: ± one cycle of travel
    assert_close!(named(&r.axes, "S"), event_raw, 0.0, 0.001 + COUNT);
    let st = d.axis("S");
    assert!(!st.fault && st.homed, "{st:#?}");
    assert_eq!(st.drive_error_code, 0, "{st:#?}");
    d.stop().expect_code(0);
    assert_clean(&b.cfg.prefix);
}

/// R on the first drive, S and T behind it (`tests/machines/unplug.toml`):
/// pulling the cable in front of S's drive takes S and T off the bus. S was
/// homing: ERR 12 / EXERR 40; T was homed: HomedStatus cleared; R homes on.
/// Plugged in again, the bus brings both drives back to OP and they home
/// again.
#[test]
fn unplugged_subdevice_aborts_its_axes_and_homes_again_after_replug() {
    let _serial = serial();
    let Some(b) = family("unplug") else {
        return;
    };
    let d = Daemon::start(&b.cfg, &["bus0"]);
    d.ctl(&["home", "T"]).expect_code(0);
    assert!(d.axis("T").homed);

    // two requests: one home request's axes fail together
    for a in ["R", "S"] {
        d.ctl(&["home", a, "--no-wait"]).expect_code(0);
    }
    wait_phase(&d, "S", "seek");
    std::thread::sleep(Duration::from_millis(500));
    let pulled = Instant::now();
    let emu = b.rig.emulator();
    emu.unplug(1);
    let s = wait_ended(&d, "S");
    eprintln!("S ended {:?} after the cable was pulled", pulled.elapsed());
    assert_eq!((s.err, s.exerr), (12, 45), "its drive lost: {s:#?}");
    assert!(!s.homed, "{s:#?}");
    // the status says the drive is lost, not enabled; motion-io says which
    assert!(s.drive_lost && !s.enabled, "{s:#?}");
    assert!(
        s.error
            .as_deref()
            .is_some_and(|e| e.starts_with("drive lost")),
        "{s:#?}"
    );
    let t = d.axis("T");
    assert!(!t.homed, "HomedStatus cleared by the feedback loss: {t:#?}");
    let r = wait_ended(&d, "R");
    assert!(r.pc && r.homed, "{r:#?}");
    // the unplugged drives stopped on their own (SM watchdog)
    assert!(wait_for(Duration::from_secs(5), || {
        let v = b.drive(1);
        v.al_code == 0x001B && v.drive.velocity == 0.0
    }));
    let stopped_at = b.drive(1).drive.position;
    let io = d.status().io[0].clone();
    assert!(io.attached, "motion-io itself stays attached: {io:#?}");

    // plugged in again: acknowledged, back to OP, feedback again
    emu.replug(1);
    assert!(
        wait_for(Duration::from_secs(10), || {
            b.drive(1).al_status == 0x08 && b.drive(2).al_status == 0x08
        }),
        "not back in OP: {:?}",
        b.drive(1)
    );
    assert!(wait_for(Duration::from_secs(5), || {
        let s = d.axis("S");
        s.raw.is_some() && !s.drive_lost
    }));
    // the axis faults (feedback lost in motion, the drives' own faults after
    // their watchdog) need a reset before the next homing (ERR 20)
    d.ctl(&["reset", "S", "T"]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || {
        !d.axis("S").faulted && !d.axis("T").faulted
    }));
    let v = home_again(&d, &["S", "T"]);
    let s = named(&v.axes, "S");
    // the first marker ahead of where the drive stopped, latched exactly
    let e = 100.0 + 360.0 * ((stopped_at - 100.0) / 360.0).ceil();
    assert_close!(s, event_raw, e, COUNT);
    ended_at(&b, 1, s, e, 90.0);
    let t = named(&v.axes, "T");
    ended_at(&b, 2, t, value(t.final_raw, t), 1.0);
    let st = d.status();
    for a in ["R", "S", "T"] {
        assert!(named(&st.axes, a).homed, "{a}: {:#?}", named(&st.axes, a));
    }
    // what motion-io said about it (both states lasted: logged)
    let end = d.stop().expect_code(0).stderr.clone();
    for line in [
        "EtherCAT: SubDevice 1 \"EMU-S\" (axis S) lost: it does not answer",
        "(axis S) back in OP",
    ] {
        assert!(end.contains(line), "no {line:?} in\n{end}");
    }
    assert_clean(&b.cfg.prefix);
}

#[test]
fn killed_motion_io_the_drives_watchdog_stops_the_axis() {
    let _serial = serial();
    let Some((b, w)) = seeking("ecat_killio", |_| {}) else {
        return;
    };
    signal_io(&b, Signal::SIGKILL);
    let after = time_until(|| {
        let v = b.drive(0).drive;
        v.state == State::Fault && v.velocity == 0.0
    })
    .unwrap_or_else(|| panic!("drive not stopped: {:?}", b.drive(0)));
    let v = b.drive(0);
    eprintln!("drive stopped {after:?} after motion-io was killed: {v:?}");
    assert_eq!(v.al_status, 0x14, "SAFE-OP + error");
    assert_eq!(v.al_code, 0x001B, "SM watchdog");
    assert_eq!(v.drive.error_code, 0x8130, "communication lost");
    assert!(!v.drive.enabled);
    let at = v.drive.position;
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(b.drive(0).drive.position, at, "stands still");

    let run = w.finish();
    let v: HomeReport = run.expect_code(1).report();
    let s = named(&v.axes, "S");
    assert!(s.er, "{s:#?}");
    assert_eq!((s.err, s.exerr), (12, 40), "feedback lost: {s:#?}");
    assert!(!s.homed);
    assert!(run.stderr.contains("motion-io"), "{}", run.stderr);
    assert_clean(&b.cfg.prefix);
}

/// From the moment the supervisor is killed (motion-io alive, its watchdog
/// the only one left) until the drive reports Switch on disabled (power
/// stage off): the interface promises 1 s by default.
fn killed_supervisor_stop_time(
    tag: &str,
    tweak: impl FnOnce(&mut [ecat_emu::DriveConfig]),
) -> Option<Duration> {
    let (b, w) = seeking(tag, tweak)?;
    signal_pid(w.pid() as i32, Signal::SIGKILL);
    let off = time_until(|| {
        let v = b.drive(0).drive;
        v.state == State::SwitchOnDisabled && !v.enabled
    })
    .unwrap_or_else(|| panic!("still powered: {:?}", b.drive(0)));
    let io = find_process("motion-io", &b.cfg.prefix);
    // motion-io outlives its supervisor by the stop and a second, then
    // leaves (it was spawned with --exit-with-supervisor)
    io_gone(&b.cfg.prefix);
    let run = w.finish();
    eprintln!("motion-io ({io:?}):\n{}", run.stderr);
    assert_clean(&b.cfg.prefix);
    Some(off)
}

#[test]
fn killed_supervisor_every_drive_ends_switched_off_within_the_bound() {
    let _serial = serial();
    let Some(honours) = killed_supervisor_stop_time("ecat_killsup", |_| {}) else {
        return;
    };
    let Some(ignores) =
        killed_supervisor_stop_time("ecat_killsup_noqs", |d| d[0].ignores_quick_stop = true)
    else {
        return;
    };
    eprintln!(
        "supervisor killed → drive in Switch on disabled: {:.1} ms (quick stop honoured), \
         {:.1} ms (quick stop ignored); io_watchdog 50 cycles of 1 ms, quick stop bound 500 ms",
        honours.as_secs_f64() * 1e3,
        ignores.as_secs_f64() * 1e3
    );
    assert!(honours < Duration::from_secs(1), "{honours:?}");
    assert!(ignores < Duration::from_secs(1), "{ignores:?}");
}

/// The drive is off: its power stage (its own state says so).
fn off(b: &Bus, position: usize) -> bool {
    let v = b.drive(position).drive;
    !v.enabled
        && matches!(
            v.state,
            State::SwitchOnDisabled | State::ReadyToSwitchOn | State::Fault
        )
}

/// R, S and T homing (`tests/machines/unplug.toml`); S's drive falls to
/// SAFE-OP with an AL error (a sync error) and stays there, answering its
/// AL status but not its process data. S's homing ends with its drive lost
/// (12/45); R homes on to the end on valid data; a disable reaches R's
/// drive; S's drive stopped by its own reaction and, back in OP, is not
/// enabled by itself and has not moved.
#[test]
fn a_drive_short_on_process_data_leaves_the_others_served() {
    let _serial = serial();
    let Some(b) = family("unplug") else {
        return;
    };
    let d = Daemon::start(&b.cfg, &["bus0"]);
    for a in ["R", "S"] {
        d.ctl(&["home", a, "--no-wait"]).expect_code(0);
    }
    wait_phase(&d, "S", "seek");
    let emu = b.rig.emulator();
    emu.refuse_op(1, Some(al::SYNC_ERROR));
    emu.drop_out_of_op(1, Dropped::SafeOp(al::SYNC_ERROR));
    let s = wait_ended(&d, "S");
    assert_eq!((s.err, s.exerr), (12, 45), "its drive lost: {s:#?}");
    assert!(s.drive_lost && !s.enabled, "{s:#?}");
    // R's data stayed valid: its homing went on to the end
    let r = wait_ended(&d, "R");
    assert!(r.pc && r.homed, "{r:#?}\n{}", d.stderr());
    assert!(!d.axis("T").drive_lost, "T behind S still answers");
    // S's drive: its own quick stop on the lost outputs, where it was
    assert!(
        wait_for(Duration::from_secs(5), || {
            let v = b.drive(1).drive;
            v.state == State::SwitchOnDisabled && v.velocity == 0.0
        }),
        "{:?}",
        b.drive(1)
    );
    let at = b.drive(1).drive.position;
    // a disable reaches R's drive while S's is short
    d.ctl(&["enable", "R"]).expect_code(0);
    assert!(
        wait_for(Duration::from_secs(5), || b.drive(0).drive.enabled),
        "{:?}",
        b.drive(0)
    );
    d.ctl(&["disable", "R"]).expect_code(0);
    assert!(
        wait_for(Duration::from_secs(2), || off(&b, 0)),
        "R's drive still powered: {:?}",
        b.drive(0)
    );
    // S's drive accepts OP again: back, data valid, not enabled, not moved
    emu.refuse_op(1, None);
    assert!(
        wait_for(Duration::from_secs(5), || {
            let s = d.axis("S");
            b.drive(1).al_status == 0x08 && s.raw.is_some() && !s.drive_lost
        }),
        "{:?} {:#?}",
        b.drive(1),
        d.axis("S")
    );
    std::thread::sleep(Duration::from_millis(300));
    let v = b.drive(1).drive;
    // power stage off: Switch on disabled (the backend's bounded stop), or
    // Ready to switch on where the engine had withdrawn the enable request
    // first (the loss is a fault of the axis) and the backend holds it as
    // every disabled drive
    assert!(
        matches!(v.state, State::SwitchOnDisabled | State::ReadyToSwitchOn),
        "{v:?}"
    );
    assert_eq!(v.position, at, "moved: {v:?}");
    assert!(!d.axis("S").enabled);
    // after a reset it homes again
    let v = reset_and_home_again(&d, "S");
    assert!(named(&v.axes, "S").pc);
    d.stop().expect_code(0);
    assert_clean(&b.cfg.prefix);
}

/// R seeking (`tests/machines/unplug.toml`); the supervisor is killed and
/// S's drive falls to SAFE-OP (AL error, OP refused) at the same moment: motion-io's watchdog stop must still reach R's and T's drives,
/// which end in Switch on disabled within the stop's bound (50 ms of
/// watchdog + 500 ms of quick stop at most), S's by its own reaction.
#[test]
fn a_drive_short_on_process_data_killed_supervisor_the_others_switch_off_within_the_bound() {
    let _serial = serial();
    let Some(b) = family("unplug") else {
        return;
    };
    // (home order: R first, S and T after it)
    let w = spawn_supervisor(&["home", "--json", "--config", b.cfg.arg()]);
    assert!(
        wait_for(Duration::from_secs(30), || b.drive(0).drive.velocity > 5.0),
        "R never seeking: {:?}\n{}",
        b.drive(0),
        w.stderr()
    );
    let emu = b.rig.emulator();
    signal_pid(w.pid() as i32, Signal::SIGKILL);
    emu.refuse_op(1, Some(al::SYNC_ERROR));
    emu.drop_out_of_op(1, Dropped::SafeOp(al::SYNC_ERROR));
    let took = time_until(|| off(&b, 0) && off(&b, 2)).unwrap_or_else(|| {
        panic!(
            "still powered: {:?} {:?}\n{}",
            b.drive(0),
            b.drive(2),
            w.stderr()
        )
    });
    eprintln!(
        "drive short on process data, supervisor killed → the other drives in Switch on \
         disabled after {:.1} ms",
        took.as_secs_f64() * 1e3
    );
    assert!(took < Duration::from_secs(1), "{took:?}");
    assert!(
        wait_for(Duration::from_secs(5), || {
            let v = b.drive(1).drive;
            v.state == State::SwitchOnDisabled && v.velocity == 0.0
        }),
        "{:?}",
        b.drive(1)
    );
    // motion-io's stop completes (a lost drive does not hold it up) and it
    // leaves a second later
    io_gone(&b.cfg.prefix);
    let run = w.finish();
    eprintln!("{}", run.stderr);
    assert_clean(&b.cfg.prefix);
}

/// motion-io's main loop blocks for good in the middle of a seek (its test
/// hook, SIGUSR1: as a write to a stderr nobody reads once blocked it): no
/// command reaches the bus thread any more, whose own watchdog stops the
/// drive — 2 × `io_watchdog_cycles` (100 ms) without a command, then the
/// bounded stop — into Switch on disabled.
#[test]
fn a_stalled_motion_io_the_bus_thread_switches_the_drive_off_by_itself() {
    let _serial = serial();
    let Some((b, w)) = seeking("ecat_stall", |_| {}) else {
        return;
    };
    signal_io(&b, Signal::SIGUSR1);
    let took =
        time_until(|| off(&b, 0)).unwrap_or_else(|| panic!("still powered: {:?}", b.drive(0)));
    eprintln!(
        "motion-io's main loop stalled → the drive in Switch on disabled after {:.1} ms \
         (bus thread's own watchdog: 100 ms; quick stop bound 500 ms)",
        took.as_secs_f64() * 1e3
    );
    assert!(took < Duration::from_secs(1), "{took:?}");
    assert_eq!(b.drive(0).drive.velocity, 0.0);
    // the supervisor's homing fails (no feedback); it ends its motion-io,
    // which does not answer SIGTERM any more: SIGKILL after the grace
    let run = w.finish();
    eprintln!("{}", run.stderr);
    if let Some(pid) = find_process("motion-io", &b.cfg.prefix) {
        signal_pid(pid, Signal::SIGKILL);
    }
    io_gone(&b.cfg.prefix);
    assert_clean(&b.cfg.prefix);
}

/// What one end-to-end jog showed (see [`jog_regularity`]).
#[derive(Debug)]
struct Jog {
    /// Frames at constant speed; those that did not advance by 5 counts,
    /// and of those the ones away from an event of the bus (a frame that
    /// passed more than half a cycle off its period within three cycles).
    frames: usize,
    irregular: usize,
    unexcused: usize,
    /// From motion-io's bus summary: frames moved off the supervisor's
    /// sequence (its whole run). From the daemon's statistics: its cycle's
    /// deadline misses since start.
    corrections: u64,
    deadline_misses: u64,
}

/// The number before `what` in the bus summary `line` (`… 3 frame(s) moved
/// off …`).
fn counted(line: &str, what: &str) -> u64 {
    let before = line.split(what).next().unwrap_or_default();
    let n = before.rsplit([' ', ',']).find(|w| !w.is_empty());
    n.and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no {what:?} in {line}"))
}

/// X of `tests/machines/ops.toml` jogged at 5 units/s — 5 counts per 1 ms
/// cycle — for 3 s through the daemon, motion-io and the bus, on drives
/// whose distributed clocks run `ppm` off the host's (the bus thread
/// follows the first one's); X's drive records every frame's target.
fn jog_regularity(tag: &str, ppm: f64) -> Option<Jog> {
    let b = Bus::start(tag, &Machine::fixture("ops"), |drives| {
        for d in drives {
            d.clock_ppm = ppm;
        }
    })?;
    let d = Daemon::start(&b.cfg, &["bus0"]);
    d.ctl(&["enable", "X"]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || d.axis("X").enabled));
    let emu = b.rig.emulator();
    emu.record_targets(0, true);
    d.ctl(&["jog", "X", "--speed", "5", "--for", "3"])
        .expect_code(0);
    let t = emu.take_timed_targets(0);
    // the daemon's statistics are handed over every second
    std::thread::sleep(Duration::from_millis(1200));
    let stats: StatsReport = d.ctl(&["stats", "--json"]).expect_code(0).report();
    let end = d.stop().expect_code(0).stderr.clone();
    assert_clean(&b.cfg.prefix);
    let summary = end
        .lines()
        .find(|l| l.contains(" bus cycles, "))
        .unwrap_or_else(|| panic!("no bus summary in\n{end}"));
    // at constant speed: between the first and the last step of 5, the
    // ramps' ends left out
    let steps: Vec<i32> = t.windows(2).map(|w| w[1].0 - w[0].0).collect();
    let first = steps.iter().position(|s| *s == 5)? + 20;
    let last = steps.iter().rposition(|s| *s == 5)?.saturating_sub(20);
    let cycle = Duration::from_millis(1);
    let off = |j: usize| {
        let dt = t[j + 1].1 - t[j].1;
        dt > cycle * 3 / 2 || dt < cycle / 2
    };
    let mut hist = std::collections::BTreeMap::new();
    let mut jog = Jog {
        frames: last - first,
        irregular: 0,
        unexcused: 0,
        corrections: counted(summary, " frame(s) moved off"),
        deadline_misses: stats.latency.deadline_misses,
    };
    for j in first..last {
        *hist.entry(steps[j]).or_insert(0u32) += 1;
        if steps[j] != 5 {
            jog.irregular += 1;
            let near = (j.saturating_sub(3)..=(j + 3).min(steps.len() - 1)).any(off);
            jog.unexcused += usize::from(!near);
        }
    }
    eprintln!(
        "clock {ppm:+} ppm, jog at 5 counts per cycle end to end: {} frames at constant speed, \
         {} not advancing by 5 counts ({:.3} %), {} of them away from the bus's events: \
         {hist:?}; {jog:?}",
        jog.frames,
        jog.irregular,
        jog.irregular as f64 * 100.0 / jog.frames as f64,
        jog.unexcused
    );
    eprintln!("{summary}");
    Some(jog)
}

/// Set-point regularity end to end on drives whose clock runs 100 and
/// 1,000 ppm off. Each frame carries the command that follows the previous
/// frame's in the supervisor's sequence (`motion_ethercat::handoff`); a
/// frame steps by other than v·T only next to an event of the bus (an
/// overrun, a lost or late frame), where the supervisor's cycle missed its
/// deadline (its command steps two cycles), or where the hand-off
/// corrected its sequence (the clocks a cycle apart, or a stall). Taking
/// the newest command for each frame made 2–4 % of the frames at 1,000 ppm
/// step by 0 or two cycles, host or not, and no correction was counted.
#[test]
fn set_points_advance_regularly_end_to_end_over_a_drifting_clock() {
    let _serial = serial();
    for (tag, ppm) in [("ecat_reg100", 100.0), ("ecat_reg1000", 1000.0)] {
        let Some(j) = jog_regularity(tag, ppm) else {
            return;
        };
        assert!(j.frames > 2500, "{j:?}");
        // (the corrections are motion-io's whole run's: how many fell in
        // the jog, and how late motion-io's main loop handed commands on,
        // is not counted end to end — `ecat-emu/tests/regularity.rs`
        // bounds them where it is)
        assert!(
            j.unexcused as u64 <= j.corrections + j.deadline_misses,
            "irregular frames the host does not explain: {j:?}"
        );
    }
}

/// R on the first drive, S and T behind it: S's and T's drives are lost
/// (cable pulled) while motion-io serves the daemon; SIGTERM to motion-io
/// still ends it within its stated bound (quick stop bound 500 ms + 200 ms
/// margin + leaving OP ≤ 1 s).
#[test]
fn sigterm_ends_motion_io_within_the_bound_with_drives_lost() {
    let _serial = serial();
    let Some(b) = family("unplug") else {
        return;
    };
    let d = Daemon::start(&b.cfg, &["bus0"]);
    let io = find_process("motion-io", &b.cfg.prefix).expect("motion-io");
    d.ctl(&["home", "R"]).expect_code(0);
    b.rig.emulator().unplug(1);
    assert!(
        wait_for(Duration::from_secs(5), || {
            let st = d.status();
            named(&st.axes, "S").drive_lost && named(&st.axes, "T").drive_lost
        }),
        "{}",
        d.stderr()
    );
    signal_pid(io, Signal::SIGTERM);
    let t0 = Instant::now();
    let alive = |pid: i32| nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid), None).is_ok();
    assert!(wait_for(Duration::from_secs(10), || !alive(io)));
    let took = t0.elapsed();
    // its bus summary counts the losses: S and T at least (more when a
    // loaded machine made a drive miss frames and come back meanwhile)
    assert!(
        d.wait_line(" drive loss(es)", Duration::from_secs(5)),
        "{}",
        d.stderr()
    );
    let losses: Option<u32> = d.stderr().lines().find_map(|l| {
        let before = l
            .split(" drive loss(es)")
            .next()
            .filter(|b| b.len() < l.len())?;
        before.rsplit(' ').next()?.parse().ok()
    });
    assert!(losses.is_some_and(|n| n >= 2), "{losses:?}\n{}", d.stderr());
    eprintln!(
        "SIGTERM with two of three drives lost: motion-io (pid {io}) gone after {:.0} ms",
        took.as_secs_f64() * 1e3
    );
    assert!(
        took < Duration::from_millis(2500),
        "{took:?}\n{}",
        d.stderr()
    );
    d.stop();
    assert_clean(&b.cfg.prefix);
}

/// S's drive loses its power mid-homing and gets it back: its axis ends
/// ERR 12 / EXERR 45 (its drive lost), the drive is re-configured and back
/// in OP without restarting motion-io, not enabled by itself, and homes
/// again when asked.
#[test]
fn a_drive_power_cycled_mid_homing_is_reconfigured_without_restarting_motion_io() {
    let (_serial, Some(b)) = (serial(), slow("ecat_powercycle", |_| {})) else {
        return;
    };
    let d = Daemon::start(&b.cfg, &["bus0"]);
    let io = find_process("motion-io", &b.cfg.prefix).expect("motion-io");
    d.ctl(&["home", "S", "--no-wait"]).expect_code(0);
    wait_phase(&d, "S", "seek");
    std::thread::sleep(Duration::from_millis(300));
    let emu = b.rig.emulator();
    emu.power_off(0);
    let s = wait_ended(&d, "S");
    assert_eq!((s.err, s.exerr), (12, 45), "{s:#?}");
    assert!(s.drive_lost && !s.enabled, "{s:#?}");
    std::thread::sleep(Duration::from_millis(500));
    emu.power_on(0);
    // back: the drive in OP again (re-configured: its station address was
    // gone) and its axis no longer lost. What motion-io logs meanwhile is
    // sampled every 20 ms (a quick re-configuration can pass unlogged), so
    // the states are awaited, and the count read from its summary at exit.
    assert!(
        wait_for(Duration::from_secs(10), || {
            let v = b.drive(0);
            v.al_status == 0x08 && v.station_address != 0
        }),
        "not back in OP: {:?}\n{}",
        b.drive(0),
        d.stderr()
    );
    assert!(
        wait_for(Duration::from_secs(5), || !d.axis("S").drive_lost),
        "{:#?}\n{}",
        d.axis("S"),
        d.stderr()
    );
    // not enabled by itself: its power stage off (the engine withdrew the
    // enable request when the drive was lost, so the backend holds it
    // where it holds every disabled drive — Ready to switch on — or, with
    // the loss's fault latched, in Switch on disabled)
    std::thread::sleep(Duration::from_millis(300));
    let v = b.drive(0).drive;
    assert!(
        matches!(v.state, State::SwitchOnDisabled | State::ReadyToSwitchOn),
        "{v:?}"
    );
    assert!(!d.axis("S").enabled);
    assert_eq!(
        find_process("motion-io", &b.cfg.prefix),
        Some(io),
        "the same motion-io"
    );
    // the axis fault of the lost drive needs a reset before homing again
    // (ERR 20 until then)
    let r = reset_and_home_again(&d, "S");
    assert!(named(&r.axes, "S").pc);
    let end = d.stop().expect_code(0).stderr.clone();
    assert!(end.contains("1 re-configured after a power cycle"), "{end}");
    assert_clean(&b.cfg.prefix);
}

/// S homed by its drive (CiA 402 mode 6, method 19 for a bidirectional
/// forward switch): the drive finds the switch edge at 0 (its position 0
/// from then on), stops past it; the engine moves to Home Position, the
/// edge + Home Offset 1.
#[test]
fn drive_side_homing_in_mode_6() {
    let _serial = serial();
    let machine = Machine::fixture("slow_switch")
        .set("axis.S.sim.start", -10.0)
        .set("axis.S.drive_homing", true)
        .set("axis.S.home_offset", 1.0)
        .set("axis.S.home_position", 10.0);
    let Some(b) = Bus::start("ecat_drivehome", &machine, |_| {}) else {
        return;
    };
    // a homing the host broke (the drive counted lost, its homing aborted
    // 12/46) is made again: see `home_unbroken`
    let (v, stderr) = home_unbroken(&b);
    assert!(
        stderr.contains("drive homing: method 19 (positive home switch)"),
        "{stderr}"
    );
    let s = homed(&v, "S");
    assert!(s.pc, "{s:#?}");
    // the drive's home point is its position 0: the switch edge, exact
    assert_close!(s, event_raw, 0.0, 1e-9);
    ended_at(&b, 0, s, 1.0, 10.0);
    assert_eq!(b.drive(0).drive.mode, 8, "back in cyclic position mode");
}

/// A drive that lacks what its axis needs: motion-io names every missing
/// object at once and exits 1; the daemon starts it again with growing
/// delays, says so without repeating itself, and its status shows the
/// restarts and the error.
#[test]
fn a_drive_lacking_objects_is_refused_with_every_one_named_and_restarted_with_back_off() {
    let _serial = serial();
    let machine = Machine::fixture("slow_switch")
        .set("axis.S.registration", true)
        .set("supervisor.io_watchdog_cycles", 50);
    let Some(b) = Bus::start("ecat_bare", &machine, |d| {
        d[0].touch_probe = false;
        d[0].digital_inputs = false;
    }) else {
        return;
    };
    // motion-io alone: every missing object, at once
    let out = spawn_io(&["--config", b.cfg.arg(), "--interface", b.rig.interface()]).finish();
    out.expect_code(1);
    for want in [
        "SubDevice 0 (EMU-S): 5 problem(s) for axis S:",
        "missing 0x60B8 touch probe function — arms the touch probes — needed by axis S: \
         registration = true",
        "missing 0x60B9 touch probe status",
        "missing 0x60BC touch probe 2 positive edge",
        "missing 0x60BD touch probe 2 negative edge",
        "missing 0x60FD digital inputs — reports the home switch, limit switch and index inputs \
         — needed by axis S: home_sequence = \"switch\"",
    ] {
        assert!(out.stderr.contains(want), "no {want:?} in\n{}", out.stderr);
    }
    // the daemon starts it again and again, 1 s, 2 s, 4 s …, saying so
    // once; its status shows the restarts and the error (read while it
    // waits for the next start: while one runs there is no retry time)
    let mut d = Daemon::spawn(&b.cfg);
    let ok = wait_for(Duration::from_secs(20), || {
        motion_harness::daemon::status(&motion_harness::bins::test_bin("motionctl"), &b.cfg.prefix)
            .is_some_and(|s| s.io[0].restarts >= 2 && s.io[0].retry_in_s.is_some())
    });
    let st = d.status();
    assert!(ok, "{:#?}\n{}", st.io, d.stderr());
    let row = &st.io[0];
    assert!(
        row.start_error
            .as_deref()
            .is_some_and(|e| e.starts_with("EtherCAT start-up on")),
        "{row:#?}"
    );
    assert!(row.retry_in_s.is_some_and(|s| s > 0.0), "{row:#?}");
    let err = d.stderr();
    assert!(
        err.contains("starting it again in 1 s (restart 1)"),
        "{err}"
    );
    assert!(
        err.contains("starting it again in 2 s (restart 2)"),
        "{err}"
    );
    assert!(err.contains("failed at start-up again, as before"), "{err}");
    assert_eq!(
        err.matches("missing 0x60B8 touch probe function").count(),
        1,
        "said once: {err}"
    );
    d.wait_ready(Attached::These(&[]));
    d.stop();
    assert_clean(&b.cfg.prefix);
}

#[test]
fn scan_from_the_command_line() {
    let _serial = serial();
    let Some(b) = family("unplug") else {
        return;
    };
    let out = spawn_io(&["scan", "--interface", b.rig.interface(), "--json"]).finish();
    out.expect_code(0);
    let v = out.json();
    let subs = v["subdevices"].as_array().expect("subdevices");
    assert_eq!(subs.len(), 3, "{v:#}");
    assert_eq!(subs[1]["name"], "EMU-S");
    assert!(v["config"]
        .as_str()
        .unwrap()
        .contains("ethercat_position = 2"));
    let text = spawn_io(&["scan", "--interface", b.rig.interface()]).finish();
    text.expect_code(0);
    assert!(
        text.stdout.contains("SubDevice 0 \"EMU-R\""),
        "{}",
        text.stdout
    );
    // nothing there
    let out = spawn_io(&["scan", "--interface", "nonexistent0", "--json"]).finish();
    out.expect_code(1);
    assert!(out.stdout.contains("\"errors\""), "{}", out.stdout);
    assert_clean(&b.cfg.prefix);
}
