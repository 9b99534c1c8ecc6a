//! Generated regions of the docs: between
//! `<!-- BEGIN motion-docgen NAME ... -->` and `<!-- END motion-docgen NAME -->`
//! a page holds what generator NAME makes from the code. `motion-docgen docs`
//! rewrites them; `motion-docgen docs --check` fails when one differs, when
//! a page names a generator that does not exist, or when a generator's
//! region is missing or there twice.

use std::path::Path;

const BEGIN: &str = "<!-- BEGIN motion-docgen ";
const END: &str = "<!-- END motion-docgen ";

/// What a region's opening line says to whoever edits the page.
fn begin_line(name: &str) -> String {
    format!(
        "{BEGIN}{name}: generated from the code; edit the source it names, then run \
         `cargo run -p motion-docgen -- docs` -->"
    )
}

/// A generator: its region's name, what it is made from, and the maker.
pub struct Generator {
    pub name: &'static str,
    pub from: &'static str,
    pub make: fn(&Path) -> Result<String, String>,
}

pub fn generators() -> Vec<Generator> {
    vec![
        Generator {
            name: "configuration",
            from: "the key table, crates/config/src/keytable/",
            make: |_| Ok(crate::config_page::render()),
        },
        Generator {
            name: "errors",
            from: "the code table, crates/homing/src/code_table.rs",
            make: |_| Ok(crate::errors_page::render()),
        },
        Generator {
            name: "protocol",
            from: "the layout description, python/motion_supervisor_client/layout.json",
            make: |root| {
                let path = root.join(crate::protocol_page::LAYOUT);
                let json = std::fs::read_to_string(&path)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                crate::protocol_page::render(&json)
            },
        },
        Generator {
            name: "commands",
            from: "the binaries' clap definitions (their cli.rs)",
            make: |_| Ok(crate::commands_page::render(&crate::assets::commands())),
        },
    ]
}

/// One region found in a page.
#[derive(Debug, PartialEq)]
pub struct Region {
    pub name: String,
    /// Byte range of the content between the two marker lines.
    pub content: std::ops::Range<usize>,
    pub line: usize,
}

/// The regions of `text`, or what is wrong with its markers.
pub fn regions(text: &str) -> Result<Vec<Region>, String> {
    let mut out = Vec::new();
    let mut open: Option<(String, usize, usize)> = None;
    let mut offset = 0;
    for (i, line) in text.split_inclusive('\n').enumerate() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix(BEGIN) {
            if let Some((name, _, at)) = &open {
                return Err(format!(
                    "line {}: region {name} (line {at}) is not closed",
                    i + 1
                ));
            }
            let name = rest.split([':', ' ']).next().unwrap_or("").to_string();
            open = Some((name, offset + line.len(), i + 1));
        } else if let Some(rest) = t.strip_prefix(END) {
            let name = rest.trim_end_matches("-->").trim();
            match open.take() {
                Some((n, start, at)) if n == name => out.push(Region {
                    name: n,
                    content: start..offset,
                    line: at,
                }),
                _ => return Err(format!("line {}: END of {name} without its BEGIN", i + 1)),
            }
        }
        offset += line.len();
    }
    match open {
        Some((name, _, at)) => Err(format!("line {at}: region {name} is not closed")),
        None => Ok(out),
    }
}

/// `text` with every region's content replaced by `make(name)`; the
/// opening lines rewritten as [`begin_line`] says.
pub fn rewrite(
    text: &str,
    make: &mut dyn FnMut(&str) -> Result<String, String>,
) -> Result<String, String> {
    let found = regions(text)?;
    let mut out = String::new();
    let mut at = 0;
    for r in found {
        let begin_start = text[..r.content.start - 1].rfind('\n').map_or(0, |i| i + 1);
        out += &text[at..begin_start];
        out += &begin_line(&r.name);
        out.push('\n');
        let body = make(&r.name)?;
        out += body.trim_end();
        out += "\n";
        at = r.content.end;
    }
    out += &text[at..];
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_are_found_and_rewritten() {
        let t = "# Page\n\n<!-- BEGIN motion-docgen x: old words -->\nold\n<!-- END motion-docgen x -->\ntail\n";
        let r = regions(t).unwrap();
        assert_eq!(r.len(), 1);
        assert_eq!(&t[r[0].content.clone()], "old\n");
        let new = rewrite(t, &mut |n| Ok(format!("made by {n}\n\n"))).unwrap();
        assert_eq!(
            new,
            format!(
                "# Page\n\n{}\nmade by x\n<!-- END motion-docgen x -->\ntail\n",
                begin_line("x")
            )
        );
        assert_eq!(
            rewrite(&new, &mut |n| Ok(format!("made by {n}"))).unwrap(),
            new
        );
        assert!(regions("<!-- BEGIN motion-docgen x -->\n").is_err());
        assert!(regions("<!-- END motion-docgen x -->\n").is_err());
    }
}
