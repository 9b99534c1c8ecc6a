//! A key of the configuration in words: what the Markdown page and the man
//! page both say of each row of the key table.

use motion_config::keytable::{number, Bounds, Default, Key, Only, Section, Status};

/// "number, units/s" — the type and the unit.
pub fn kind(k: &Key) -> String {
    match k.unit {
        "" => k.kind.describe(),
        u => format!("{}, {u}", k.kind.describe()),
    }
}

/// The default, with code spans for values.
pub fn default(k: &Key) -> String {
    match k.default {
        Default::Required => "required".into(),
        Default::Unset(words) => format!("none — {words}"),
        Default::Int(i) => format!("`{i}`"),
        Default::Num(x) => format!("`{}`", number(x)),
        Default::Bool(b) => format!("`{b}`"),
        Default::Text(s) => format!("`\"{s}\"`"),
        Default::Derived(words) => words.to_string(),
    }
}

/// The bounds and further constraints, "" when there are none.
pub fn bounds(k: &Key) -> String {
    let unit = if k.unit.is_empty() || k.unit == "cycles" {
        String::new()
    } else {
        format!(" {}", k.unit)
    };
    let b = match k.bounds {
        Bounds::Any => String::new(),
        Bounds::Range(lo, hi) => format!("{} ..= {}{unit}", number(lo), number(hi)),
        Bounds::AboveZero(hi) => format!("above 0, at most {}{unit}", number(hi)),
        Bounds::AtMost(hi) => format!("at most {}{unit}", number(hi)),
        Bounds::Text(words) => words.to_string(),
    };
    match (b.is_empty(), k.note.is_empty()) {
        (_, true) => b,
        (true, false) => k.note.to_string(),
        (false, false) => format!("{b}, {}", k.note),
    }
}

/// Sentences on where the key applies and whether it is current.
pub fn remarks(k: &Key) -> Vec<String> {
    let mut out = Vec::new();
    if k.only == Only::Ethercat {
        out.push(match k.section {
            Section::Io => "Only with `backend = \"ethercat\"`; a problem elsewhere.".into(),
            _ => "Only on an axis of an EtherCAT I/O process; a problem elsewhere.".into(),
        });
    }
    match k.status {
        Status::Current => {}
        Status::Alias(of) => out.push(format!("An older name of `{of}`, still read.")),
        Status::Deprecated(words) => out.push(format!("Deprecated: {words}.")),
        Status::Refused(words) => out.push(format!("Refused: {words}.")),
    }
    out
}

/// `name = example`.
pub fn example(k: &Key) -> String {
    format!("{} = {}", k.name, k.example)
}

/// Said of a key whose name is one of the interface's fixed points.
pub const FIXED: &str = "fixed name";
