//! The codes of `docs/errors.md`, from the code table
//! (`motion_homing::code_table::TABLE`): an index by ERR / EXERR, then each
//! code with where it is reported, its cause and its remedy.

use crate::markdown::{cell, slug};
use motion_homing::code_table::{Code, TABLE};

/// "12 / 45", "3 / any".
fn id(c: &Code) -> String {
    match c.exerr {
        Some(x) => format!("{} / {x}", c.err),
        None => format!("{} / any", c.err),
    }
}

fn title(c: &Code) -> String {
    format!("ERR {}", id(c))
}

pub fn render() -> String {
    let mut rows: Vec<&Code> = TABLE.iter().collect();
    // By ERR, then EXERR, the row for "any other EXERR" last.
    rows.sort_by_key(|c| (c.err, c.exerr.is_none(), c.exerr));
    let mut out = String::from("| ERR / EXERR | reported as | meaning |\n|---|---|---|\n");
    for c in &rows {
        out += &format!(
            "| [{}](#{}) | {} | {} |\n",
            id(c),
            slug(&title(c)),
            seen(c),
            cell(c.short)
        );
    }
    out.push('\n');
    for c in &rows {
        let origin = if c.ours {
            "This project's code, in the style of the Logix tables."
        } else {
            "A Logix code."
        };
        out += &format!(
            "### {}\n\n*{}.* Reported as: {}. {origin}\n\n**Cause.** {}\n\n**Remedy.** {}\n\n",
            title(c),
            c.short,
            seen(c),
            c.cause,
            c.remedy
        );
    }
    out
}

fn seen(c: &Code) -> String {
    c.seen
        .iter()
        .map(|s| s.name())
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_code_has_its_section_and_index_row() {
        let page = render();
        let anchors = crate::markdown::anchors(&page);
        for c in TABLE {
            assert!(anchors.contains(&slug(&title(c))), "{}", id(c));
            assert!(
                page.contains(c.cause) && page.contains(c.remedy),
                "{}",
                id(c)
            );
        }
        assert!(page.contains("### ERR 12 / 45\n\n*drive lost"));
        assert!(page.contains("| [12 / 45](#err-12--45) |"));
    }
}
