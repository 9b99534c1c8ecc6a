//! The deployed controller end to end: `motion-supervisor run` commanded and
//! watched with `motionctl`, several I/O processes attaching and detaching.
//! (The Python client package against the daemon: `python_client.rs`.)
//!
//! The machine is `tests/machines/two_buses.toml`: X (switch then marker,
//! event -7.5, about 3 s) and Z (a slow switch) on bus0, Y (a slow switch,
//! about 9 s) on bus1.

use motion_harness::{assert_close, *};
use motion_report::{AcceptedReport, StatsReport, TraceReport};
use std::time::Duration;

fn two_buses(tag: &str) -> TempConfig {
    Machine::fixture("two_buses").write(tag)
}

/// `motionctl home|stop|unhome …` refused (exit 1), saying `why`.
#[track_caller]
fn refused(d: &Daemon, args: &[&str], why: &[&str]) {
    let r = d.ctl(args);
    r.expect_code(1);
    assert!(why.iter().any(|w| r.stdout.contains(w)), "{}", r.stdout);
}

#[test]
fn motionctl_homes_stops_unhomes_reports_and_traces() {
    let _serial = serial();
    let cfg = two_buses("ctl");
    let d = Daemon::start(&cfg, &["bus0", "bus1"]);
    let p = cfg.prefix.clone();

    // status --json: its fixed keys (docs/status.md; read from the JSON
    // itself: a typed field would have a default where a key was missing)
    let raw = d.ctl(&["status", "--json"]).json();
    let x = raw["axes"]
        .as_array()
        .and_then(|a| a.iter().find(|r| r["name"] == "X"))
        .unwrap_or_else(|| panic!("no X in {raw}"));
    for k in [
        "name", "io", "phase", "homing", "homed", "en", "dn", "er", "ip", "pc", "err", "exerr",
        "position", "raw",
    ] {
        assert!(x.get(k).is_some(), "status has no {k}: {x}");
    }
    let x = d.axis("X");
    assert_eq!(x.io, "bus0");
    assert_eq!(x.phase, "idle");
    assert!(!x.homed);
    assert_close!(x, raw, -20.0, COUNT);

    // home X with a trace: CSV and plot
    let dir = TempDir::new("ctl_files");
    let (csv, svg) = (dir.file("trace.csv"), dir.file("trace.svg"));
    let r = d.ctl(&[
        "trace", "X", "--home", "--out", &csv, "--plot", &svg, "--json",
    ]);
    let t: TraceReport = r.expect_code(0).report();
    assert!(
        t.event_raw.is_some_and(|e| (e + 7.5).abs() <= COUNT),
        "{t:#?}"
    );
    assert!(t.cycles > 1000, "{t:#?}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("t_s,phase,cmd_position"));
    assert_eq!(
        text.lines()
            .filter(|l| l.split(',').nth(10) == Some("1"))
            .count(),
        1
    );
    for phase in ["seek", "return", "move_home"] {
        assert!(text.contains(&format!(",{phase},")), "no {phase} rows");
    }
    assert!(std::fs::read_to_string(&svg)
        .unwrap()
        .contains("home event -7.5000"));
    let x = d.axis("X");
    assert!(x.pc && x.homed, "{x:#?}");

    // home Y and Z; stop Z while it seeks: ERR 12 / EXERR 1
    let r = d.ctl(&["home", "Y", "Z", "--parallel", "--no-wait", "--json"]);
    let _: AcceptedReport = r.expect_code(0).report();
    assert!(wait_for(Duration::from_secs(10), || d.axis("Z").phase == "seek"));
    // a second home of a homing axis is refused, with the reason
    refused(
        &d,
        &["home", "Z", "--no-wait", "--json"],
        &["already homing", "another home sequence"],
    );
    d.ctl(&["stop", "Z"]).expect_code(0);
    assert!(wait_for(Duration::from_secs(10), || {
        let z = d.axis("Z");
        z.er && !z.ip
    }));
    let z = d.axis("Z");
    assert_eq!((z.err, z.exerr), (12, 1), "{z:#?}");

    // Y was homing beside Z: a stop of Z does not stop it (parallel request
    // of named axes; Z's stop is not an I/O loss, so the sequence ends — but
    // Y's homing is its own and completes or is stopped with a reason)
    assert!(wait_for(Duration::from_secs(30), || !d.axis("Y").ip));

    // unhome X
    d.ctl(&["unhome", "X", "--json"]).expect_code(0);
    assert!(!d.axis("X").homed);

    // unknown axis: refused with the reason
    refused(&d, &["home", "W", "--json"], &["unknown axis"]);

    // stats: since start, then reset
    let r = d.ctl(&["stats", "--json", "--reset"]);
    let s: StatsReport = r.expect_code(0).report();
    assert_eq!(s.since, "start");
    assert!(s.latency.cycles > 1000, "{s:#?}");
    // from the JSON itself: the typed field would read 0 were it missing
    let calls = &r.json()["allocations"]["system_calls_in_cycle"];
    assert_eq!(calls, 0, "{}", r.stdout);
    let hlog = dir.file("stats.hlog");
    let r = d.ctl(&["stats", "--since-reset", "--hlog", &hlog]);
    r.expect_code(0);
    assert!(r.stdout.contains("since reset"), "{}", r.stdout);
    assert!(std::fs::read_to_string(&hlog)
        .unwrap()
        .contains("#[StartTime"));

    d.stop().expect_code(0);
    assert_clean(&p);
    assert!(!std::path::Path::new(&format!("/run/motion/{p}.session")).exists());
}

/// Two external I/O processes; bus1 killed mid-homing: Y aborts with 12/40,
/// X (bus0) homes. bus1 restarted: attached again, Y's reference cleared.
#[test]
fn losing_one_of_two_io_processes_aborts_only_its_axes() {
    let _serial = serial();
    let cfg = Machine::fixture("two_buses")
        .set("io.bus0.spawn", "external")
        .set("io.bus1.spawn", "external")
        .write("twoio");
    let mut d = Daemon::spawn(&cfg);
    let io_args = |io: &'static str| ["--config", cfg.arg(), "--io", io, "--priority", "60"];
    let bus0 = spawn_io(&io_args("bus0"));
    let mut bus1 = spawn_io(&io_args("bus1"));
    d.wait_ready(Attached::All);
    // home X and Y together; kill bus1 while Y seeks (X takes ~3 s, Y ~9 s)
    d.ctl(&["home", "X", "Y", "--parallel", "--no-wait"])
        .expect_code(0);
    std::thread::sleep(Duration::from_millis(1000));
    bus1.kill();
    assert!(wait_for(Duration::from_secs(20), || {
        let v = d.status();
        !named(&v.axes, "X").ip && !named(&v.axes, "Y").ip
    }));
    let v = d.status();
    let x = named(&v.axes, "X");
    let y = named(&v.axes, "Y");
    assert!(x.pc && x.homed, "{x:#?}");
    assert_eq!((y.err, y.exerr), (12, 40), "{y:#?}");
    assert!(!y.homed);
    assert!(!named(&v.io, "bus1").attached);
    assert!(
        d.wait_line("I/O process bus1 detached", Duration::from_secs(5)),
        "{}",
        d.stderr()
    );
    // Home Y while bus1 is gone: refused, naming the reason
    refused(&d, &["home", "Y", "--json"], &["not attached"]);

    // bus1 comes back: attached again (reported), Y not homed, X still homed
    let bus1b = spawn_io(&io_args("bus1"));
    assert!(wait_for(Duration::from_secs(20), || {
        named(&d.status().io, "bus1").attached
    }));
    assert!(
        d.wait_line("I/O process bus1 attached again", Duration::from_secs(5)),
        "{}",
        d.stderr()
    );
    let v = d.status();
    let io1 = named(&v.io, "bus1");
    assert_eq!(io1.attachments, 2, "{io1:#?}");
    assert!(named(&v.axes, "X").homed);
    assert!(!named(&v.axes, "Y").homed);
    d.stop().expect_code(0);
    // the I/O processes stop their axes and leave when the supervisor is gone
    for w in [bus0, bus1b] {
        w.stop();
    }
    assert_clean(&cfg.prefix);
}

/// An HMI that outlives the daemon (`status --watch` notices it is gone
/// and exits) is the domain's last node: nothing of the domain may stay in
/// /dev/shm behind it (iceoryx2 would leave its node counter).
#[test]
fn an_hmi_outliving_the_daemon_leaves_nothing_behind() {
    let _serial = serial();
    let cfg = two_buses("hmi");
    let d = Daemon::start(&cfg, &["bus0", "bus1"]);
    let mut hmi = spawn_motionctl(&["--service-prefix", &cfg.prefix, "status", "--watch"]);
    std::thread::sleep(Duration::from_millis(500));
    d.stop().expect_code(0);
    // The watcher finds the status service gone within its 2 s wait.
    assert!(
        hmi.wait_exit(Duration::from_secs(15)).is_some(),
        "motionctl status --watch did not notice the supervisor was gone"
    );
    let ended = hmi.finish();
    assert_ne!(ended.code(), Some(0), "it must say the supervisor is gone");
    assert_clean(&cfg.prefix);
}
