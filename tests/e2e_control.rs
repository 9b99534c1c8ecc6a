//! The deployed controller end to end: `motion-supervisor run` commanded and
//! watched with `motionctl`, several I/O processes attaching and detaching,
//! and a client nobody here wrote (Python, the iceoryx2 package only).

use motion_tests::*;
use nix::sys::signal::Signal;
use std::process::{Command, Stdio};
use std::time::Duration;

/// X: switch then marker 20 units away (about 3 s), on bus0.
/// Y: switch 40 units away at 5 u/s (about 9 s), on bus1.
/// Z: a slow switch axis on bus0, for stop during homing.
fn two_buses(tag: &str, spawn: &str) -> TempConfig {
    // A generous loss bound: these tests are about which axes a lost I/O
    // process takes down, not about a loaded CI machine's scheduling gaps.
    config(
        tag,
        "feedback_timeout_ms = 100\n",
        &format!(
            r#"
[[io]]
name = "bus0"
spawn = "{spawn}"
[[io]]
name = "bus1"
spawn = "{spawn}"

[[axis]]
name = "X"
io = "bus0"
counts_per_unit = 1000.0
marker = true
home_sequence = "switch_then_marker"
home_speed = 20.0
home_return_speed = 4.0
home_acceleration = 500.0
home_deceleration = 500.0
home_timeout = 30.0
[axis.sim]
start = -20.0
switch = [0.0, 5.0]
marker_every = 10.0
marker_at = 2.5

[[axis]]
name = "Y"
io = "bus1"
counts_per_unit = 1000.0
home_sequence = "switch"
home_speed = 5.0
home_return_speed = 1.0
home_acceleration = 100.0
home_deceleration = 100.0
home_timeout = 60.0
[axis.sim]
start = -40.0
switch = [0.0, 5.0]

[[axis]]
name = "Z"
io = "bus0"
counts_per_unit = 1000.0
home_sequence = "switch"
home_speed = 5.0
home_return_speed = 1.0
home_acceleration = 100.0
home_deceleration = 100.0
home_timeout = 60.0
[axis.sim]
start = -40.0
switch = [0.0, 5.0]
"#
        ),
    )
}

fn axis_status<'a>(v: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    axis(v, name)
}

