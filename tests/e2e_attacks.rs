//! Hostile peers' attacks, reproduced: each must end refused, in a safe stop with
//! a clear code, or in a correct home — never in a wrong reference reported
//! as success, never with anything left in /dev/shm.
//!
//! The other-user cases create a system user `motion-attacker` (when run as
//! root, as CI is) and run this test binary as that user for the attacker's
//! part; they say clearly when they are skipped.

use motion_harness::{assert_close, *};
use motion_report::{CtlHomeReport, ErrorReport, HomeReport};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The attacker's part, run as another user (does nothing otherwise).
const ROLE: &str = "MOTION_ATTACK_ROLE";
const ATTACKER: &str = "motion-attacker";

/// X of the demo machine (`tests/machines/demo_x.toml`): switch then
/// marker, event exactly at -7.5.
fn x_axis(tag: &str) -> TempConfig {
    Machine::fixture("demo_x").write(tag)
}

fn iox_config(file_prefix: &str, root: &str) -> iceoryx2::config::Config {
    use iceoryx2::prelude::*;
    let mut c = iceoryx2::config::Config::default();
    c.global.prefix = FileName::new(file_prefix.as_bytes()).unwrap();
    c.global
        .set_root_path(&iceoryx2::prelude::Path::new(root.as_bytes()).unwrap());
    c
}

/// Attack 1: a process creates the supervisor's services first, in the
/// domains it could guess, with more publishers allowed; it publishes forged
/// commands. The supervisor's domain is drawn at random per start and its
/// services are created exclusively: the squatter reaches nothing, and the
/// reference is the true one.
#[test]
fn squatting_the_services_first_changes_nothing() {
    use iceoryx2::prelude::*;
    let _serial = serial();
    let cfg = x_axis("squat");
    let p = cfg.prefix.clone();
    let root = "/run/motion/";
    let _ = std::fs::create_dir_all(root);
    // Every domain a squatter could name: iceoryx2's default, the old
    // `iox2_<prefix>_` naming, and our naming with a guessed id.
    let mut squatters = Vec::new();
    for (file_prefix, r) in [
        (format!("iox2_{p}_"), "/tmp/iceoryx2/"),
        (format!("{p}.00000000."), root),
    ] {
        let node = NodeBuilder::new()
            .config(&iox_config(&file_prefix, r))
            .create::<ipc::Service>()
            .unwrap();
        let mut pubs = Vec::new();
        for topic in [format!("{p}/io/io/command"), format!("{p}/command")] {
            let svc = node
                .service_builder(&ServiceName::new(&topic).unwrap())
                .publish_subscribe::<motion_frames::CommandFrame>()
                .max_publishers(8)
                .max_subscribers(8)
                .create()
                .unwrap();
            let publisher = svc.publisher_builder().create().unwrap();
            pubs.push((svc, publisher));
        }
        squatters.push((node, pubs));
    }
    // Forged commands: move 13 units, enabled.
    type Squat = Vec<(
        Node<ipc::Service>,
        Vec<(
            iceoryx2::service::port_factory::publish_subscribe::PortFactory<
                ipc::Service,
                motion_frames::CommandFrame,
                (),
            >,
            iceoryx2::port::publisher::Publisher<ipc::Service, motion_frames::CommandFrame, ()>,
        )>,
    )>;
    let forge = |squatters: &Squat| {
        for (_, pubs) in squatters {
            for (_, publisher) in pubs {
                let mut f = motion_frames::CommandFrame::ZERO;
                f.header.layout_version = motion_frames::LAYOUT_VERSION;
                f.header.axis_count = 1;
                f.axes[0].target_position = -13_000;
                f.axes[0].control_word = motion_frames::CW_ENABLE;
                let _ = publisher.send_copy(f);
            }
        }
    };
    forge(&squatters);
    let cfg_path = cfg.arg().to_string();
    let homing = std::thread::spawn(move || supervisor(&["home", "--json", "--config", &cfg_path]));
    let until = Instant::now() + Duration::from_secs(60);
    while !homing.is_finished() && Instant::now() < until {
        forge(&squatters);
        std::thread::sleep(Duration::from_millis(1));
    }
    let run = homing.join().unwrap();
    let v: HomeReport = run.expect_code(0).report();
    assert_close!(named(&v.axes, "X"), event_raw, -7.5, COUNT);
    assert_eq!(
        v.run.io[0].frames_refused, 0,
        "nothing forged even reached it"
    );
    for (_, pubs) in &squatters {
        for (svc, _) in pubs {
            assert_eq!(
                svc.dynamic_config().number_of_subscribers(),
                0,
                "nobody subscribed to a squatted service"
            );
        }
    }
    drop(squatters);
    // The squatter's own leftovers (its domains' node counters).
    motion_ipc::cleanup_stale_domains(&p, std::path::Path::new(root));
    for f in std::fs::read_dir("/dev/shm").unwrap().flatten() {
        if f.file_name()
            .to_string_lossy()
            .starts_with(&format!("iox2_{p}_"))
        {
            let _ = std::fs::remove_file(f.path());
        }
    }
    assert_clean(&p);
}

