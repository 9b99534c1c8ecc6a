//! The log of `motion-opcua`: the daemons' conventions (`RUST_LOG`, default
//! `info`, stderr, journald priorities under systemd — see
//! `motion_rt::logging`) with one addition for a network-facing process:
//! every line is escaped. Clients choose much of what gets logged — user
//! names, application URIs, session names, the subject of a certificate
//! (which the stack itself logs when it refuses one) — and a control
//! character in any of them must not forge a log line or a terminal
//! sequence. So control characters, and the invisible and bidirectional
//! formatting ones, are written as `\u{..}`, whoever logged them.

use std::borrow::Cow;
use std::io::Write;

/// (syslog priority, word) per `log::Level` (Error = 1 … Trace = 5).
const TAGS: [(u8, &str); 5] = [
    (3, "error: "),
    (4, "warning: "),
    (6, ""),
    (7, "debug: "),
    (7, "trace: "),
];

/// Installs the escaping logger (a second call is ignored).
pub fn init() {
    let journal = std::env::var_os("JOURNAL_STREAM").is_some();
    let mut b = env_logger::Builder::new();
    b.filter_level(log::LevelFilter::Info);
    if let Ok(spec) = std::env::var("RUST_LOG") {
        b.parse_filters(&spec);
    }
    b.target(env_logger::Target::Stderr);
    b.format(move |buf, r| {
        let (prio, word) = TAGS[(r.level() as usize).clamp(1, 5) - 1];
        let text = r.args().to_string();
        let text = escape(&text);
        match journal {
            true => writeln!(buf, "<{prio}>{word}{text}"),
            false => writeln!(buf, "motion-opcua: {word}{text}"),
        }
    });
    let _ = b.try_init();
}

fn hidden(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `s` with every control, invisible or bidirectional character as
/// `\u{..}` (unchanged, and not copied, when it has none).
pub fn escape(s: &str) -> Cow<'_, str> {
    if !s.chars().any(hidden) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 16);
    for c in s.chars() {
        if hidden(c) {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_client_s_text_cannot_forge_lines_or_terminal_sequences() {
        assert_eq!(
            escape("user \"op1\" on Basic256Sha256"),
            "user \"op1\" on Basic256Sha256"
        );
        assert_eq!(
            escape("x\nmotion-opcua: OPC UA login: admin\r\x1b[2J"),
            "x\\u{a}motion-opcua: OPC UA login: admin\\u{d}\\u{1b}[2J"
        );
        assert_eq!(escape("ab\u{202e}cd"), "ab\\u{202e}cd");
        assert_eq!(escape("Zürich µs"), "Zürich µs", "printable text stays");
    }
}
