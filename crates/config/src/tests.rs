use super::*;

#[test]
fn demo_parses() {
    let m = parse(DEMO_TOML).unwrap_or_else(|p| panic!("{p:#?}"));
    assert_eq!(m.axes.len(), 4);
    assert_eq!(m.supervisor.cycle_us, 1000);
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["U", "X", "C", "Z"]);
    assert_eq!(m.axes[1].sim.switch, Some((0.0, 5.0)));
    assert_eq!(m.supervisor.feedback_timeout_ms, 10.0);
    assert_eq!(m.ios.len(), 1);
    assert_eq!(m.ios[0].name, "io");
}

#[test]
fn every_mistake_is_reported_with_axis_and_key() {
    let text = r#"
[supervisor]
cycle_us = 0
io = "carrier-pigeon"
colour = "blue"

[[axis]]
name = "X"
home_sequence = "switch"
home_speed = 0.0
home_return_speed = 1.0
home_acceleration = 100.0
home_deceleration = 100.0
home_sped = 3.0

[axis.sim]
switch = [1.0]

[[axis]]
name = "Y"
home_mode = "sideways"
counts_per_unit = "many"
"#;
    let problems = parse(text).unwrap_err();
    let lines: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
    let want = [
        "supervisor.cycle_us: 0 is outside 50..=100000",
        "supervisor.io: \"carrier-pigeon\"",
        "supervisor.colour: unknown key",
        "axis X: home_sped: unknown key",
        "axis X: sim.switch: expected [low, high]",
        "axis X: home_speed: home speed is zero (ERR 41 EXERR 6)",
        "axis Y: home_mode: \"sideways\" is not one of",
        "axis Y: counts_per_unit: expected a number, found string",
    ];
    for w in want {
        assert!(
            lines.iter().any(|l| l.starts_with(w)),
            "missing {w:?} in\n{}",
            lines.join("\n")
        );
    }
}

#[test]
fn duplicate_names_and_syntax_errors() {
    let text = "[[axis]]\nname = \"A\"\n[[axis]]\nname = \"A\"\n";
    let p = parse(text).unwrap_err();
    assert!(p
        .iter()
        .any(|p| p.to_string() == "axis A: name: axis name used twice"));
    let p = parse("[[axis]\n").unwrap_err();
    assert!(p[0].message.starts_with("TOML syntax"));
    assert_eq!(p[0].key, "line 1, column 8", "{}", p[0]);
    let p = parse("[supervisor]\n").unwrap_err();
    assert!(p.iter().any(|p| p.key == "axis"));
}

/// The demo machine homes in simulation (engine + plant, no processes) with
/// the results its comments promise.
#[test]
fn demo_homes_in_simulation() {
    use motion_homing::{Axis, Request};
    use motion_plant::Plant;
    let m = parse(DEMO_TOML).unwrap();
    let want = [
        ("U", 2.0, f64::NAN),
        ("X", -7.5, -7.5),
        ("C", 123.4, 168.4),
        ("Z", -30.0, -28.0),
    ];
    for (a, (name, event, final_raw)) in m.axes.iter().zip(want) {
        assert_eq!(a.name, name);
        let mut axis = Axis::new(a.engine);
        let mut plant = Plant::new(a.sim);
        let mut fb = plant.feedback();
        let req = Request {
            home: true,
            ..Request::default()
        };
        let dt = m.supervisor.cycle_us as f64 * 1e-6;
        let mut k = 0u64;
        while k < 2 || axis.status().ip {
            let cmd = axis.step(k * m.supervisor.cycle_ns(), Some(&fb), &req);
            fb = plant.step(&cmd, dt);
            k += 1;
            assert!(k < 30_000, "{name} did not finish: {:?}", axis.status());
        }
        let s = axis.status();
        assert!(s.pc && s.homed, "{name}: {s:?}");
        assert!((s.event_raw.unwrap() - event).abs() < 1e-9, "{name}: {s:?}");
        if !final_raw.is_nan() {
            for _ in 0..10 {
                let cmd = axis.step(k * m.supervisor.cycle_ns(), Some(&fb), &req);
                fb = plant.step(&cmd, dt);
                k += 1;
            }
            assert!(
                (plant.position() - final_raw).abs() < 1e-9,
                "{name}: {}",
                plant.position()
            );
            assert!(
                axis.axis_position().unwrap().abs() < 1e-9,
                "{name} at Home Position 0"
            );
        }
        eprintln!("{name}: homed in {:.3} s", k as f64 * dt);
    }
}