/// Attack 2: motion-io waiting for its supervisor (io = "external") is fed
/// forged commands — first in a domain it never joined, then in its real
/// domain without the session key. Neither moves the axis; the refusals are
/// counted and reported.
#[test]
fn forged_commands_never_move_an_axis() {
    let _serial = serial();
    let cfg = x_axis("forge");
    let p = cfg.prefix.clone();
    let io = spawn_io(&["--config", cfg.arg()]);
    let waiting = io.wait_line("waiting for the supervisor", Duration::from_secs(10));
    assert!(waiting.is_some(), "{}", io.stderr());
    // A forger with no session: motion-io has not even created a node.
    std::thread::sleep(Duration::from_millis(500));
    assert!(motion_ipc::Domain::shm_files_of_prefix(&p).is_empty());

    // The real session (played by this test), and a forger who knows the
    // domain but not the key and got to the command topic first.
    let real = motion_ipc::Domain::establish(&p, None).unwrap();
    let mut forged_domain = real.clone();
    forged_domain.key = [0xdead, 0xbeef];
    let node = forged_domain.create_node("forger").unwrap();
    let mut ports = motion_ipc::SupervisorPorts::create(&node, &forged_domain, "io").unwrap();
    assert!(io
        .wait_line("backend sim", Duration::from_secs(10))
        .is_some());
    for _ in 0..300 {
        let _ = ports.send(|f| {
            f.header.axis_count = 1;
            f.axes[0].target_position = 89_650; // 89.65 units
            f.axes[0].control_word = motion_frames::CW_ENABLE;
            f.axes[0].torque_limit_positive = 100.0;
            f.axes[0].torque_limit_negative = 100.0;
        });
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(
        io.wait_line("does not carry this session's key", Duration::from_secs(5))
            .is_some(),
        "refusal not reported: {}",
        io.stderr()
    );
    // Nothing was answered: every forged frame was refused.
    assert!(ports.receive_latest().unwrap().is_none());
    drop(ports);

    // The axis never moved: ask with the real key, on the same services
    // (motion-io holds them), with raw iceoryx2 ports.
    use iceoryx2::prelude::*;
    let names = motion_ipc::IoServiceNames::new(&p, "io");
    let cmd = node
        .service_builder(&ServiceName::new(&names.command).unwrap())
        .publish_subscribe::<motion_frames::CommandFrame>()
        .open()
        .unwrap();
    let fbk = node
        .service_builder(&ServiceName::new(&names.feedback).unwrap())
        .publish_subscribe::<motion_frames::FeedbackFrame>()
        .open()
        .unwrap();
    let ev = node
        .service_builder(&ServiceName::new(&names.command_ready).unwrap())
        .event()
        .open()
        .unwrap();
    let publisher = cmd.publisher_builder().create().unwrap();
    let subscriber = fbk.subscriber_builder().create().unwrap();
    let notifier = ev.notifier_builder().create().unwrap();
    let mut answer = None;
    for seq in 1..=500u64 {
        let mut f = motion_frames::CommandFrame::ZERO;
        f.header.layout_version = motion_frames::LAYOUT_VERSION;
        f.header.axis_count = 1;
        f.header.sequence = seq;
        f.header.key = real.key;
        f.axes[0].target_position = -20_000;
        let _ = publisher.send_copy(f);
        let _ = notifier.notify();
        std::thread::sleep(Duration::from_millis(2));
        if let Ok(Some(s)) = subscriber.receive() {
            answer = Some(s.payload().axes[0].position);
            break;
        }
    }
    assert_eq!(
        answer,
        Some(-20_000),
        "the axis is where it started: -20 units"
    );
    drop((publisher, subscriber, notifier, cmd, fbk, ev, node));
    io.stop();
    real.withdraw();
    let _ = motion_ipc::cleanup_domain(&real);
    assert_clean(&p);
}

// ---------------------------------------------------------------------------
// Another local user
// ---------------------------------------------------------------------------

/// Creates the attacker user; false, with `SKIPPED: …` printed, where
/// it cannot (not root).
fn attacker_user() -> bool {
    match create_attacker_user() {
        Ok(()) => true,
        Err(why) => {
            eprintln!("SKIPPED: another-user attacks need root to create a user ({why})");
            false
        }
    }
}

fn create_attacker_user() -> Result<(), String> {
    if !nix::unistd::geteuid().is_root() {
        return Err("not running as root".into());
    }
    let exists = Command::new("id")
        .arg(ATTACKER)
        .output()
        .is_ok_and(|o| o.status.success());
    if !exists {
        let out = Command::new("useradd")
            .args([
                "--system",
                "--no-create-home",
                "--shell",
                "/usr/sbin/nologin",
                ATTACKER,
            ])
            .output()
            .map_err(|e| format!("useradd: {e}"))?;
        if !out.status.success() {
            return Err(format!("useradd: {}", String::from_utf8_lossy(&out.stderr)));
        }
    }
    Ok(())
}

/// Runs this test binary's `attacker_part` as the attacker user with `env`.
fn as_attacker(env: &[(&str, String)]) -> String {
    let exe = std::env::current_exe().unwrap();
    let mut cmd = Command::new("runuser");
    cmd.args(["-u", ATTACKER, "--"])
        .arg(&exe)
        .args([
            "--exact",
            "attacker_part",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(ROLE, "attacker");
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().expect("runuser");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "attacker part failed: {text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    text
}

/// What another user can do to a running supervisor's files. Prints one
/// `RESULT <what> <outcome>` line per attempt.
#[test]
fn attacker_part() {
    if std::env::var(ROLE).as_deref() != Ok("attacker") {
        return;
    }
    let prefix = std::env::var("PREFIX").unwrap();
    let runtime = PathBuf::from(std::env::var("RUNTIME").unwrap());
    let result = |what: &str, outcome: String| println!("RESULT {what} {outcome}");
    // The session file (the key).
    result(
        "read_session",
        match std::fs::read(runtime.join(format!("{prefix}.session"))) {
            Ok(_) => "OPENED".into(),
            Err(e) => format!("refused:{:?}", e.kind()),
        },
    );
    // Every file of the domain in /dev/shm: open for writing, truncate.
    let files = motion_ipc::Domain::shm_files_of_prefix(&prefix);
    result("shm_files_visible", files.len().to_string());
    let mut opened = 0;
    for f in &files {
        if std::fs::OpenOptions::new()
            .write(true)
            .open(Path::new("/dev/shm").join(f))
            .is_ok()
        {
            opened += 1;
        }
    }
    result("shm_files_opened_for_writing", opened.to_string());
    // A node in the supervisor's domain (its id is in the file names).
    let id = files
        .first()
        .and_then(|f| f[prefix.len() + 1..].split('.').next().map(str::to_string))
        .unwrap_or_default();
    let d = motion_ipc::Domain {
        prefix: prefix.clone(),
        runtime_dir: runtime.clone(),
        id,
        key: [0; 2],
        pid: 1,
    };
    result(
        "create_node",
        match d.create_node("attacker") {
            Ok(_) => "OPENED".into(),
            Err(e) => format!(
                "refused:{}",
                e.to_string()
                    .replace(' ', "_")
                    .chars()
                    .take(60)
                    .collect::<String>()
            ),
        },
    );
    // The same without our checks: iceoryx2 itself, in that domain.
    let raw = iceoryx2::prelude::NodeBuilder::new()
        .config(&iox_config(
            &d.file_prefix(),
            &format!("{}/", runtime.display()),
        ))
        .create::<iceoryx2::prelude::ipc::Service>();
    result(
        "create_node_raw",
        match raw {
            Ok(_) => "OPENED".into(),
            Err(e) => format!("refused:{e:?}"),
        },
    );
    result(
        "runtime_dir_listing",
        match std::fs::read_dir(&runtime) {
            Ok(_) => "OPENED".into(),
            Err(e) => format!("refused:{:?}", e.kind()),
        },
    );
}

/// Attacks 3 and 4 by another user: read the key, open or truncate the
/// domain's shared memory (the node counter iceoryx2 makes 0666 included),
/// attach subscribers. Everything is refused, and homing is exact.
#[test]
fn another_user_can_open_nothing_of_a_running_supervisor() {
    if !attacker_user() {
        return;
    }
    let _serial = serial();
    let cfg = x_axis("otheruser");
    let p = cfg.prefix.clone();
    let d = Daemon::start(&cfg, &["io"]);
    let out = as_attacker(&[("PREFIX", p.clone()), ("RUNTIME", "/run/motion".into())]);
    let get = |what: &str| {
        let tag = format!("RESULT {what} ");
        out.lines()
            .find_map(|l| l.find(&tag).map(|i| l[i + tag.len()..].to_string()))
            .unwrap_or_else(|| panic!("no {what} in {out}"))
    };
    assert!(get("read_session").starts_with("refused"), "{out}");
    assert!(
        get("shm_files_visible").parse::<u32>().unwrap() > 0,
        "{out}"
    );
    assert_eq!(get("shm_files_opened_for_writing"), "0", "{out}");
    assert!(get("create_node").starts_with("refused"), "{out}");
    assert!(get("create_node_raw").starts_with("refused"), "{out}");
    assert!(get("runtime_dir_listing").starts_with("refused"), "{out}");
    // The daemon is unharmed: X homes exactly.
    let r = d.ctl(&["home", "X", "--json"]);
    let v: CtlHomeReport = r.expect_code(0).report();
    assert_close!(named(&v.axes, "X"), event_raw, -7.5, COUNT);
    d.stop();
    assert_clean(&p);
}

/// Attack 4, the directory: a runtime directory another user created first
/// (or that others may write) is refused with a clear message.
#[test]
fn a_runtime_dir_another_user_created_is_refused() {
    if !attacker_user() {
        return;
    }
    let _serial = serial();
    let dir = format!("/tmp/mra{}", std::process::id() % 100_000);
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new("runuser")
        .args(["-u", ATTACKER, "--", "mkdir", "-m", "0777", &dir])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cfg = x_axis("squatdir");
    let run = supervisor(&[
        "home",
        "--json",
        "--config",
        cfg.arg(),
        "--runtime-dir",
        &dir,
    ]);
    let v: ErrorReport = run.expect_code(1).report();
    let msg = &v.errors[0].message;
    assert!(msg.contains("belongs to uid"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
    assert_clean(&cfg.prefix);
}

/// Attack 1, the same user: a second supervisor under the same prefix is
/// refused while the first runs; the first keeps running.
#[test]
fn a_second_supervisor_under_the_same_prefix_is_refused() {
    let _serial = serial();
    let cfg = x_axis("twice");
    let d = Daemon::start(&cfg, &["io"]);
    let run = supervisor(&["run", "--json", "--duration", "1", "--config", cfg.arg()]);
    run.expect_code(1);
    assert!(run.stdout.contains("already runs"), "{}", run.stdout);
    assert!(d.status().io[0].attached);
    d.stop();
    assert_clean(&cfg.prefix);
}

// ---------------------------------------------------------------------------
// Configuration and arguments (attacks 6–11)
// ---------------------------------------------------------------------------

/// Every hostile config is refused by `check` and by `home` before anything
/// starts: exit 2, the key named, one JSON object with `--json`, nothing
/// echoed raw, nothing in /dev/shm.
#[test]
fn hostile_configs_are_refused_by_key_before_anything_starts() {
    let _serial = serial();
    let axis_with = |extra: &str, sim: &str| {
        let switch = if sim.contains("switch") {
            ""
        } else {
            "switch = [0.0, 5.0]\n"
        };
        let speed = if extra.contains("home_speed") {
            ""
        } else {
            "home_speed = 10.0\n"
        };
        let acc = if extra.contains("home_acceleration") {
            ""
        } else {
            "home_acceleration = 100.0\n"
        };
        format!(
            "[[axis]]\nname = \"X\"\nhome_sequence = \"switch\"\n{speed}{acc}\
             home_return_speed = 1.0\nhome_deceleration = 100.0\n\
             {extra}\n[axis.sim]\n{switch}{sim}\n"
        )
    };
    let long_name = "n".repeat(100_000);
    let cases: Vec<(String, String, &str)> = vec![
        (String::new(), axis_with("", "start = nan"), "sim.start"),
        (
            String::new(),
            axis_with("", "switch = [inf, -inf]"),
            "sim.switch",
        ),
        (
            String::new(),
            axis_with("", "marker_every = nan"),
            "sim.marker_every",
        ),
        (
            String::new(),
            axis_with("", "push_gain = nan"),
            "sim.push_gain",
        ),
        (
            String::new(),
            axis_with("home_speed = 1e308", ""),
            "home_speed",
        ),
        (
            String::new(),
            axis_with("home_acceleration = 1e308", ""),
            "home_acceleration",
        ),
        (
            String::new(),
            axis_with("home_position = 1e308", ""),
            "home_position",
        ),
        (
            String::new(),
            axis_with("counts_per_unit = 1e308", ""),
            "counts_per_unit",
        ),
        (
            String::new(),
            axis_with("counts_per_unit = 1e-300", ""),
            "counts_per_unit",
        ),
        (
            String::new(),
            axis_with("max_position = 1e308", ""),
            "max_position",
        ),
        ("cpu = 99\n".into(), axis_with("", ""), "supervisor.cpu"),
        (
            "cpu = 4294967295\n".into(),
            axis_with("", ""),
            "supervisor.cpu",
        ),
        (
            "io_cpu = 99\n".into(),
            axis_with("", ""),
            "supervisor.io_cpu",
        ),
        (
            "stale_cycles = 4294967295\n".into(),
            axis_with("", ""),
            "supervisor.stale_cycles",
        ),
        (
            "io_watchdog_cycles = 4294967295\n".into(),
            axis_with("", ""),
            "supervisor.io_watchdog_cycles",
        ),
        (
            String::new(),
            "[[axis]]\nname = \"X\\u001b[31m\"\n".into(),
            "name",
        ),
        (
            String::new(),
            "[[axis]]\nname = \"X\\u0000\"\n".into(),
            "name",
        ),
        (
            String::new(),
            "[[axis]]\nname = \"X\\u200b\"\n".into(),
            "name",
        ),
        (
            String::new(),
            format!("[[axis]]\nname = \"{long_name}\"\n"),
            "name",
        ),
    ];
    for (sup, axes, key) in cases {
        let cfg = Machine::parse(&format!("[supervisor]\n{sup}\n{axes}")).write("hostile");
        let path = cfg.arg();
        let run = supervisor(&["check", "--config", path]);
        assert_eq!(run.code(), Some(2), "{key}: {}", run.stderr);
        assert!(run.stderr.contains(key), "{key}: {}", run.stderr);
        assert!(!run.stderr.contains('\u{1b}'), "an escape was echoed");
        assert!(
            run.stderr.len() < 20_000,
            "{key}: {} bytes of stderr",
            run.stderr.len()
        );
        let run = supervisor(&["home", "--json", "--config", path]);
        assert_eq!(run.code(), Some(2), "{key}: {}", run.stdout);
        let v: ErrorReport = run.report();
        assert!(
            (v.errors.iter()).any(|e| e.key.as_deref().is_some_and(|k| k.contains(key))),
            "{key}: {v:#?}"
        );
        assert!(shm_leftovers(&cfg.prefix).is_empty());
    }
}

/// Attacks 8–10: hostile arguments and files. Refused at once (exit 2, a
/// JSON object with --json), no panic, nothing started.
#[test]
fn hostile_arguments_and_files_are_refused_at_once() {
    let _serial = serial();
    let cfg = x_axis("args");
    let path = cfg.arg();
    let home = |extra: &[&'static str]| [&["home", "--json", "--config", path], extra].concat();
    for args in [
        home(&["--timeout", "1e308"]),
        home(&["--timeout", "1e19"]),
        home(&["--service-prefix", "../../tmp/x"]),
        home(&["--service-prefix", "a/b"]),
        home(&["--service-prefix", "x y"]),
        vec!["home", "--json", "--config", "--json"],
        vec!["run", "--json", "--config", path, "--duration", "nan"],
    ] {
        let t = Instant::now();
        let run = supervisor(&args);
        assert_eq!(
            run.code(),
            Some(2),
            "{args:?}: {}\n{}",
            run.stdout,
            run.stderr
        );
        let _: ErrorReport = run.report();
        assert!(t.elapsed() < Duration::from_secs(5));
    }
    // A FIFO and /dev/zero as the config: refused at once, not read forever.
    let dir = TempDir::new("fifo");
    let fifo = dir.file("config.fifo");
    nix::unistd::mkfifo(fifo.as_str(), nix::sys::stat::Mode::S_IRWXU).unwrap();
    for file in [fifo.as_str(), "/dev/zero"] {
        let t = Instant::now();
        let run = supervisor(&["check", "--json", "--config", file]);
        assert_eq!(run.code(), Some(2), "{file}: {}", run.stdout);
        assert!(run.stdout.contains("not a regular file"), "{}", run.stdout);
        assert!(t.elapsed() < Duration::from_secs(5));
    }
    assert!(shm_leftovers(&cfg.prefix).is_empty());
}
