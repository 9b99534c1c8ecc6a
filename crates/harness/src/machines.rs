//! The machines of the tests: fixture files (`tests/machines/*.toml`, one
//! per machine that tests share, loaded by name), small stated overrides,
//! and the temporary config a test runs with — its own service prefix and
//! state directory, removed when the test ends.

use std::path::{Path, PathBuf};

use motion_config::MachineConfig;
use toml::{Table, Value};

use crate::unique_prefix;

/// The fixture files, compiled in (a test binary runs from anywhere).
const FIXTURES: &[(&str, &str)] = &[
    (
        "switch",
        include_str!("../../../tests/machines/switch.toml"),
    ),
    (
        "marker",
        include_str!("../../../tests/machines/marker.toml"),
    ),
    (
        "torque",
        include_str!("../../../tests/machines/torque.toml"),
    ),
    (
        "passive",
        include_str!("../../../tests/machines/passive.toml"),
    ),
    (
        "slow_switch",
        include_str!("../../../tests/machines/slow_switch.toml"),
    ),
    (
        "demo_x",
        include_str!("../../../tests/machines/demo_x.toml"),
    ),
    (
        "two_buses",
        include_str!("../../../tests/machines/two_buses.toml"),
    ),
    (
        "unplug",
        include_str!("../../../tests/machines/unplug.toml"),
    ),
    (
        "io_marker",
        include_str!("../../../tests/machines/io_marker.toml"),
    ),
    ("ops", include_str!("../../../tests/machines/ops.toml")),
    (
        "limits",
        include_str!("../../../tests/machines/limits.toml"),
    ),
];

/// `[supervisor]` keys every test machine gets unless it sets them: 1 kHz
/// on CPU 1 at SCHED_FIFO 80, `motion-io` with the sim backend, and a
/// generous feedback bound (several tests run on a small CI machine, and
/// they are about sequences, not about a starved peer). A machine that sets
/// `stale_cycles` bounds the loss that way instead.
const DEFAULTS: [(&str, Default); 5] = [
    ("cycle_us", Default::Int(1000)),
    ("cpu", Default::Int(1)),
    ("priority", Default::Int(80)),
    ("io", Default::Str("sim")),
    ("feedback_timeout_ms", Default::Int(20)),
];

enum Default {
    Int(i64),
    Str(&'static str),
}

/// A machine as a TOML document, before a test writes it.
#[derive(Clone, Debug)]
pub struct Machine {
    doc: Table,
}

impl Machine {
    /// `tests/machines/<name>.toml`.
    #[track_caller]
    pub fn fixture(name: &str) -> Machine {
        let (_, text) = FIXTURES
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("no machine {name:?} in tests/machines"));
        Machine::parse(text)
    }

    /// A machine written out in the test (a one-off, or a config that is
    /// wrong on purpose).
    #[track_caller]
    pub fn parse(text: &str) -> Machine {
        let doc = text
            .parse::<Table>()
            .unwrap_or_else(|e| panic!("not TOML: {e}\n{text}"));
        Machine { doc }
    }

    /// The shipped gantry example (`deploy/gantry.toml`): its I/O, axes and
    /// gantry, without its `[supervisor]` section.
    pub fn gantry() -> Machine {
        Machine::parse(motion_config::GANTRY_TOML).without("supervisor")
    }

    /// Sets one key. `path`: `supervisor.KEY`, `axis.NAME.KEY` or
    /// `io.NAME.KEY` (an entry of `[[axis]]`/`[[io]]` by its name), with
    /// sub-tables by further dots (`axis.S.sim.start`).
    #[track_caller]
    pub fn set(mut self, path: &str, value: impl Into<Value>) -> Machine {
        let (table, key) = self.table_of(path);
        table.insert(key.to_string(), value.into());
        self
    }

    /// Removes one key or table (same paths as [`set`](Self::set)).
    #[track_caller]
    pub fn without(mut self, path: &str) -> Machine {
        let (table, key) = self.table_of(path);
        table.remove(key);
        self
    }

    /// The config text under `prefix`: the machine, the defaults it does not
    /// set, `service_prefix = prefix` and, unless it sets one, `state_dir`.
    pub fn text(&self, prefix: &str, state_dir: &Path) -> String {
        let mut doc = self.doc.clone();
        let sup = doc
            .entry("supervisor")
            .or_insert_with(|| Value::Table(Table::new()))
            .as_table_mut()
            .expect("[supervisor] is a table");
        let bounded = sup.contains_key("stale_cycles");
        for (key, value) in DEFAULTS {
            if key == "feedback_timeout_ms" && bounded {
                continue;
            }
            sup.entry(key).or_insert_with(|| match value {
                Default::Int(i) => Value::Integer(i),
                Default::Str(s) => Value::String(s.into()),
            });
        }
        sup.insert("service_prefix".into(), prefix.into());
        sup.entry("state_dir")
            .or_insert_with(|| state_dir.display().to_string().into());
        toml::to_string(&doc).expect("a TOML table serializes")
    }

    /// Writes the config under a new prefix named after `tag`.
    pub fn write(&self, tag: &str) -> TempConfig {
        self.write_mapped(tag, |text| text)
    }

