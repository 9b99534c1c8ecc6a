//! The Python client package (`python/`, `pip install ./python`): its
//! ctypes layouts against the description the Rust types write, the
//! package installed offline with its `motion-client` command, and —
//! a client nobody here wrote the protocol side of — the installed package
//! driving the real daemon: status, home, the operations and the stream.
//!
//! The Python is `$MOTION_PYTHON`, else `.ci/venv/bin/python` (else, for the
//! layout check, which needs only the standard library, `python3`). Without
//! one each test says SKIPPED, unless `MOTION_PYTHON_REQUIRED` is set (CI).

use motion_harness::{assert_close, *};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

const PACKAGE_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../python");
const EXAMPLES_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/python");

/// The first candidate Python that runs `check` (a `-c` program), or None
/// after saying why the test is skipped (a failure with
/// `MOTION_PYTHON_REQUIRED`).
fn python(check: &str, what: &str, fallback: bool) -> Option<String> {
    let candidates = [
        std::env::var("MOTION_PYTHON").ok(),
        Some(concat!(env!("CARGO_MANIFEST_DIR"), "/../.ci/venv/bin/python").to_string()),
        fallback.then(|| "python3".to_string()),
    ];
    let found = candidates.into_iter().flatten().find(|p| {
        Command::new(p)
            .args(["-c", check])
            .output()
            .is_ok_and(|o| o.status.success())
    });
    if found.is_none() {
        assert!(
            std::env::var_os("MOTION_PYTHON_REQUIRED").is_none(),
            "MOTION_PYTHON_REQUIRED is set but no Python with {what} was found"
        );
        eprintln!("SKIPPED: no Python with {what} (set MOTION_PYTHON; .ci/run makes one)");
    }
    found
}

/// `pip install ./python` into a scratch directory: offline (`--no-index`;
/// the in-tree build backend needs nothing), without its dependency
/// (iceoryx2 is in the Python already).
fn install(python: &str) -> TempDir {
    let dir = TempDir::new("pypkg");
    let target = dir.file("site");
    let mut cmd = Command::new(python);
    cmd.args(["-m", "pip", "install", "--quiet", "--no-deps", "--no-index"])
        .env("PYTHONDONTWRITEBYTECODE", "1") // nothing written into python/
        .args([
            "--disable-pip-version-check",
            "--target",
            &target,
            PACKAGE_DIR,
        ]);
    Running::start(&mut cmd, "pip install")
        .finish()
        .expect_code(0);
    dir
}

/// `python -m unittest` over `python/tests`: every field of every mirror
/// against `layout.json`, and the check against wrong mirrors.
#[test]
fn the_ctypes_layouts_match_the_rust_types_field_by_field() {
    let Some(python) = python("import ctypes, json", "ctypes", true) else {
        return;
    };
    let mut cmd = Command::new(&python);
    cmd.args(["-m", "unittest", "discover", "-v", "-s", "tests"])
        .env("PYTHONDONTWRITEBYTECODE", "1") // the source tree stays as it is
        .current_dir(PACKAGE_DIR);
    let out = Running::start(&mut cmd, "python -m unittest").finish();
    out.expect_code(0);
    // the mutated mirrors ran (the check can fail), and nothing was skipped
    let swapped = out
        .stderr
        .lines()
        .find(|l| l.starts_with("test_swapped_fields_of_the_same_size "));
    assert!(
        swapped.is_some_and(|l| l.ends_with("... ok")),
        "{}",
        out.stderr
    );
    assert!(!out.stderr.contains("skipped"), "{}", out.stderr);
}

/// Installed offline, the package has its command, its layout description
/// and mirrors that match it.
#[test]
fn the_package_installs_offline_with_its_command_and_description() {
    let Some(python) = python("import pip", "pip", true) else {
        return;
    };
    let dir = install(&python);
    let site = dir.path().join("site");
    assert!(site.join("bin/motion-client").exists(), "no console script");
    assert!(site.join("motion_supervisor_client/layout.json").exists());
    let mut cmd = Command::new(&python);
    cmd.args(["-m", "motion_supervisor_client.check"])
        .env("PYTHONPATH", &site)
        .current_dir(dir.path());
    let out = Running::start(&mut cmd, "check").finish();
    out.expect_code(0);
    assert!(
        out.stdout.contains("match the Rust layout"),
        "{}",
        out.stdout
    );
}

