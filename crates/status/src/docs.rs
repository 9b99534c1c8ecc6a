//! The docs page of the status fields, rendered from the table: a plain
//! function (no I/O), so the one docs generator can call it; the test
//! below keeps the checked-in `docs/status.md` equal to it.

use crate::axis::ROWS;
use crate::schema::{Type, FLAG_BITS, INT_SLOTS, VALUE_SLOTS};

/// Where the page is checked in, from the repository's root.
pub const PAGE: &str = "docs/status.md";

fn cell(s: &str) -> String {
    if s.is_empty() {
        "–".to_string()
    } else {
        s.replace('|', "\\|")
    }
}

fn code(s: Option<&str>) -> String {
    s.map_or("–".to_string(), |s| {
        format!("`{}`", s.replace('|', "\\|"))
    })
}

/// `docs/status.md`: every status field of an axis with its JSON key, OPC UA
/// name, mark in `motionctl status`, unit, place in the status frame and
/// meaning.
pub fn markdown() -> String {
    let mut s = String::from(
        "# Status fields\n\n\
         <!-- Generated from the status table (crates/status/src/axis.rs) by \
         motion_status::docs::markdown; a test fails when this page differs. -->\n\n\
         Every field of an axis's status, as each interface shows it: the key in \
         `motionctl status --json` (and the Python property of a status entry), the \
         variable under `Objects/Machine/Axes/<axis>` in OPC UA (namespace \
         `urn:motion-supervisor`), the mark in the flags column of `motionctl status` \
         (a dot when the flag is off), the unit (axis units follow `counts_per_unit`), \
         and where the status frame carries it.\n\n\
         Besides these, each axis row has `name`, `io` (its I/O process), `phase` \
         (the homing phase: OPC UA `Phase`), `owner` (the program streaming to it), \
         and in JSON `error` and `warnings` in words (OPC UA `Message`, `Warnings`).\n\n\
         A `maybe` number has no value when there is none to give (no valid feedback, \
         nothing latched yet): `null` in JSON, NaN in the frame, a Bad status in OPC UA. \
         An `enum` is its name in JSON and its number (with `EnumStrings`) in OPC UA.\n\n",
    );
    s += &format!(
        "The frame's entry has room for {FLAG_BITS} flags, {INT_SLOTS} integers and \
         {VALUE_SLOTS} numbers: a new field takes a free place and moves no other, so a \
         client built for an older table still reads every field it knows.\n\n"
    );
    s += "| field | JSON key | OPC UA | mark | type | unit | in the frame | meaning |\n";
    s += "|---|---|---|---|---|---|---|---|\n";
    for r in ROWS {
        let ty = match r.ty {
            Type::Enum(_) => format!("enum: {}", r.ty.enum_names().join(", ")),
            t => t.name().to_string(),
        };
        s += &format!(
            "| `{}` | `{}` | {} | {} | {} | {} | `{}` | {} |\n",
            r.name,
            r.json,
            code(r.opcua),
            code(r.mark),
            cell(&ty),
            cell(r.unit.symbol()),
            r.place_text(),
            cell(&r.doc_line()),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checked-in page is what the table renders (with
    /// `MOTION_DOCS_WRITE=1`, it is rewritten to be).
    #[test]
    fn the_checked_in_status_page_is_current() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/status.md");
        let page = markdown();
        if std::env::var_os("MOTION_DOCS_WRITE").is_some() {
            std::fs::write(path, &page).expect("write docs/status.md");
            return;
        }
        let checked_in = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            checked_in == page,
            "docs/status.md is stale: regenerate it with \
             MOTION_DOCS_WRITE=1 cargo test -p motion-status the_checked_in_status_page"
        );
    }
}
