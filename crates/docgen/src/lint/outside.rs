//! The repository stands alone: no text file names a file outside it (the
//! interface's specification, the source texts it was written from, a
//! shared directory beside the checkout) or cites an issue number a reader
//! cannot look up; and the front door, `README.md`, stays at most 400
//! lines. (Rust sources are checked on their own.)

use std::path::Path;

/// The front door's length.
pub const README_MAX_LINES: usize = 400;

/// What a word points at, when it points outside.
fn outside(line: &str) -> Option<&'static str> {
    let l = line.to_lowercase();
    const NAMES: &[(&str, &str)] = &[
        // Spelled in pieces, so that this file does not name them itself.
        (
            concat!("interface", ".md"),
            "a specification outside the repository",
        ),
        (
            concat!("../", "shared"),
            "a directory outside the repository",
        ),
        (
            concat!("shared/", "spec"),
            "a directory outside the repository",
        ),
        (
            concat!("shared/", "seeds"),
            "a directory outside the repository",
        ),
        (
            concat!("seed", " document"),
            "source texts outside the repository",
        ),
        (
            concat!("the seed", "'s"),
            "source texts outside the repository",
        ),
    ];
    if let Some((_, what)) = NAMES.iter().find(|(n, _)| l.contains(n)) {
        return Some(what);
    }
    let followed_by_number = |word: &str, digits: usize| {
        l.match_indices(word).any(|(i, _)| {
            let before = l[..i].chars().next_back();
            let after = &l[i + word.len()..];
            !before.is_some_and(|c| c.is_alphanumeric())
                && after.len() >= digits
                && after.chars().take(digits).all(|c| c.is_ascii_digit())
        })
    };
    if followed_by_number("issue ", 1) || followed_by_number("issues ", 1) {
        return Some("an issue number a reader of the repository cannot look up");
    }
    if followed_by_number("seed ", 3) {
        return Some("source texts outside the repository");
    }
    None
}

pub fn check(root: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for rel in crate::repo::worded(root) {
        let Ok(text) = std::fs::read_to_string(root.join(&rel)) else {
            continue;
        };
        for (i, line) in text.lines().enumerate() {
            if let Some(what) = outside(line) {
                out.push(format!("{}:{}: names {what}", rel.display(), i + 1));
            }
        }
    }
    if let Ok(readme) = std::fs::read_to_string(root.join("README.md")) {
        let n = readme.lines().count();
        if n > README_MAX_LINES {
            out.push(format!("README.md: {n} lines, at most {README_MAX_LINES}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_outside_are_found() {
        for bad in [
            concat!("as interface", ".md says"),
            concat!("see ../", "shared/", "spec/homing.md"),
            concat!("Unhomed they do not apply (seed", " 003)"),
            concat!("the keys of issue", " 15"),
            concat!("Issues", " 3 and 4"),
            concat!("like the diagrams of the seed", " documents"),
        ] {
            assert!(outside(bad).is_some(), "{bad}");
        }
        for good in [
            "LinuxCNC #2983 (open)",
            "# Seeds for failure cases proptest has generated",
            "tissue 5",
            "an issue of the drive",
            "docs/homing.md",
        ] {
            assert!(outside(good).is_none(), "{good}");
        }
    }
}
