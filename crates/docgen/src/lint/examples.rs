//! Configuration examples: a fenced block marked ```` ```toml machine ````
//! is a complete machine and must load as `motion-supervisor check` loads
//! it (parsed and validated, every problem named); any other `toml` block
//! must be TOML whose keys the key table declares in their section.

use crate::markdown::fences;
use motion_config::keytable::{self, Section};

pub fn check(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for f in fences(text) {
        let mut words = f.info.split_whitespace();
        if words.next() != Some("toml") {
            continue;
        }
        if words.any(|w| w == "machine") {
            if let Err(problems) = motion_config::parse(&f.body) {
                for p in problems {
                    out.push((f.line, format!("machine example: {p}")));
                }
            }
            continue;
        }
        match f.body.parse::<toml::Table>() {
            Ok(t) => {
                for bad in unknown_keys(&t) {
                    out.push((f.line, format!("toml example: {bad}")));
                }
            }
            Err(e) => out.push((f.line, format!("toml example: {}", e.message()))),
        }
    }
    out
}

/// The keys of a fragment the key table does not declare: below a section's
/// header, that section's; bare keys, any section's.
fn unknown_keys(t: &toml::Table) -> Vec<String> {
    let mut out = Vec::new();
    for (k, v) in t {
        let section = match k.as_str() {
            "supervisor" => Some(Section::Supervisor),
            "io" => Some(Section::Io),
            "axis" => Some(Section::Axis),
            "gantry" => Some(Section::Gantry),
            "opcua" => Some(Section::Opcua),
            _ => None,
        };
        match (section, v) {
            (Some(s), toml::Value::Table(inner)) => section_keys(s, inner, &mut out),
            (Some(s), toml::Value::Array(items)) => {
                for i in items.iter().filter_map(|i| i.as_table()) {
                    section_keys(s, i, &mut out);
                }
            }
            _ => {
                if !keytable::all().any(|key| key.name == k) {
                    out.push(format!("no section has a key {k}"));
                }
            }
        }
    }
    out
}

fn section_keys(section: Section, t: &toml::Table, out: &mut Vec<String>) {
    for (k, v) in t {
        if keytable::find(section, k).is_none() {
            out.push(format!("{} has no key {k}", section.header()));
            continue;
        }
        let below = match (section, k.as_str()) {
            (Section::Axis, "sim") => Some(Section::AxisSim),
            (Section::Opcua, "user") => Some(Section::OpcuaUser),
            _ => None,
        };
        match (below, v) {
            (Some(s), toml::Value::Table(inner)) => section_keys(s, inner, out),
            (Some(s), toml::Value::Array(items)) => {
                for i in items.iter().filter_map(|i| i.as_table()) {
                    section_keys(s, i, out);
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn machines_load_and_fragments_use_declared_keys() {
        let good = "```toml machine\n[[axis]]\nname = \"X\"\n```\n\
                    ```toml\n[supervisor]\ncycle_us = 500\n[[axis]]\nhome_speed = 1\n[axis.sim]\nstart = 1\n```\n\
                    ```toml\nhome_speed = 2\n```\n";
        assert_eq!(check(good), []);
        let bad = "```toml machine\n[[axis]]\nname = \"X\"\nhome_speed = -1\n```\n\
                   ```toml\n[supervisor]\ncycle = 500\n```\n```toml\nwarp = 9\n```\n```toml\nx = [\n```\n";
        let p = check(bad);
        let what: Vec<&str> = p.iter().map(|(_, w)| w.as_str()).collect();
        assert_eq!(p.len(), 4, "{what:?}");
        assert!(
            what[0].starts_with("machine example: axis X: home_speed"),
            "{what:?}"
        );
        assert_eq!(what[1], "toml example: [supervisor] has no key cycle");
        assert_eq!(what[2], "toml example: no section has a key warp");
        assert_eq!((p[0].0, p[1].0), (2, 7));
    }
}