/// The installed package against the real daemon: `motion-client` reads the
/// status and homes an axis, enables it, moves and jogs it, resets it,
/// stops and unhomes it, and `examples/python/stream_sine.py` streams a
/// sine to it through the package.
#[test]
fn the_installed_client_reads_status_homes_and_operates() {
    let Some(python) = python("import iceoryx2, pip", "the iceoryx2 package", false) else {
        return;
    };
    let pkg = install(&python);
    let site = pkg.path().join("site");
    let _serial = serial();
    // a Python program descheduled for more than 50 ms on a busy CI
    // machine would (rightly) have its stream stopped: 300 ms here
    let cfg = Machine::fixture("two_buses")
        .set("axis.X.stream_timeout_ms", 300)
        .write("py");
    let d = Daemon::start(&cfg, &["bus0", "bus1"]);
    let run = |program: &Path, args: &[&str]| {
        let mut cmd = Command::new(program);
        cmd.args(args)
            .env("PYTHONPATH", &site)
            .current_dir(pkg.path());
        Running::start(&mut cmd, "python").finish()
    };
    let python_path = Path::new(&python);
    let client = |args: &[&str]| {
        let mut all = vec!["-m", "motion_supervisor_client"];
        all.extend_from_slice(args);
        run(python_path, &all)
    };
    // the console script
    let out = run(
        &site.join("bin/motion-client"),
        &["--prefix", &cfg.prefix, "--home", "X"],
    );
    out.expect_code(0);
    assert!(out.stdout.contains("io bus0: attached"), "{}", out.stdout);
    assert!(out.stdout.contains("X: homed: PC 1"), "{}", out.stdout);
    assert!(out.stdout.contains("event_raw -7.500000"), "{}", out.stdout);
    assert!(d.axis("X").pc);

    // the operations
    let p = cfg.prefix.as_str();
    client(&["--prefix", p, "--enable", "X"]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || d
        .axis("X")
        .servo_action));
    let out = client(&["--prefix", p, "--move", "X", "--to", "2.5"]);
    out.expect_code(0);
    assert!(out.stdout.contains("X: PC 1 ER 0"), "{}", out.stdout);
    assert_close!(d.axis("X"), position, 2.5, 2.0 * COUNT);
    let out = client(&["--prefix", p, "--jog", "X", "--speed", "-2", "--for", "0.5"]);
    out.expect_code(0);
    let x = d.axis("X");
    assert!(value(x.position, "X") < 2.0 && !x.jogging, "{x:#?}");
    client(&["--prefix", p, "--reset", "X"]).expect_code(0);
    // redefine position through the package: +10, nothing moves, and back
    let x = d.axis("X");
    let out = client(&["--prefix", p, "--redefine", "X", "--by", "10"]);
    assert!(
        out.expect_code(0).stdout.contains("redefine: X"),
        "{}",
        out.stdout
    );
    assert!(wait_for(Duration::from_secs(5), || d.axis("X").op_kind == "redefine"));
    let y = d.axis("X");
    assert_close!(y, position, value(x.position, "X") + 10.0, COUNT);
    assert_close!(y, raw, value(x.raw, "X"), COUNT);
    let back = format!("{}", value(x.cmd_position, "X"));
    client(&["--prefix", p, "--redefine", "X", "--to", &back]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || (value(
        d.axis("X").cmd_position,
        "X"
    ) - value(
        x.cmd_position,
        "X"
    ))
    .abs()
        < 1e-9));
    // registration: armed and disarmed in place, a bad window refused
    let arm = format!(
        "import sys\n\
         from motion_supervisor_client import Supervisor, accepted, refusals\n\
         s = Supervisor({p:?})\n\
         assert accepted(s.arm('X', edge='falling', window=(-100.0, 100.0)))\n\
         print('refused', refusals(s.arm('X', window=(2.0, 1.0))))\n\
         sys.stdout.flush()\n"
    );
    let out = run(python_path, &["-c", &arm]);
    out.expect_code(0);
    assert!(out.stdout.contains("refused [('X', "), "{}", out.stdout);
    assert!(out.stdout.contains(", 1022, 4)]"), "{}", out.stdout);
    assert!(wait_for(Duration::from_secs(5), || d
        .axis("X")
        .registration_armed));
    let disarm = format!(
        "from motion_supervisor_client import Supervisor, accepted\n\
         assert accepted(Supervisor({p:?}).disarm(['X']))\n"
    );
    run(python_path, &["-c", &disarm]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || !d
        .axis("X")
        .registration_armed));
    // gear() through the package: Y (unhomed) follows X until stopped
    client(&["--prefix", p, "--enable", "Y"]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || d
        .axis("Y")
        .servo_action));
    let gear = format!(
        "from motion_supervisor_client import Supervisor, accepted, refusals\n\
         r = Supervisor({p:?}).gear('Y', master='X', ratio=-0.5, clutch=50)\n\
         print('gear', accepted(r), refusals(r))"
    );
    let out = run(python_path, &["-c", &gear]);
    out.expect_code(0);
    assert!(out.stdout.contains("gear True []"), "{}", out.stdout);
    assert!(d.axis("Y").gearing);
    client(&["--prefix", p, "--stop", "Y"]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || !d.axis("Y").gearing));
    // the stream through the package: a sine of amplitude 1 from where X stands
    let x0 = value(d.axis("X").position, "X");
    let sine = Path::new(EXAMPLES_DIR).join("stream_sine.py");
    let sine = sine.to_str().expect("a UTF-8 path");
    let out = run(
        python_path,
        &[
            sine,
            "--prefix",
            p,
            "--axis",
            "X",
            "--amplitude",
            "1",
            "--hz",
            "0.5",
            "--seconds",
            "2",
        ],
    );
    out.expect_code(0);
    assert!(out.stdout.contains("X: ER 0"), "{}", out.stdout);
    // after 2 s of a 0.5 Hz (1 − cos): back where it started
    let x = d.axis("X");
    assert!((value(x.position, "X") - x0).abs() < 0.01, "{x:#?} vs {x0}");
    assert!(x.owner.is_none() && !x.streaming, "{x:#?}");
    // stop and unhome
    client(&["--prefix", p, "--stop", "X"]).expect_code(0);
    let out = client(&["--prefix", p, "--unhome", "X"]);
    out.expect_code(0);
    assert!(out.stdout.contains("unhome: X"), "{}", out.stdout);
    assert!(wait_for(Duration::from_secs(5), || !d.axis("X").homed));
    // and without a supervisor: exit 3
    client(&["--prefix", "nobody_here"]).expect_code(3);
    d.stop();
    assert_clean(&cfg.prefix);
}

