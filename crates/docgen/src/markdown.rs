//! What the generators and the checks need of Markdown: fenced blocks with
//! their info strings and line numbers, headings and their anchors (as
//! GitHub makes them), links, and escaping a table cell.

/// A fenced code block.
#[derive(Debug, PartialEq)]
pub struct Fence {
    /// The info string after the opening fence (`toml machine`).
    pub info: String,
    /// Line number (1-based) of the block's first line of content.
    pub line: usize,
    pub body: String,
}

/// The fenced code blocks of `text` (``` or ~~~ fences).
pub fn fences(text: &str) -> Vec<Fence> {
    let mut out = Vec::new();
    let mut open: Option<(String, String, usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        match &mut open {
            None => {
                if let Some(marker) = fence_marker(trimmed) {
                    let info = trimmed[marker.len()..].trim().to_string();
                    open = Some((marker, info, i + 2, String::new()));
                }
            }
            Some((marker, info, start, body)) => {
                if trimmed.starts_with(marker.as_str()) && trimmed.trim_end() == marker.as_str() {
                    out.push(Fence {
                        info: std::mem::take(info),
                        line: *start,
                        body: std::mem::take(body),
                    });
                    open = None;
                } else {
                    body.push_str(line);
                    body.push('\n');
                }
            }
        }
    }
    out
}

fn fence_marker(line: &str) -> Option<String> {
    for c in ['`', '~'] {
        let n = line.chars().take_while(|&x| x == c).count();
        if n >= 3 {
            return Some(c.to_string().repeat(n));
        }
    }
    None
}

/// `text` with every fenced block's lines and every inline code span
/// blanked (kept as spaces, so line numbers stay): what is prose. A code
/// span may run over a line break, not over a blank line.
pub fn prose(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut fence: Option<String> = None;
    let mut in_code = false;
    for line in text.lines() {
        if line.trim().is_empty() {
            in_code = false;
        }
        let trimmed = line.trim_start();
        match &fence {
            Some(m) => {
                if trimmed.trim_end() == m.as_str() {
                    fence = None;
                }
                out.push('\n');
                continue;
            }
            None => {
                if let Some(m) = fence_marker(trimmed) {
                    fence = Some(m);
                    out.push('\n');
                    continue;
                }
            }
        }
        out.push_str(&blank_code_spans(line, &mut in_code));
        out.push('\n');
    }
    out
}

fn blank_code_spans(line: &str, in_code: &mut bool) -> String {
    let mut out = String::with_capacity(line.len());
    for c in line.chars() {
        if c == '`' {
            *in_code = !*in_code;
            out.push(' ');
        } else if *in_code {
            out.push(' ');
        } else {
            out.push(c);
        }
    }
    out
}

/// The anchors of `text`'s headings, as GitHub makes them: lower case,
/// punctuation but `-` and `_` dropped, spaces as `-`, repeats numbered.
pub fn anchors(text: &str) -> Vec<String> {
    let mut seen: Vec<String> = Vec::new();
    let mut out = Vec::new();
    for line in prose_keeping_headings(text).lines() {
        let Some(title) = heading(line) else { continue };
        let base = slug(title);
        let n = seen.iter().filter(|s| **s == base).count();
        seen.push(base.clone());
        out.push(if n == 0 { base } else { format!("{base}-{n}") });
    }
    out
}

/// Like [`prose`], but inline code in headings is kept (its text is part of
/// the anchor).
fn prose_keeping_headings(text: &str) -> String {
    let blanked = prose(text);
    blanked
        .lines()
        .zip(text.lines())
        .map(|(b, t)| {
            if heading(t).is_some() && !b.trim().is_empty() {
                t
            } else {
                b
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The title of an ATX heading line.
pub fn heading(line: &str) -> Option<&str> {
    let hashes = line.chars().take_while(|&c| c == '#').count();
    if (1..=6).contains(&hashes) && line[hashes..].starts_with(' ') {
        Some(line[hashes..].trim().trim_end_matches('#').trim())
    } else {
        None
    }
}

/// GitHub's anchor of a heading's title.
pub fn slug(title: &str) -> String {
    let mut out = String::new();
    for c in title.trim().chars() {
        if c.is_alphanumeric() || c == '-' || c == '_' {
            out.extend(c.to_lowercase());
        } else if c == ' ' {
            out.push('-');
        }
    }
    out
}

/// A link or image target in the prose of a file.
#[derive(Debug, PartialEq)]
pub struct Link {
    pub line: usize,
    pub target: String,
}

/// Every inline link and image target (`[text](target)`, `![alt](target)`)
/// and reference definition (`[label]: target`) outside code.
pub fn links(text: &str) -> Vec<Link> {
    let mut out = Vec::new();
    for (i, line) in prose(text).lines().enumerate() {
        let bytes = line.as_bytes();
        let mut k = 0;
        while let Some(p) = line[k..].find("](") {
            let start = k + p + 2;
            let mut depth = 1;
            let mut end = start;
            while end < bytes.len() {
                match bytes[end] {
                    b'(' => depth += 1,
                    b')' => {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    _ => {}
                }
                end += 1;
            }
            let target = line[start..end.min(line.len())].trim();
            // `[text](target "title")`
            let target = target.split_whitespace().next().unwrap_or("");
            let target = target.trim_start_matches('<').trim_end_matches('>');
            if !target.is_empty() {
                out.push(Link {
                    line: i + 1,
                    target: target.to_string(),
                });
            }
            k = end.min(line.len());
        }
        let t = line.trim_start();
        if t.starts_with('[') {
            if let Some(p) = t.find("]: ") {
                let target = t[p + 3..].split_whitespace().next().unwrap_or("");
                if !target.is_empty() {
                    out.push(Link {
                        line: i + 1,
                        target: target.to_string(),
                    });
                }
            }
        }
    }
    out
}

/// `s` safe inside a table cell: no line breaks, `|` escaped.
pub fn cell(s: &str) -> String {
    s.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .replace('|', "\\|")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fences_with_info_and_lines() {
        let t = "a\n```toml machine\nx = 1\n```\n~~~\nb\n~~~\n";
        let f = fences(t);
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].info, "toml machine");
        assert_eq!((f[0].line, f[0].body.as_str()), (3, "x = 1\n"));
        assert_eq!(f[1].body, "b\n");
    }

    #[test]
    fn anchors_as_github_makes_them() {
        let t = "# The `cycle_us` key\n## EtherCAT drives\n## EtherCAT drives\n\
                 ### Homing by the drive (CiA 402 mode 6)\n```\n# not a heading\n```\n";
        assert_eq!(
            anchors(t),
            [
                "the-cycle_us-key",
                "ethercat-drives",
                "ethercat-drives-1",
                "homing-by-the-drive-cia-402-mode-6"
            ]
        );
    }

    #[test]
    fn links_outside_code_only() {
        let t = "See [a](docs/a.md#x) and ![p](p.svg).\n`[no](code.md)` `across\n[no](y)` b\n```\n[no](x)\n```\n\
                 [ref]: ../b.md\n[t](c.md \"title\")\n";
        let targets: Vec<String> = links(t).into_iter().map(|l| l.target).collect();
        assert_eq!(targets, ["docs/a.md#x", "p.svg", "../b.md", "c.md"]);
    }
}
