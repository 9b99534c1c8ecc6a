//! Registration (MAR / MDR) end to end, through real processes: the daemon,
//! its `motion-io` (sim) and `motionctl arm` / `disarm`. The machine is
//! `tests/machines/ops.toml` with a home switch over [2, 4] on X and Z and
//! markers at 7.5 + 10 k on X; X's drive latches both (`registration`,
//! `marker_latch`: the sim's latches are exact), Z's latches nothing (the
//! edge is sampled from the input bits). Unhomed: axis = raw.

use motion_harness::*;
use motion_report::RegistrationReport;
use std::time::Duration;

fn machine(tag: &str) -> TempConfig {
    let mut m = Machine::fixture("ops");
    for a in ["X", "Z"] {
        m = m.set(&format!("axis.{a}.sim.switch"), vec![2.0, 4.0]);
    }
    m.set("axis.X.registration", true)
        .set("axis.X.marker", true)
        .set("axis.X.marker_latch", true)
        .set("axis.X.sim.marker_every", 10.0)
        .set("axis.X.sim.marker_at", 7.5)
        .write(tag)
}

/// `motionctl arm ARGS --json` started in the background, and waited for
/// until the registration is armed.
fn arm_waiting(d: &Daemon, prefix: &str, axis: &str, args: &[&str]) -> Running {
    let mut all = vec!["--service-prefix", prefix, "arm", axis, "--json"];
    all.extend_from_slice(args);
    let running = spawn_motionctl(&all);
    d.wait_axis(axis, 20, |a| a.registration_armed);
    running
}

/// What a waiting `arm --json` printed: its one row's position.
fn latched(running: Running) -> f64 {
    let r = running.wait(Duration::from_secs(20), Duration::from_secs(1));
    let rep: RegistrationReport = r.expect_code(0).report();
    assert_eq!(rep.axes.len(), 1, "{}", r.stdout);
    rep.axes[0].position.expect("a position")
}

#[test]
fn arm_latches_the_switch_and_the_marker_exactly_where_the_drive_latches() {
    let _serial = serial();
    let cfg = machine("reg_exact");
    let d = Daemon::start(&cfg, &["io"]);
    d.ctl(&["enable", "X"]).expect_code(0);
    d.wait_axis("X", 20, |a| a.servo_action);

    // --no-wait: armed, nothing latched yet; a jog across the switch
    d.ctl(&["arm", "X", "--no-wait"]).expect_code(0);
    let x = d.axis("X");
    assert!(
        x.registration_armed && x.registration_position.is_none(),
        "{x:#?}"
    );
    let mut jog = spawn_motionctl(&["--service-prefix", &cfg.prefix, "jog", "X", "--speed", "5"]);
    let x = d.wait_axis("X", 20, |a| !a.registration_armed);
    assert!(x.jogging, "the jog runs on: {x:#?}");
    d.ctl(&["stop", "X"]).expect_code(0);
    assert_eq!(
        jog.wait_exit(Duration::from_secs(5)).and_then(|s| s.code()),
        Some(0),
        "the jog ended normally"
    );
    let x = d.axis("X");
    assert_eq!(
        x.registration_position,
        Some(2.0),
        "the edge, exactly: {x:#?}"
    );

    // waiting, the falling edge, during a move
    d.wait_axis("X", 20, |a| !a.stopping && !a.jogging);
    d.ctl(&["move", "X", "--to", "1"]).expect_code(0);
    let arm = arm_waiting(&d, &cfg.prefix, "X", &["--edge", "falling"]);
    d.ctl(&["move", "X", "--to", "6"]).expect_code(0);
    assert_eq!(latched(arm), 4.0);

    // the marker inside a window: 7.5 passed over, 17.5 latched
    let arm = arm_waiting(
        &d,
        &cfg.prefix,
        "X",
        &["--input", "marker", "--window", "10", "20"],
    );
    d.ctl(&["move", "X", "--to", "19"]).expect_code(0);
    assert_eq!(latched(arm), 17.5);

    // refusals: an empty window; a marker Z does not have
    d.refused_with(&["arm", "X", "--window", "3", "1"], 1022, 4);
    d.refused_with(&["arm", "Z", "--input", "marker"], 1022, 2);
    d.stop().expect_code(0);
    assert_clean(&cfg.prefix);
}