fn problems_of(text: &str) -> Vec<String> {
    parse(text)
        .map(|_| Vec::new())
        .unwrap_or_else(|p| p.iter().map(|p| p.to_string()).collect())
}

fn has(lines: &[String], want: &str) {
    assert!(
        lines.iter().any(|l| l.contains(want)),
        "missing {want:?} in\n{}",
        lines.join("\n")
    );
}

const ONE_AXIS: &str = "[[axis]]\nname = \"X\"\n";

/// Hostile numbers in a configuration (huge, tiny, NaN, wrong types): every
/// one is a problem naming the key, never a value taken.
#[test]
fn hostile_numbers_are_refused_by_key() {
    let text = r#"
[supervisor]
cpu = 4294967295
io_cpu = 99
stale_cycles = 4294967295
io_watchdog_cycles = 4294967295

[[axis]]
name = "X"
home_sequence = "switch"
home_speed = 1e308
home_return_speed = 1.0
home_acceleration = 1e308
home_deceleration = 100.0
home_position = 1e308
counts_per_unit = 1e-300
max_position = 1e308

[axis.sim]
start = nan
switch = [inf, -inf]
marker_every = nan
push_gain = nan
"#;
    let p = problems_of(text);
    for want in [
        "supervisor.cpu: CPU 4294967295 does not exist",
        "supervisor.io_cpu: CPU 99 does not exist",
        "supervisor.stale_cycles: 4294967295 cycles",
        "supervisor.io_watchdog_cycles: 4294967295 is outside 1..=1000",
        "axis X: home_speed: 1e308 is outside",
        "axis X: home_acceleration: 1e308 is outside",
        "axis X: home_position: 1e308 is outside",
        "axis X: counts_per_unit: 1e-300 is outside",
        "axis X: max_position: 1e308 is outside",
        "axis X: sim.start: NaN is not a finite number",
        "axis X: sim.switch: [inf, -inf]: both ends must be finite",
        "axis X: sim.marker_every: NaN is not a finite number",
        "axis X: sim.push_gain: NaN is not a finite number",
    ] {
        has(&p, want);
    }
}

#[test]
fn counts_must_stay_exact() {
    let p = problems_of(&format!(
        "{ONE_AXIS}counts_per_unit = 1e9\nmax_position = 1e8\n"
    ));
    has(
        &p,
        "axis X: max_position: max_position 100000000 × counts_per_unit",
    );
}

#[test]
fn names_are_printable_and_bounded() {
    // TOML escapes: the name holds a real ESC / zero-width character.
    for bad in ["X\\u001b[31m", "a\\u200bb", "x y", "nul\\u0000"] {
        let p = problems_of(&format!("[[axis]]\nname = \"{bad}\"\n"));
        has(&p, "name: ");
        assert!(p
            .iter()
            .all(|l| !l.contains('\u{1b}') && !l.contains('\u{200b}')));
    }
    let long = "n".repeat(100_000);
    let p = problems_of(&format!("[[axis]]\nname = \"{long}\"\n"));
    assert!(
        p.iter().all(|l| l.len() < 300),
        "a name is never echoed in full"
    );
    let p = problems_of(&format!(
        "[supervisor]\nservice_prefix = \"a/b\"\n{ONE_AXIS}"
    ));
    has(&p, "supervisor.service_prefix: service prefix \"a/b\"");
}

