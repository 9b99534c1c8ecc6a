use super::*;
use crate::{parse, DEMO_TOML};

/// A machine every key can be set in: an axis `X` homing on its switch
/// (with a marker and limit switches), a gantry `Y` of two more, a rotary
/// `C`, an `[opcua]` section with a user — and, for an EtherCAT key, `X` on
/// an EtherCAT I/O process of its own.
fn base(ethercat: bool) -> toml::Table {
    const HASH: &str = "$argon2id$v=19$m=19456,t=2,p=1$c29tZXNhbHRzb21lc2FsdA$\
                        qDYw3NfO0x0l5w5Np4r3b7g8kD9n5fZ3yq1u2qvXq0o";
    let homing = "home_sequence = \"switch\"\nhome_speed = 10.0\nhome_return_speed = 1.0\n\
                  home_acceleration = 100.0\nhome_deceleration = 100.0\n";
    let sim = "[axis.sim]\nswitch = [0.0, 5.0]\n";
    let (ios, x_io, others) = if ethercat {
        (
            "[[io]]\nname = \"bus0\"\nbackend = \"ethercat\"\ninterface = \"eth9\"\n\
             [[io]]\nname = \"sim0\"\n",
            "io = \"bus0\"\nethercat_position = 0\n",
            "io = \"sim0\"\n",
        )
    } else {
        ("[[io]]\nname = \"bus0\"\n", "", "")
    };
    format!(
        "[supervisor]\n{ios}\
         [[axis]]\nname = \"X\"\n{x_io}marker = true\n{homing}\
         {sim}marker_every = 10.0\nlimit_switches = [-100.0, 100.0]\n\
         [[axis]]\nname = \"Y1\"\n{others}{homing}{sim}\
         [[axis]]\nname = \"Y2\"\n{others}{homing}{sim}\
         [[axis]]\nname = \"C\"\n{others}\
         [[gantry]]\nname = \"Y\"\naxes = [\"Y1\", \"Y2\"]\n\
         [opcua]\n[[opcua.user]]\nname = \"op\"\nrole = \"viewer\"\npassword_hash = \"{HASH}\"\n"
    )
    .parse()
    .expect("the base machine is TOML")
}

/// The table of `section` in `machine` (its first, for an array).
fn section_of(machine: &mut toml::Table, section: Section) -> &mut toml::Table {
    let path: &[&str] = match section {
        Section::Top => &[],
        Section::Supervisor => &["supervisor"],
        Section::Io => &["io"],
        Section::Axis => &["axis"],
        Section::AxisSim => &["axis", "sim"],
        Section::Gantry => &["gantry"],
        Section::Opcua => &["opcua"],
        Section::OpcuaUser => &["opcua", "user"],
    };
    let mut t = machine;
    for name in path {
        t = match t.get_mut(*name).expect("in the base machine") {
            toml::Value::Table(inner) => inner,
            toml::Value::Array(a) => a[0].as_table_mut().expect("an array of tables"),
            _ => unreachable!(),
        };
    }
    t
}