#[test]
fn without_a_drive_latch_arm_samples_the_edge_within_a_cycle_of_travel() {
    let _serial = serial();
    let cfg = machine("reg_sampled");
    let d = Daemon::start(&cfg, &["io"]);
    d.ctl(&["enable", "Z"]).expect_code(0);
    d.wait_axis("Z", 20, |a| a.servo_action);
    // speed 5 u/s, cycle 1 ms: the edge within 5 × 0.001 / 2 (and a count)
    let arm = arm_waiting(&d, &cfg.prefix, "Z", &[]);
    d.ctl(&["move", "Z", "--to", "6", "--speed", "5"])
        .expect_code(0);
    let p = latched(arm);
    eprintln!(
        "sampled: latched {p} for the edge at 2 (error {:.4})",
        p - 2.0
    );
    assert!((p - 2.0).abs() <= 5.0 * 0.001 / 2.0 + COUNT, "{p}");

    // disarm: nothing latched on the way back; the last position stays
    d.ctl(&["arm", "Z", "--no-wait"]).expect_code(0);
    d.ctl(&["disarm", "Z"]).expect_code(0);
    let z = d.wait_axis("Z", 20, |a| !a.registration_armed);
    assert_eq!(z.registration_position, None, "a new arming cleared it");
    d.ctl(&["move", "Z", "--to", "0"]).expect_code(0);
    assert!(!d.axis("Z").registration_armed);
    d.stop().expect_code(0);
    assert_clean(&cfg.prefix);
}

/// One linear axis S on an emulated CiA 402 drive: immediate homing (axis
/// = raw until homed), the home switch over [0, 5], markers at 2.5 + 10 k;
/// `registration` (touch probe 2 on the switch) as given, the marker
/// latched by touch probe 1 where the drive has it. `tweak` changes the
/// drive. None (printed why) without root.
fn ecat(
    tag: &str,
    registration: bool,
    tweak: impl FnOnce(&mut [ecat_emu::DriveConfig]),
) -> Option<motion_harness::ecat::Bus> {
    let m = Machine::fixture("slow_switch")
        .set("supervisor.feedback_timeout_ms", 100)
        .set("axis.S.home_sequence", "immediate")
        .set("axis.S.max_speed", 10.0)
        .set("axis.S.marker", true)
        .set("axis.S.registration", registration)
        .set("axis.S.sim.start", -2.0)
        .set("axis.S.sim.marker_every", 10.0)
        .set("axis.S.sim.marker_at", 2.5);
    motion_harness::ecat::Bus::start(tag, &m, tweak)
}

/// The daemon on bus `b`, S enabled.
fn enabled_on(b: &motion_harness::ecat::Bus) -> Daemon {
    let d = Daemon::start(&b.cfg, &["bus0"]);
    d.ctl(&["enable", "S"]).expect_code(0);
    d.wait_axis("S", 20, |a| a.servo_action);
    d
}

/// Armed on the bus's S, moved at 2 u/s to `to`: the latched position.
fn ecat_latched(d: &Daemon, prefix: &str, args: &[&str], to: &str) -> f64 {
    let arm = arm_waiting(d, prefix, "S", args);
    d.ctl(&["move", "S", "--to", to, "--speed", "2"])
        .expect_code(0);
    latched(arm)
}

/// Through the touch probes: exact to the count, both edges of the switch
/// (0x60BC, 0x60BD) and the marker (0x60BA).
#[test]
fn over_ethercat_the_touch_probe_latches_exactly_to_the_count() {
    let _serial = serial();
    let Some(b) = ecat("ecat_reg_tp", true, |_| {}) else {
        return;
    };
    let d = enabled_on(&b);
    let p = &b.cfg.prefix;
    let rising = ecat_latched(&d, p, &[], "1");
    let falling = ecat_latched(&d, p, &["--edge", "falling"], "6");
    let back = ecat_latched(&d, p, &["--edge", "rising"], "4");
    let marker = ecat_latched(&d, p, &["--input", "marker"], "1");
    eprintln!(
        "touch probe: rising {rising} (edge 0), falling {falling} (edge 5), \
         rising backwards {back} (edge 5), marker {marker} (2.5)"
    );
    for (got, want) in [(rising, 0.0), (falling, 5.0), (back, 5.0), (marker, 2.5)] {
        assert!(
            (got - want).abs() < 1e-9,
            "{got} vs {want}: not to the count"
        );
    }
    d.stop().expect_code(0);
    assert_clean(&b.cfg.prefix);
}

/// A drive without touch probes ("no touch probe" profile): `arm` is not
/// refused; the edge is sampled from 0x60FD, within speed × cycle (a
/// sample may be a bus cycle old, see `e2e_ethercat.rs`).
#[test]
fn over_ethercat_without_a_touch_probe_the_edge_is_sampled_within_a_cycle_of_travel() {
    let _serial = serial();
    let Some(b) = ecat("ecat_reg_sampled", false, |d| d[0].touch_probe = false) else {
        return;
    };
    let d = enabled_on(&b);
    let p = &b.cfg.prefix;
    let rising = ecat_latched(&d, p, &[], "1");
    let falling = ecat_latched(&d, p, &["--edge", "falling"], "6");
    eprintln!(
        "sampled over EtherCAT at 2 u/s, 1 ms: rising {rising} (edge 0), falling {falling} (edge 5)"
    );
    let bound = 2.0 * 0.001 + COUNT;
    assert!(rising.abs() <= bound, "{rising}");
    assert!((falling - 5.0).abs() <= bound, "{falling}");
    d.stop().expect_code(0);
    assert_clean(&b.cfg.prefix);
}