#[test]
fn several_io_processes() {
    let text = r#"
[[io]]
name = "bus0"
spawn = "sim"
cpu = 0
priority = 70

[[io]]
name = "bus1"
spawn = "external"

[[axis]]
name = "X"
io = "bus0"

[[axis]]
name = "Y"
io = "bus1"

[[axis]]
name = "Z"
io = "bus0"
"#;
    let m = parse(text).unwrap_or_else(|p| panic!("{p:#?}"));
    assert_eq!(m.ios.len(), 2);
    assert_eq!(
        (m.ios[0].spawn, m.ios[1].spawn),
        (IoMode::Sim, IoMode::External)
    );
    assert_eq!((m.ios[0].cpu, m.ios[0].priority), (Some(0), 70));
    assert_eq!(m.axes_of(0), vec![0, 2]);
    assert_eq!(m.axes_of(1), vec![1]);
    assert_eq!(m.only_io(1).axes.len(), 1);

    let p = problems_of(
        "[[io]]\nname = \"a\"\n[[io]]\nname = \"b\"\n[[axis]]\nname = \"X\"\n[[axis]]\nname = \"Y\"\nio = \"c\"\n",
    );
    has(&p, "axis X: io: missing");
    has(&p, "axis Y: io: no I/O process \"c\" (configured: a, b)");
    let p = problems_of("[[io]]\nname = \"a.b\"\n[[io]]\nname = \"x\"\n[[io]]\nname = \"x\"\n[[axis]]\nname = \"X\"\nio = \"x\"\n");
    has(&p, "io.name: io #1: \"a.b\"");
    has(&p, "io.name: I/O process name \"x\" used twice");
}

#[test]
fn one_implicit_io_process_without_io_sections() {
    let m = parse(&format!("[supervisor]\nio = \"external\"\n{ONE_AXIS}")).unwrap();
    assert_eq!(m.ios.len(), 1);
    assert_eq!(m.ios[0].name, DEFAULT_IO_NAME);
    assert_eq!(m.ios[0].spawn, IoMode::External);
    assert_eq!(m.axes[0].io, 0);
}

#[test]
fn stale_cycles_is_read_in_milliseconds() {
    let m = parse(&format!(
        "[supervisor]\ncycle_us = 500\nstale_cycles = 8\n{ONE_AXIS}"
    ))
    .unwrap();
    assert_eq!(m.supervisor.feedback_timeout_ms, 4.0);
    assert!(m.warnings.iter().any(|w| w.contains("stale_cycles")));
}

const ECAT_IO: &str = r#"
[[io]]
name = "bus0"
spawn = "supervisor"
backend = "ethercat"
interface = "eth1"
"#;