#[test]
fn motionctl_homes_stops_unhomes_reports_and_traces() {
    let _serial = serial();
    let cfg = two_buses("ctl", "sim");
    let d = Daemon::start(&cfg, &["bus0", "bus1"]);
    let p = cfg.prefix.clone();

    // status --json: the fixed keys of interface.md
    let v = d.status();
    let x = axis_status(&v, "X");
    for k in [
        "name", "io", "phase", "homing", "homed", "en", "dn", "er", "ip", "pc", "err", "exerr",
        "position", "raw",
    ] {
        assert!(x.get(k).is_some(), "status has no {k}: {x}");
    }
    assert_eq!(x["io"], "bus0");
    assert_eq!(x["phase"], "idle");
    assert_eq!(x["homed"], false);
    close(x, "raw", -20.0, COUNT);

    // home X with a trace: CSV and plot
    let dir = std::env::temp_dir();
    let csv = dir.join(format!("{p}.csv"));
    let svg = dir.join(format!("{p}.svg"));
    let r = ctl(
        &p,
        &[
            "trace",
            "X",
            "--home",
            "--out",
            csv.to_str().unwrap(),
            "--plot",
            svg.to_str().unwrap(),
            "--json",
        ],
    );
    assert_eq!(r.code, Some(0), "{}\n{}", r.stdout, r.stderr);
    let t = r.json();
    close(&t, "event_raw", -7.5, COUNT);
    assert!(t["cycles"].as_u64().unwrap() > 1000, "{t}");
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
    let _ = std::fs::remove_file(&csv);
    let _ = std::fs::remove_file(&svg);
    let x = axis_status(&d.status(), "X").clone();
    assert_eq!(
        (x["pc"].clone(), x["homed"].clone()),
        (true.into(), true.into())
    );

    // home Y and Z; stop Z while it seeks: ERR 12 / EXERR 1
    let r = ctl(&p, &["home", "Y", "Z", "--parallel", "--no-wait", "--json"]);
    assert_eq!(r.code, Some(0), "{}\n{}", r.stdout, r.stderr);
    assert!(wait_for(Duration::from_secs(10), || axis_status(
        &d.status(),
        "Z"
    )["phase"]
        == "seek"));
    // a second home of a homing axis is refused, with the reason
    let r = ctl(&p, &["home", "Z", "--no-wait", "--json"]);
    assert_eq!(r.code, Some(1));
    assert!(
        r.stdout.contains("already homing") || r.stdout.contains("another home sequence"),
        "{}",
        r.stdout
    );
    let r = ctl(&p, &["stop", "Z"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(wait_for(Duration::from_secs(10), || {
        let z = axis_status(&d.status(), "Z").clone();
        z["er"] == true && z["ip"] == false
    }));
    let z = axis_status(&d.status(), "Z").clone();
    assert_eq!((num(&z, "err"), num(&z, "exerr")), (12.0, 1.0), "{z}");

    // Y was homing beside Z: a stop of Z does not stop it (parallel request
    // of named axes; Z's stop is not an I/O loss, so the sequence ends — but
    // Y's homing is its own and completes or is stopped with a reason)
    assert!(wait_for(Duration::from_secs(30), || axis_status(
        &d.status(),
        "Y"
    )["ip"]
        == false));

    // unhome X
    let r = ctl(&p, &["unhome", "X", "--json"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(axis_status(&d.status(), "X")["homed"], false);

    // unknown axis: refused with the reason
    let r = ctl(&p, &["home", "W", "--json"]);
    assert_eq!(r.code, Some(1));
    assert!(r.stdout.contains("unknown axis"), "{}", r.stdout);

    // stats: since start, then reset
    let r = ctl(&p, &["stats", "--json", "--reset"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let s = r.json();
    assert_eq!(s["since"], "start");
    assert!(s["latency"]["cycles"].as_u64().unwrap() > 1000, "{s}");
    assert_eq!(s["allocations"]["system_calls_in_cycle"], 0, "{s}");
    let hlog = dir.join(format!("{p}.hlog"));
    let r = ctl(
        &p,
        &["stats", "--since-reset", "--hlog", hlog.to_str().unwrap()],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(r.stdout.contains("since reset"), "{}", r.stdout);
    assert!(std::fs::read_to_string(&hlog)
        .unwrap()
        .contains("#[StartTime"));
    let _ = std::fs::remove_file(&hlog);

    let run = d.stop();
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert_clean(&p);
    assert!(!std::path::Path::new(&format!("/run/motion/{p}.session")).exists());
}

/// Two external I/O processes; bus1 killed mid-homing: Y aborts with 12/40,
/// X (bus0) homes. bus1 restarted: attached again, Y's reference cleared.
#[test]
fn losing_one_of_two_io_processes_aborts_only_its_axes() {
    let _serial = serial();
    let cfg = two_buses("twoio", "external");
    let p = cfg.prefix.clone();
    let conf = cfg.path.to_str().unwrap();
    let w = Watched::new(spawn_supervisor(&["run", "--config", conf]));
    let d = Daemon {
        watched: Some(w),
        prefix: p.clone(),
    };
    let io_args = |io: &'static str| ["--config", conf, "--io", io, "--priority", "60"];
    let bus0 = spawn_io(&io_args("bus0"));
    let mut bus1 = spawn_io(&io_args("bus1"));
    assert!(
        wait_for(Duration::from_secs(20), || {
            let r = ctl(&p, &["status", "--json"]);
            r.code == Some(0)
                && r.json()["io"]
                    .as_array()
                    .is_some_and(|a| a.iter().all(|x| x["attached"] == true))
        }),
        "I/O processes never attached: {}",
        d.stderr()
    );
    // home X and Y together; kill bus1 while Y seeks (X takes ~3 s, Y ~9 s)
    let r = ctl(&p, &["home", "X", "Y", "--parallel", "--no-wait"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    std::thread::sleep(Duration::from_millis(1000));
    signal(bus1.child.id() as i32, Signal::SIGKILL);
    let _ = bus1.child.wait();
    assert!(wait_for(Duration::from_secs(20), || {
        let v = d.status();
        axis(&v, "X")["ip"] == false && axis(&v, "Y")["ip"] == false
    }));
    let v = d.status();
    let x = axis(&v, "X");
    let y = axis(&v, "Y");
    assert_eq!(
        (x["pc"].clone(), x["homed"].clone()),
        (true.into(), true.into()),
        "{x}"
    );
    assert_eq!((num(y, "err"), num(y, "exerr")), (12.0, 40.0), "{y}");
    assert_eq!(y["homed"], false);
    let io1 = v["io"]
        .as_array()
        .unwrap()
        .iter()
        .find(|i| i["name"] == "bus1")
        .unwrap()
        .clone();
    assert_eq!(io1["attached"], false);
    assert!(
        d.wait_line("I/O process bus1 detached", Duration::from_secs(5)),
        "{}",
        d.stderr()
    );
    // Home Y while bus1 is gone: refused, naming the reason
    let r = ctl(&p, &["home", "Y", "--json"]);
    assert_eq!(r.code, Some(1));
    assert!(r.stdout.contains("not attached"), "{}", r.stdout);

    // bus1 comes back: attached again (reported), Y not homed, X still homed
    let bus1b = spawn_io(&io_args("bus1"));
    assert!(wait_for(Duration::from_secs(20), || {
        d.status()["io"][1]["attached"] == true
    }));
    assert!(
        d.wait_line("I/O process bus1 attached again", Duration::from_secs(5)),
        "{}",
        d.stderr()
    );
    let v = d.status();
    assert_eq!(v["io"][1]["attachments"], 2, "{}", v["io"][1]);
    assert_eq!(axis(&v, "X")["homed"], true);
    assert_eq!(axis(&v, "Y")["homed"], false);
    let run = d.stop();
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    // the I/O processes stop their axes and leave when the supervisor is gone
    for w in [bus0, bus1b] {
        let mut w = w;
        signal(w.child.id() as i32, Signal::SIGTERM);
        let _ = w.child.wait();
    }
    assert_clean(&p);
}

/// An HMI that outlives the daemon (`status --watch` notices it is gone
/// and exits) is the domain's last node: nothing of the domain may stay in
/// /dev/shm behind it (iceoryx2 would leave its node counter).
#[test]
fn an_hmi_outliving_the_daemon_leaves_nothing_behind() {
    let _serial = serial();
    let cfg = two_buses("hmi", "sim");
    let d = Daemon::start(&cfg, &["bus0", "bus1"]);
    let p = cfg.prefix.clone();
    let hmi = Command::new(bin("motionctl"))
        .args(["--service-prefix", &p, "status", "--watch"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("motionctl status --watch");
    let mut hmi = Watched::new(hmi);
    std::thread::sleep(Duration::from_millis(500));
    let run = d.stop();
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    // The watcher finds the status service gone within its 2 s wait.
    assert!(
        wait_for(Duration::from_secs(15), || {
            hmi.child.try_wait().map_or(true, |s| s.is_some())
        }),
        "motionctl status --watch did not notice the supervisor was gone"
    );
    let ended = hmi.finish();
    assert_ne!(ended.code, Some(0), "it must say the supervisor is gone");
    assert_clean(&p);
}

/// A client nobody here wrote: the Python example, with nothing but the
/// `iceoryx2` package, reads the status and homes an axis.
#[test]
fn the_python_client_reads_status_and_homes() {
    let Some(python) = python_with_iceoryx2() else {
        assert!(
            std::env::var_os("MOTION_PYTHON_REQUIRED").is_none(),
            "MOTION_PYTHON_REQUIRED is set but no Python with the iceoryx2 package was found"
        );
        eprintln!(
            "SKIPPED: no Python with the iceoryx2 package (set MOTION_PYTHON; .ci/run makes one)"
        );
        return;
    };
    let _serial = serial();
    let cfg = two_buses("py", "sim");
    let d = Daemon::start(&cfg, &["bus0", "bus1"]);
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/python/motion_client.py"
    );
    let out: Run = std::process::Command::new(&python)
        .args([script, "--prefix", &cfg.prefix, "--home", "X"])
        .output()
        .expect("run python")
        .into();
    assert_eq!(out.code, Some(0), "{}\n{}", out.stdout, out.stderr);
    assert!(out.stdout.contains("io bus0: attached"), "{}", out.stdout);
    assert!(out.stdout.contains("X: homed: PC 1"), "{}", out.stdout);
    assert!(out.stdout.contains("event_raw -7.500000"), "{}", out.stdout);
    let v = d.status();
    assert_eq!(axis(&v, "X")["pc"], true);
    // and without a supervisor: exit 3
    let none: Run = std::process::Command::new(&python)
        .args([script, "--prefix", "nobody_here"])
        .output()
        .expect("run python")
        .into();
    assert_eq!(none.code, Some(3), "{}", none.stderr);
    d.stop();
    assert_clean(&cfg.prefix);
}

/// `$MOTION_PYTHON`, else `.ci/venv/bin/python`, if it imports iceoryx2.
fn python_with_iceoryx2() -> Option<String> {
    let candidates = [
        std::env::var("MOTION_PYTHON").ok(),
        Some(concat!(env!("CARGO_MANIFEST_DIR"), "/../.ci/venv/bin/python").to_string()),
    ];
    candidates.into_iter().flatten().find(|p| {
        std::process::Command::new(p)
            .args(["-c", "import iceoryx2"])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}
