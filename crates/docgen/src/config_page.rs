//! The keys of `docs/configuration.md`, from the key table: per group its
//! intro, a summary table, and each key with its type, default, bounds,
//! meaning and an example.

use crate::keys;
use crate::markdown::{cell, slug};
use motion_config::keytable::{Key, Section, GROUPS};

/// A key's heading: `[[axis]] home_speed` (anchor `axis-home_speed`).
fn title(k: &Key) -> String {
    match k.section {
        Section::Top => format!("{} (top level)", table_of(k)),
        _ => format!("{} {}", k.section.header(), k.name),
    }
}

/// `[supervisor]` for the top-level key `supervisor`.
fn table_of(k: &Key) -> String {
    match k.kind {
        motion_config::keytable::Kind::Tables => format!("[[{}]]", k.name),
        _ => format!("[{}]", k.name),
    }
}

pub fn render() -> String {
    let mut out = String::new();
    for g in GROUPS {
        out += &format!("### {}\n\n{}\n\n", g.title, g.intro);
        out += "| key | type | default | bounds |\n|---|---|---|---|\n";
        for k in g.keys {
            out += &format!(
                "| [`{}`](#{}) | {} | {} | {} |\n",
                k.name,
                slug(&title(k)),
                cell(&keys::kind(k)),
                cell(&keys::default(k)),
                cell(&keys::bounds(k)),
            );
        }
        out.push('\n');
        for k in g.keys {
            out += &key_block(k);
        }
    }
    out
}

fn key_block(k: &Key) -> String {
    let mut facts = vec![
        format!("*{}*", keys::kind(k)),
        format!("default: {}", keys::default(k)),
    ];
    let b = keys::bounds(k);
    if !b.is_empty() {
        facts.push(format!("bounds: {b}"));
    }
    if k.fixed {
        facts.push(keys::FIXED.to_string());
    }
    let mut out = format!(
        "#### {}\n\n{}\n\n{}",
        title(k),
        facts.join(" · "),
        k.meaning
    );
    for r in keys::remarks(k) {
        out += &format!(" {r}");
    }
    out += &format!("\n\nExample: `{}`\n\n", keys::example(k));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_config::keytable::all;

    /// Every key has its block, with its default, bounds and example, and the
    /// summary tables link to the blocks.
    #[test]
    fn every_key_is_on_the_page() {
        let page = render();
        let anchors = crate::markdown::anchors(&page);
        for k in all() {
            let t = title(k);
            assert!(page.contains(&format!("#### {t}\n")), "{t}");
            assert!(anchors.contains(&slug(&t)), "{t}");
            assert!(page.contains(&keys::example(k)), "{t}");
            assert!(page.contains(&keys::default(k)), "{t}");
        }
        assert!(page.contains(
            "#### [supervisor] cycle_us\n\n*integer, µs* · default: `1000` · \
             bounds: 50 ..= 100000 µs · fixed name\n"
        ));
        assert!(page.contains("| [`home_speed`](#axis-home_speed) |"));
    }
}