#[test]
fn ethercat_io_process_and_its_axes() {
    let text = format!(
        r#"{ECAT_IO}dc = "off"
sm_watchdog_ms = 20
reply_timeout_us = 500
startup_timeout_s = 5
mode_in_pdo = true
dc_static_sync_iterations = 0

[[io]]
name = "sim0"

[[axis]]
name = "X"
io = "bus0"
ethercat_position = 0

[[axis]]
name = "Y"
io = "bus0"
ethercat_name = "X5-Servo 2"
ethercat_index_pulse_bit = 17

[[axis]]
name = "V"
io = "bus0"
configuration = "virtual"

[[axis]]
name = "S"
io = "sim0"
"#
    );
    let m = parse(&text).unwrap_or_else(|p| panic!("{p:#?}"));
    let bus = &m.ios[0];
    assert_eq!((bus.spawn, bus.backend), (IoMode::Sim, IoBackend::Ethercat));
    let e = bus.ethercat.as_ref().unwrap();
    assert_eq!(
        *e,
        EthercatIo {
            interface: "eth1".into(),
            dc: EthercatDc::Off,
            sm_watchdog_ms: 20,
            reply_timeout_us: Some(500),
            startup_timeout_s: 5,
            mode_in_pdo: true,
            dc_static_sync_iterations: 0,
            quick_stop_timeout_ms: 500,
        }
    );
    assert_eq!(
        (m.ios[1].backend, &m.ios[1].ethercat),
        (IoBackend::Sim, &None)
    );
    assert_eq!(
        m.axes[0].ethercat,
        Some(AxisEthercat {
            drive: EthercatDrive::Position(0),
            index_pulse_bit: None,
            home_switch_bit: None,
            brake_delay_ms: 0,
            drive_homing_method: None,
        })
    );
    assert_eq!(
        m.axes[1].ethercat,
        Some(AxisEthercat {
            drive: EthercatDrive::Name("X5-Servo 2".into()),
            index_pulse_bit: Some(17),
            home_switch_bit: None,
            brake_delay_ms: 0,
            drive_homing_method: None,
        })
    );
    assert_eq!(m.axes[2].ethercat, None, "virtual: no drive");
    assert_eq!(m.axes[3].ethercat, None);

    // defaults
    let m = parse(&format!(
        "{ECAT_IO}[[axis]]\nname = \"X\"\nethercat_position = 3\n"
    ))
    .unwrap();
    assert_eq!(
        *m.ios[0].ethercat.as_ref().unwrap(),
        EthercatIo {
            interface: "eth1".into(),
            ..EthercatIo::default()
        }
    );
    assert_eq!(m.ios[0].ethercat.as_ref().unwrap().sm_watchdog_ms, 50);
    // without [[io]] nothing changes
    let m = parse(ONE_AXIS).unwrap();
    assert_eq!(
        (m.ios[0].backend, &m.ios[0].ethercat),
        (IoBackend::Sim, &None)
    );
    assert_eq!(m.axes[0].ethercat, None);
}