/// Through the package, a program whose setpoint timestamps claim an hour
/// from p0 to p0 + 15 and then 1 ms at rest there (`python/tests/
/// stream_clock.py`): on the cycle's timeline 15 units in one cycle. The
/// axis follows nothing of it faster or harder than its limits
/// (stream_acceleration 1000 allows 0.06 in 11 ms from rest): it cannot
/// follow within them, so the stream is refused (1019 / 4) before its
/// command moved.
#[test]
fn a_python_program_cannot_buy_speed_with_its_timestamps() {
    let Some(python) = python("import iceoryx2, pip", "the iceoryx2 package", false) else {
        return;
    };
    let pkg = install(&python);
    let site = pkg.path().join("site");
    let _serial = serial();
    // X: immediate homing, max_speed 20, stream_acceleration 1000
    // stream_timeout_ms 1000: a Python descheduled between its setpoints
    // on a loaded machine must not read as silence (not the subject here)
    let cfg = Machine::fixture("ops")
        .set("axis.X.stream_acceleration", 1000.0)
        .set("axis.X.stream_timeout_ms", 1000)
        .write("py_clock");
    let d = Daemon::start(&cfg, &["io"]);
    d.ctl(&["home", "X"]).expect_code(0);
    d.ctl(&["enable", "X"]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || {
        let x = d.axis("X");
        x.homed && x.servo_action
    }));
    let script = Path::new(PACKAGE_DIR).join("tests/stream_clock.py");
    let mut cmd = Command::new(&python);
    cmd.arg(&script)
        .args(["--prefix", &cfg.prefix, "--axis", "X", "--distance", "15"])
        .env("PYTHONPATH", &site)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .current_dir(pkg.path());
    let out = Running::start(&mut cmd, "stream_clock.py").finish();
    out.expect_code(0);
    let r: serde_json::Value = serde_json::from_str(out.stdout.trim()).expect("one JSON line");
    assert_eq!(r["acquired"], true, "{r}");
    assert_eq!(
        (r["err"].as_u64(), r["exerr"].as_u64()),
        (Some(1019), Some(4)),
        "{r}"
    );
    assert_eq!(r["streaming"], false, "{r}");
    let moved = r["largest_excursion"].as_f64().expect("a number");
    assert!(moved <= 2.0 * COUNT, "the command moved {moved}: {r}");
    d.ctl(&["reset", "X"]).expect_code(0);
    d.stop();
    assert_clean(&cfg.prefix);
}
