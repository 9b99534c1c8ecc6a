use super::*;

#[test]
fn demo_parses() {
    let m = parse(DEMO_TOML).unwrap_or_else(|p| panic!("{p:#?}"));
    assert_eq!(m.axes.len(), 4);
    assert_eq!(m.supervisor.cycle_us, 1000);
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["U", "X", "C", "Z"]);
    assert_eq!(m.axes[1].sim.switch, Some((0.0, 5.0)));
    assert_eq!(m.axes[0].engine.feedback_timeout_ns, 10_000_000);
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
        "supervisor.cycle_us: 0 µs",
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