#[test]
fn ethercat_mistakes_are_reported_by_axis_and_key() {
    let text = r#"
[supervisor]
cycle_us = 2000

[[io]]
name = "bus0"
backend = "ethercat"
interface = "a/very/long/interface"
dc = "sometimes"
sm_watchdog_ms = 5
reply_timeout_us = 1990
startup_timeout_s = 0
dc_static_sync_iterations = 1000000
mode_in_pdo = "yes"

[[io]]
name = "sim0"
spawn = "by-hand"
interface = "eth0"
dc = "on"

[[io]]
name = "bus1"
backend = "profinet"

[[io]]
name = "bus2"
backend = "ethercat"

[[axis]]
name = "A"
io = "bus0"

[[axis]]
name = "B"
io = "bus0"
ethercat_position = 70000
ethercat_index_pulse_bit = 3

[[axis]]
name = "C"
io = "bus0"
ethercat_position = 1
ethercat_name = "drive\u001b[31m"

[[axis]]
name = "D"
io = "sim0"
ethercat_position = 0
ethercat_index_pulse_bit = 16

[[axis]]
name = "E"
io = "bus0"
configuration = "virtual"
ethercat_name = "X"

[[axis]]
name = "F"
io = "bus0"
ethercat_position = 1

[[axis]]
name = "G"
io = "bus2"
ethercat_position = 0
"#;
    let p = problems_of(text);
    for want in [
        "io.interface: I/O process bus0: interface name \"a/very/long/interface\" must be",
        "io.dc: \"sometimes\" is not one of \"auto\", \"on\", \"off\"",
        "io.sm_watchdog_ms: I/O process bus0: 5 ms is shorter than 3 cycles of 2000 µs",
        "io.reply_timeout_us: I/O process bus0: 1990 µs leaves no time in a cycle of 2000 µs",
        "io.startup_timeout_s: 0 is outside 1..=300",
        "io.dc_static_sync_iterations: 1000000 is outside 0..=100000",
        "io.mode_in_pdo: expected true or false, found string",
        "io.spawn: io #2: \"by-hand\" is not one of \"sim\", \"supervisor\", \"external\"",
        "io.interface: I/O process sim0: only for backend = \"ethercat\" (this I/O process has backend = \"sim\")",
        "io.dc: I/O process sim0: only for backend = \"ethercat\"",
        "io.backend: \"profinet\" is not one of \"sim\", \"ethercat\"",
        "io.interface: I/O process bus2: missing: backend = \"ethercat\" needs the network interface",
        "axis A: ethercat_position: missing: an axis of EtherCAT I/O process bus0 names its drive",
        "axis B: ethercat_position: 70000 is outside 0..=65535",
        "axis B: ethercat_index_pulse_bit: 3 is outside 16..=31",
        "axis C: ethercat_name: give ethercat_position or ethercat_name, not both",
        "axis C: ethercat_name: SubDevice name \"drive\\u{1b}[31m\" must be",
        "axis D: ethercat_position: only for an axis of an EtherCAT I/O process (its I/O process sim0 has backend = \"sim\")",
        "axis D: ethercat_index_pulse_bit: only for an axis of an EtherCAT I/O process",
        "axis E: ethercat_name: a virtual axis has no drive",
    ] {
        has(&p, want);
    }
    assert!(p.iter().all(|l| !l.contains('\u{1b}')), "{p:?}");

    // one drive per axis; "unknown key" never doubles a reported one
    let p = problems_of(&format!(
        "{ECAT_IO}[[axis]]\nname = \"X\"\nethercat_position = 1\n\
         [[axis]]\nname = \"Y\"\nethercat_position = 1\n\
         [[axis]]\nname = \"Z\"\nethercat_name = \"N\"\n\
         [[axis]]\nname = \"W\"\nethercat_name = \"N\"\n"
    ));
    has(
        &p,
        "axis Y: ethercat_position: the SubDevice at position 1 already drives axis X",
    );
    has(
        &p,
        "axis W: ethercat_name: the SubDevice at name \"N\" already drives axis Z",
    );
    assert_eq!(p.len(), 2, "{p:#?}");
    let p = problems_of(&format!(
        "[[io]]\nname = \"s\"\ninterface = \"eth0\"\n{ONE_AXIS}ethercat_position = 0\n"
    ));
    assert_eq!(p.len(), 2, "{p:#?}");
    assert!(p.iter().all(|l| !l.contains("unknown key")), "{p:#?}");

    // the bus cycle has a floor
    let p = problems_of(&format!(
        "[supervisor]\ncycle_us = 50\n{ECAT_IO}sm_watchdog_ms = 1\n[[axis]]\nname = \"X\"\nethercat_position = 0\n"
    ));
    has(&p, "io.backend: I/O process bus0: the EtherCAT bus cycles at [supervisor] cycle_us = 50 µs; it needs at least 100 µs");
    // at most 32 drives on one EtherCAT I/O process
    let mut t = ECAT_IO.to_string();
    for i in 0..33 {
        t += &format!("[[axis]]\nname = \"A{i}\"\nethercat_position = {i}\n");
    }
    has(
        &problems_of(&t),
        "io: EtherCAT I/O process bus0 drives 33 axes, at most 32",
    );
}

#[test]
fn the_gantry_example_has_orders_a_gantry_and_an_absolute_axis() {
    let m = parse(GANTRY_TOML).unwrap_or_else(|p| panic!("{p:#?}"));
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["Z", "Y1", "Y2", "X", "W"]);
    let orders: Vec<Option<u32>> = m.axes.iter().map(|a| a.home_order).collect();
    assert_eq!(orders, [Some(0), Some(1), Some(1), Some(1), None]);
    assert_eq!(m.gantries.len(), 1);
    assert_eq!(m.gantries[0].axes, [1, 2]);
    assert_eq!(m.gantry_of(2), Some(0));
    let w = &m.axes[4].engine;
    assert!(w.absolute);
    assert_eq!(w.home_mode, motion_homing::HomeMode::Absolute);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
}

/// Axis X homed where it stands, Home Speed 20, Home Acceleration 400 and
/// Deceleration 500: the base the operation keys are added to.
const IMMEDIATE_X: &str = r#"
[[axis]]
name = "X"
home_sequence = "immediate"
home_speed = 20.0
home_acceleration = 400.0
home_deceleration = 500.0
"#;