/// Every key the table declares is one the parser reads: its example, set
/// in a machine (replacing the value there), is never "unknown"; a current
/// key's example makes no problem named by the key, a refused key's one.
#[test]
fn every_declared_key_is_read() {
    let mut failures = Vec::new();
    for key in all() {
        if key.section == Section::Top || matches!(key.kind, Kind::Table | Kind::Tables) {
            continue;
        }
        let mut machine = base(key.only == Only::Ethercat);
        let value: toml::Table = format!("v = {}", key.example).parse().unwrap();
        let t = section_of(&mut machine, key.section);
        t.insert(key.name.to_string(), value["v"].clone());
        if key.name == "ethercat_name" {
            t.remove("ethercat_position");
        }
        let text = toml::to_string(&machine).unwrap();
        let problems = parse(&text).err().unwrap_or_default();
        let named: Vec<String> = problems
            .iter()
            .filter(|p| p.key.ends_with(&format!(".{}", key.name)) || p.key == key.name)
            .map(|p| p.to_string())
            .collect();
        // What the example implies for other keys (a cyclic axis needs an
        // unwind) may be a problem of theirs, never of the key itself; a
        // file that no longer parses, or an unknown key, is always wrong.
        let broken = problems
            .iter()
            .any(|p| p.message.starts_with("TOML syntax") || p.message.contains("unknown key"));
        let ok = !broken
            && match key.status {
                Status::Refused(_) => !named.is_empty(),
                Status::Current => named.is_empty(),
                _ => true,
            };
        if !ok {
            failures.push(format!(
                "{} = {}: {problems:?}",
                key.qualified(),
                key.example
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A key that is not declared is unknown wherever it is written.
#[test]
fn an_undeclared_key_is_unknown() {
    let text = format!("{DEMO_TOML}\n[opcua]\nspeed_of_light = 1\n");
    let p = parse(&text).unwrap_err();
    assert_eq!(p.len(), 1, "{p:?}");
    assert_eq!(p[0].key, "opcua.speed_of_light");
    assert!(p[0].message.starts_with("unknown key"));
}

/// Each example is a value of the key's type inside its bounds, and each
/// row says what the key does.
#[test]
fn every_row_is_complete_and_its_example_fits() {
    for key in all() {
        let q = key.qualified();
        assert!(!key.meaning.is_empty(), "{q}: no meaning");
        assert!(!key.example.is_empty(), "{q}: no example");
        let v: toml::Value = format!("x = {}", key.example)
            .parse::<toml::Table>()
            .unwrap_or_else(|e| panic!("{q}: example {}: {e}", key.example))["x"]
            .clone();
        let number = v.as_float().or(v.as_integer().map(|i| i as f64));
        let fits = match key.kind {
            Kind::Integer => v.is_integer(),
            Kind::Number => number.is_some(),
            Kind::Bool => v.is_bool(),
            Kind::Text => v.is_str(),
            Kind::Choice(names) => v.as_str().is_some_and(|s| names().contains(&s)),
            Kind::ChoiceList(names) => v.as_array().is_some_and(|a| {
                a.iter()
                    .all(|e| e.as_str().is_some_and(|s| names().contains(&s)))
            }),
            Kind::Interval => v.as_array().is_some_and(|a| a.len() == 2),
            Kind::NameList => v.as_array().is_some_and(|a| a.iter().all(|e| e.is_str())),
            Kind::NameMap(names) => v.as_table().is_some_and(|t| {
                t.values()
                    .all(|e| e.as_str().is_some_and(|s| names().contains(&s)))
            }),
            Kind::Table => v.is_table(),
            Kind::Tables => v.as_array().is_some_and(|a| a.iter().all(|e| e.is_table())),
        };
        assert!(
            fits,
            "{q}: example {} is not a {}",
            key.example,
            key.kind.describe()
        );
        if let (Some(x), Bounds::Range(..) | Bounds::AboveZero(_) | Bounds::AtMost(_)) =
            (number, key.bounds)
        {
            let (lo, hi) = key.range_of();
            let above = !matches!(key.bounds, Bounds::AboveZero(_)) || x > 0.0;
            assert!(
                lo <= x && x <= hi && above,
                "{q}: example {x} outside its bounds"
            );
        }
        if let Kind::Choice(names) = key.kind {
            if let Default::Text(d) = key.default {
                assert!(names().contains(&d), "{q}: default {d} is not a choice");
            }
        }
    }
}

/// One row per key and section; an alias or a replacement names a key of
/// the same section.
#[test]
fn keys_are_declared_once() {
    let keys: Vec<&Key> = all().collect();
    for (i, k) in keys.iter().enumerate() {
        assert!(
            !keys[..i]
                .iter()
                .any(|o| o.section == k.section && o.name == k.name),
            "{} declared twice",
            k.qualified()
        );
        if let Status::Alias(of) = k.status {
            assert!(
                find(k.section, of).is_some(),
                "{}: alias of {of}?",
                k.qualified()
            );
        }
    }
}

/// The defaults the rows state are the ones a parsed machine has.
#[test]
fn stated_defaults_are_the_parsed_ones() {
    let m = parse("[[axis]]\nname = \"X\"\n").unwrap();
    let (s, a) = (&m.supervisor, &m.axes[0]);
    assert_eq!(f64::from(s.cycle_us), supervisor::CYCLE_US.default_f64());
    assert_eq!(s.cpu as f64, supervisor::CPU.default_f64());
    assert_eq!(f64::from(s.priority), supervisor::PRIORITY.default_f64());
    assert_eq!(s.service_prefix, supervisor::SERVICE_PREFIX.default_text());
    assert_eq!(
        s.feedback_timeout_ms,
        supervisor::FEEDBACK_TIMEOUT_MS.default_f64()
    );
    assert_eq!(s.io_cpu, None, "{}", supervisor::IO_CPU.meaning);
    let e = &a.engine;
    let d = motion_homing::AxisConfig::default();
    assert_eq!(e.torque_limit, axis::TORQUE_LIMIT.default_f64());
    assert_eq!(
        d.torque_limit,
        axis::TORQUE_LIMIT.default_f64(),
        "the engine's own default"
    );
    assert_eq!(d.enable_timeout, axis::ENABLE_TIMEOUT.default_f64());
    assert_eq!(d.max_position, axis::MAX_POSITION.default_f64());
    assert_eq!(e.home_sequence.name(), axis::HOME_SEQUENCE.default_text());
    assert_eq!(e.home_direction.name(), axis::HOME_DIRECTION.default_text());
    assert_eq!(
        e.stream_timeout_ns as f64,
        operations::STREAM_TIMEOUT_MS.default_f64() * 1e6
    );
    assert_eq!(a.sim, motion_plant::PlantConfig::default());
    assert_eq!(m.ios[0].backend.name(), io::BACKEND.default_text());
}

/// The parser cannot read a key the table does not declare (debug builds).
#[test]
#[should_panic(expected = "not declared there in the key table")]
fn reading_an_undeclared_key_is_a_bug() {
    const SECRET: Key = Key::new(Section::Axis, "secret", Kind::Bool);
    let table: toml::Table = "secret = true".parse().unwrap();
    let mut problems = Vec::new();
    let mut r = crate::keys::Reader::new(&table, Some("X"), Section::Axis, &mut problems);
    r.bool(&SECRET);
}

/// A key of another section cannot be read from this one (debug builds).
#[test]
#[should_panic(expected = "not declared there in the key table")]
fn reading_another_sections_key_is_a_bug() {
    let table: toml::Table = "cycle_us = 1000".parse().unwrap();
    let mut problems = Vec::new();
    let mut r = crate::keys::Reader::new(&table, None, Section::Axis, &mut problems);
    r.u32_in(&supervisor::CYCLE_US);
}