    /// As [`write`](Self::write), with the text passed through `map` first
    /// (e.g. [`crate::ecat::on_ethercat`]).
    pub fn write_mapped(&self, tag: &str, map: impl FnOnce(String) -> String) -> TempConfig {
        let prefix = unique_prefix(tag);
        let dir = std::env::temp_dir();
        let own_state = dir.join(format!("{prefix}.state"));
        let state_dir = self
            .doc
            .get("supervisor")
            .and_then(|s| s.get("state_dir"))
            .and_then(Value::as_str)
            .map_or(own_state.clone(), PathBuf::from);
        let path = dir.join(format!("{prefix}.toml"));
        std::fs::write(&path, map(self.text(&prefix, &own_state))).expect("write config");
        TempConfig {
            path,
            prefix,
            state_dir,
        }
    }

    #[track_caller]
    fn table_of<'a>(&'a mut self, path: &'a str) -> (&'a mut Table, &'a str) {
        let mut parts: Vec<&str> = path.split('.').collect();
        let key = parts.pop().expect("a key");
        let mut table = &mut self.doc;
        let mut rest = parts.as_slice();
        if let [list @ ("axis" | "io" | "gantry"), name, more @ ..] = rest {
            let entries = table
                .get_mut(*list)
                .and_then(Value::as_array_mut)
                .unwrap_or_else(|| panic!("{path}: the machine has no [[{list}]]"));
            let names: Vec<String> = entries
                .iter()
                .map(|e| format!("{:?}", e.get("name")))
                .collect();
            table = entries
                .iter_mut()
                .filter_map(Value::as_table_mut)
                .find(|e| e.get("name").and_then(Value::as_str) == Some(*name))
                .unwrap_or_else(|| panic!("{path}: no {list} {name:?} among {names:?}"));
            rest = more;
        }
        for part in rest {
            table = table
                .entry(*part)
                .or_insert_with(|| Value::Table(Table::new()))
                .as_table_mut()
                .unwrap_or_else(|| panic!("{path}: {part} is not a table"));
        }
        (table, key)
    }
}

/// `text` with the machine it parses to, or every problem in one line (a
/// machine generated as text: the EtherCAT rig's, the benches').
pub fn checked(text: String) -> Result<(String, MachineConfig), String> {
    match motion_config::parse(&text) {
        Ok(m) => Ok((text, m)),
        Err(problems) => Err(problems
            .iter()
            .map(|p| p.to_string())
            .collect::<Vec<_>>()
            .join("; ")),
    }
}

/// A config file written for one test; the file and its state directory
/// are removed on drop.
pub struct TempConfig {
    pub path: PathBuf,
    /// Its service prefix, unique to this config.
    pub prefix: String,
    /// Its `state_dir` (homing record, stored references).
    pub state_dir: PathBuf,
}

impl TempConfig {
    /// The path as a command-line argument.
    pub fn arg(&self) -> &str {
        self.path.to_str().expect("temp paths are UTF-8")
    }
}

impl Drop for TempConfig {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
        let _ = std::fs::remove_dir_all(&self.state_dir);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_fixture_is_a_valid_machine_with_the_defaults() {
        for (name, _) in FIXTURES {
            let text = Machine::fixture(name).text("mh_fixture", Path::new("/tmp/x"));
            let m = motion_config::parse(&text).unwrap_or_else(|p| panic!("{name}: {p:#?}"));
            assert_eq!(m.supervisor.service_prefix, "mh_fixture", "{name}");
            assert_eq!(m.supervisor.cycle_us, 1000, "{name}");
        }
    }

    #[test]
    fn overrides_reach_the_named_entry_and_keep_the_order() {
        let m = Machine::fixture("two_buses")
            .set("axis.Y.sim.start", -20.5)
            .set("io.bus1.spawn", "external")
            .without("supervisor.feedback_timeout_ms")
            .set("supervisor.stale_cycles", 5);
        let text = m.text("mh_o", Path::new("/tmp/x"));
        let c = motion_config::parse(&text).unwrap();
        let names: Vec<&str> = c.axes.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["X", "Y", "Z"]);
        assert_eq!(c.axes[1].sim.start, -20.5);
        assert!(
            !text.contains("feedback_timeout_ms"),
            "the default yields: {text}"
        );
        assert!(text.contains("spawn = \"external\""), "{text}");
    }

    #[test]
    fn hostile_values_survive_the_round_trip() {
        for v in [1e308, 1e-300, f64::NAN, f64::INFINITY, -0.0] {
            let m = Machine::parse("[[axis]]\nname = \"X\"\n").set("axis.X.home_speed", v);
            let back: Table = m.text("p", Path::new("/tmp")).parse().unwrap();
            let got = back["axis"][0]["home_speed"].as_float().unwrap();
            assert!(
                got.to_bits() == v.to_bits() || (got.is_nan() && v.is_nan()),
                "{v}"
            );
        }
        let name = "X\u{1b}[31m\u{0}\u{200b}";
        let m = Machine::parse(&format!(
            "[[axis]]\nname = \"{}\"\n",
            "X\\u001b[31m\\u0000\\u200b"
        ));
        let back: Table = m.text("p", Path::new("/tmp")).parse().unwrap();
        assert_eq!(back["axis"][0]["name"].as_str(), Some(name));
    }
}