/// The keys of the operations: parsed, defaults left to the engine (0),
/// every mistake named by axis and key.
#[test]
fn the_keys_of_the_operations() {
    let base = IMMEDIATE_X;
    let m = parse(base).unwrap_or_else(|p| panic!("{p:#?}"));
    let e = &m.axes[0].engine;
    assert_eq!(
        (e.unhomed_speed, e.max_deceleration, e.stream_acceleration),
        (0.0, 0.0, 0.0),
        "left out: the engine's defaults"
    );
    assert!(e.limit_switches && !e.stream_unhomed);
    assert_eq!(e.stream_timeout_ns, 50_000_000);
    let l = motion_homing::OpLimits::new(e);
    assert_eq!((l.unhomed_speed, l.max_deceleration), (20.0, 500.0));
    assert_eq!(l.stream_acceleration, 4000.0);

    let set = format!(
        "{base}unhomed_speed = 5\nlimit_switches = false\nmax_deceleration = 2000.0\n\
         stream_acceleration = 1e4\nstream_timeout_ms = 20\nstream_unhomed = true\n"
    );
    let m = parse(&set).unwrap_or_else(|p| panic!("{p:#?}"));
    let e = &m.axes[0].engine;
    assert_eq!(e.unhomed_speed, 5.0);
    assert!(!e.limit_switches && e.stream_unhomed);
    assert_eq!((e.max_deceleration, e.stream_acceleration), (2000.0, 1e4));
    assert_eq!(e.stream_timeout_ns, 20_000_000);

    let bad = format!(
        "{base}unhomed_speed = 0\nlimit_switches = 1\nmax_deceleration = -1.0\n\
         stream_acceleration = nan\nstream_timeout_ms = 5000\nstream_unhomed = \"yes\"\n"
    );
    let lines: Vec<String> = parse(&bad)
        .unwrap_err()
        .iter()
        .map(|p| p.to_string())
        .collect();
    for want in [
        "axis X: unhomed_speed: must be above 0 units/s (leave it out for the default: home_speed (20))",
        "axis X: limit_switches: expected true or false, found integer",
        "axis X: max_deceleration: -1 is outside 0 (excluded)..=1000000000 units/s²",
        "axis X: stream_acceleration: NaN is not a finite number",
        "axis X: stream_timeout_ms: 5000 is outside 1..=1000 ms",
        "axis X: stream_unhomed: expected true or false, found string",
    ] {
        assert!(
            lines.iter().any(|l| l.starts_with(want)),
            "missing {want:?} in\n{}",
            lines.join("\n")
        );
    }
    assert_eq!(lines.len(), 6, "{lines:#?}");
}

/// `jerk`: 0 when left out (trapezoids), read when given, refused when
/// negative; a gantry's sides must agree on it (they jog and move alike).
#[test]
fn the_jerk_key() {
    let base = IMMEDIATE_X;
    let m = parse(base).unwrap_or_else(|p| panic!("{p:#?}"));
    assert_eq!(m.axes[0].engine.jerk, 0.0);
    let m = parse(&format!("{base}jerk = 20000.0\n")).unwrap_or_else(|p| panic!("{p:#?}"));
    assert_eq!(m.axes[0].engine.jerk, 20_000.0);
    for bad in ["-1.0", "inf", "2e12"] {
        let lines = problems_of(&format!("{base}jerk = {bad}\n"));
        has(&lines, "axis X: jerk: ");
    }
    let one_side = GANTRY_TOML.replacen("name = \"Y1\"\n", "name = \"Y1\"\njerk = 1000.0\n", 1);
    assert_ne!(one_side, GANTRY_TOML);
    let lines = problems_of(&one_side);
    has(&lines, "axis Y2: jerk: gantry Y: differs from side Y1");
    let both = one_side.replacen("name = \"Y2\"\n", "name = \"Y2\"\njerk = 1000.0\n", 1);
    parse(&both).unwrap_or_else(|p| panic!("{p:#?}"));
}
