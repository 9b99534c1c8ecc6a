//! `motion-machine.toml(5)`: the configuration as a man page, from the key
//! table (the same rows as `docs/configuration.md`).

use crate::keys;
use motion_config::keytable::{Key, Kind, Section, GROUPS};
use roff::{bold, italic, roman, Inline, Roff};

/// Markdown's code spans as bold, the rest roman (the key table's texts use
/// no other markup).
fn inline(md: &str) -> Vec<Inline> {
    md.split('`')
        .enumerate()
        .filter(|(_, s)| !s.is_empty())
        .map(|(i, s)| if i % 2 == 1 { bold(s) } else { roman(s) })
        .collect()
}

/// Longest example shown whole: a longer one (a password hash) would not
/// fit a terminal's line, and is cut.
const EXAMPLE_MAX: usize = 48;

fn example(k: &Key) -> String {
    let e = keys::example(k);
    match e.char_indices().nth(EXAMPLE_MAX) {
        Some((i, _)) => format!("{}…", &e[..i]),
        None => e,
    }
}

/// The page's roff source; `date` and `source` as the command pages have.
pub fn render(date: &str, source: &str) -> String {
    let mut page = Roff::new();
    page.control(
        "TH",
        [
            "MOTION-MACHINE.TOML",
            "5",
            date,
            source,
            "motion-supervisor",
        ],
    );
    page.control("SH", ["NAME"]);
    page.text([roman(
        "motion-machine.toml - the machine configuration of motion-supervisor",
    )]);
    page.control("SH", ["SYNOPSIS"]);
    page.text([roman("/etc/motion/machine.toml")]);
    page.control("SH", ["DESCRIPTION"]);
    page.text(inline(
        "The machine configuration of `motion-supervisor`, `motion-io` and `motion-opcua`: \
         the real-time cycle, the drive-I/O processes, the axes and how they home, the \
         limits of their operations, gantries, and the OPC UA server. Every key is listed \
         below with its type, default, bounds, meaning and an example; the same list is \
         the manual's configuration page.",
    ));
    for g in GROUPS {
        page.control("SH", [g.title.to_uppercase().as_str()]);
        page.text(inline(g.intro));
        for k in g.keys {
            page.control("TP", []);
            let name = match (k.section, k.kind) {
                (Section::Top, Kind::Tables) => format!("[[{}]]", k.name),
                (Section::Top, _) => format!("[{}]", k.name),
                _ => k.name.to_string(),
            };
            page.text([bold(name), roman(" ("), italic(keys::kind(k)), roman(")")]);
            let mut facts = vec![format!("Default: {}.", keys::default(k))];
            let b = keys::bounds(k);
            if !b.is_empty() {
                facts.push(format!("Bounds: {b}."));
            }
            if k.fixed {
                facts.push("A fixed name: tools outside this repository rely on it.".into());
            }
            let mut text = format!("{} {}", k.meaning, facts.join(" "));
            for r in keys::remarks(k) {
                text += &format!(" {r}");
            }
            page.text(inline(&text));
            page.control("br", []);
            page.text([roman("Example: "), bold(example(k))]);
        }
    }
    page.control("SH", ["FILES"]);
    page.control("TP", []);
    page.text([bold("/etc/motion/machine.toml")]);
    page.text([roman(
        "The machine the packaged units run (a conffile; it ships as the demo machine).",
    )]);
    page.control("TP", []);
    page.text([bold("/usr/share/doc/motion-supervisor/examples/")]);
    page.text([roman("A gantry and a limit-switch machine to start from.")]);
    page.control("SH", ["SEE ALSO"]);
    page.text([roman(
        "motion-supervisor(1), motion-supervisor-check(1), motion-io(1), motionctl(1), \
         motion-opcua(1)",
    )]);
    page.render()
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_config::keytable::all;

    #[test]
    fn every_key_is_on_the_man_page() {
        let page = render("2026-12-01", "motion-supervisor 0.1.0");
        assert!(
            page.contains(".TH MOTION-MACHINE.TOML 5 2026-12-01"),
            "{page}"
        );
        for k in all() {
            let name = k.name.replace('-', "\\-");
            assert!(page.contains(&format!("\\fB{name}")), "{}", k.qualified());
        }
    }
}
