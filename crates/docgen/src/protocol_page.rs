//! The wire layout of `docs/protocol.md`, from the checked-in layout
//! description (`python/motion_supervisor_client/layout.json`, which a test
//! of `motion-control` writes from the Rust types and keeps current).
//!
//! The description is rendered generically, so the page keeps working when
//! its format grows: a string becomes a line, an object of plain values a
//! table of names and values, an array of objects of plain values a table
//! with a column per key (`name`, `offset`, `size`, `align`, `type` first
//! when present, then any other key), any other array of objects one
//! section per object, headed by its `name`. Nothing else is named.

use crate::markdown::cell;
use serde_json::{Map, Value};

/// Where the description lives, from the repository's root.
pub const LAYOUT: &str = "python/motion_supervisor_client/layout.json";

/// The Markdown for the description `json`.
pub fn render(json: &str) -> Result<String, String> {
    let v: Value = serde_json::from_str(json).map_err(|e| format!("{LAYOUT}: {e}"))?;
    let Value::Object(top) = v else {
        return Err(format!("{LAYOUT}: not a JSON object"));
    };
    let mut out = String::new();
    object(&top, 3, &mut out);
    Ok(out)
}

fn scalar(v: &Value) -> Option<String> {
    match v {
        Value::String(s) => Some(format!("`{s}`")),
        Value::Number(n) => Some(n.to_string()),
        Value::Bool(b) => Some(b.to_string()),
        Value::Null => Some("null".into()),
        _ => None,
    }
}

fn object(o: &Map<String, Value>, level: usize, out: &mut String) {
    let mut facts = Vec::new();
    for (k, v) in o {
        if k == "name" {
            continue;
        }
        if let Some(s) = scalar(v) {
            facts.push(format!("{k}: {}", cell(&s)));
        }
    }
    if !facts.is_empty() {
        *out += &format!("{}\n\n", facts.join(" · "));
    }
    for (k, v) in o {
        match v {
            Value::Object(inner) if inner.values().all(|x| scalar(x).is_some()) => {
                *out += &format!("{} {k}\n\n| name | value |\n|---|---|\n", "#".repeat(level));
                for (n, x) in inner {
                    *out += &format!("| `{n}` | {} |\n", cell(&scalar(x).unwrap_or_default()));
                }
                out.push('\n');
            }
            Value::Object(inner) => {
                *out += &format!("{} {k}\n\n", "#".repeat(level));
                object(inner, level + 1, out);
            }
            Value::Array(items) if items.iter().all(Value::is_object) && !items.is_empty() => {
                let flat = items.iter().all(|i| {
                    i.as_object()
                        .is_some_and(|m| m.values().all(|x| scalar(x).is_some()))
                });
                if !flat {
                    *out += &format!("{} {k}\n\n", "#".repeat(level));
                    for item in items {
                        let m = item.as_object().expect("checked: objects");
                        let name = m.get("name").and_then(Value::as_str).unwrap_or("?");
                        *out += &format!("{} {name}\n\n", "#".repeat((level + 1).min(6)));
                        object(m, (level + 2).min(6), out);
                    }
                } else {
                    table(k, items, level, out);
                }
            }
            Value::Array(items) => {
                let shown: Vec<String> = items.iter().filter_map(scalar).collect();
                *out += &format!("{k}: {}\n\n", cell(&shown.join(", ")));
            }
            _ => {}
        }
    }
}

/// An array of objects as a table, a column per key.
fn table(title: &str, items: &[Value], level: usize, out: &mut String) {
    const FIRST: [&str; 5] = ["name", "offset", "size", "align", "type"];
    let mut cols: Vec<String> = FIRST.iter().map(|s| s.to_string()).collect();
    let mut rest: Vec<String> = Vec::new();
    for i in items {
        for k in i.as_object().expect("checked: objects").keys() {
            if !FIRST.contains(&k.as_str()) && !rest.contains(k) {
                rest.push(k.clone());
            }
        }
    }
    rest.sort();
    cols.retain(|c| items.iter().any(|i| i.get(c).is_some()));
    cols.extend(rest);
    *out += &format!(
        "{} {title}\n\n| {} |\n|{}\n",
        "#".repeat(level.min(6)),
        cols.join(" | "),
        "---|".repeat(cols.len())
    );
    for i in items {
        let cells: Vec<String> = cols
            .iter()
            .map(|c| {
                i.get(c)
                    .map(|v| scalar(v).unwrap_or_else(|| format!("`{v}`")))
                    .map(|s| cell(&s))
                    .unwrap_or_default()
            })
            .collect();
        *out += &format!("| {} |\n", cells.join(" | "));
    }
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_the_description_and_what_it_may_grow() {
        let json = r#"{"generator": "g", "constants": {"A": 1, "B_C": 2},
            "structs": [{"name": "Frame", "size": 16, "align": 8,
                "fields": [{"name": "a", "offset": 0, "size": 8, "align": 8, "type": "u64"},
                           {"name": "b", "offset": 8, "size": 8, "align": 8, "type": "f64",
                            "unit": "units/s", "doc": "speed | signed"}]}],
            "future": {"nested": {"x": [1, 2]}}}"#;
        let page = render(json).unwrap();
        assert!(page.contains("generator: `g`"), "{page}");
        assert!(page.contains("| `B_C` | 2 |"), "{page}");
        assert!(page.contains("#### Frame\n\nalign: 8 · size: 16"), "{page}");
        assert!(
            page.contains("| name | offset | size | align | type | doc | unit |"),
            "{page}"
        );
        assert!(
            page.contains("| `b` | 8 | 8 | 8 | `f64` | `speed \\| signed` | `units/s` |"),
            "{page}"
        );
        assert!(page.contains("x: 1, 2"), "{page}");
        assert!(render("[1]").is_err());
    }
}
