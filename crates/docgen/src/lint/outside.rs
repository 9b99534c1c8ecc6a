//! The repository stands alone: no tracked text file — Rust sources and
//! their comments included — names a file outside it (the interface's
//! specification, the source texts it was written from, a shared directory
//! beside the checkout) or cites an issue number a reader cannot look up
//! (an upstream project's `#1234` is fine: that one can be looked up); and
//! the front door, `README.md`, stays at most 400 lines.

use std::path::Path;

/// The front door's length.
pub const README_MAX_LINES: usize = 400;

/// What a word points at, when it points outside.
fn outside(line: &str) -> Option<&'static str> {
    let l = line.to_lowercase();
    const SPEC: &str = "a specification outside the repository";
    const DIR: &str = "a directory outside the repository";
    const TEXTS: &str = "source texts outside the repository";
    const NAMES: &[(&str, &str)] = &[
        // Spelled in pieces, so that this file does not name them itself.
        (concat!("interface", ".md"), SPEC),
        (concat!("../", "shared"), DIR),
        (concat!("shared/", "spec"), DIR),
        (concat!("shared/", "seeds"), DIR),
        (concat!("seeds", "/"), TEXTS),
        (concat!("seed", " document"), TEXTS),
        (concat!("the seed", "'s"), TEXTS),
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
            concat!("/// Issue", " 8, fuzzed: any argument vector"),
            concat!("//! The operations of issue", " 15 end to end"),
            concat!("// (issue", " 15: ERR 20 until then)"),
            concat!("(ISSUE", " 7)"),
            concat!("//! `motionctl`'s command line (interface", ".md), parsed"),
            concat!("see the mah text in seeds", "/003.md"),
            concat!("Issues", " 15's keys"),
        ] {
            assert!(outside(bad).is_some(), "{bad}");
        }
        for good in [
            "LinuxCNC #2983 (open)",
            "# Seeds for failure cases proptest has generated",
            "tissue 5",
            "the tissue 12 sample",
            "misissue 3",
            "an issue of the drive",
            "the failure of LinuxCNC issue #3717",
            "an issue: 5 axes",
            "the random seed 7 of the plant",
            "# Seeds for failure cases",
            "docs/homing.md",
            "the interface of the drive",
            "shared memory in /dev/shm",
        ] {
            assert!(outside(good).is_none(), "{good}");
        }
    }

    /// A Rust source's comments are checked like the docs: a comment citing
    /// an issue number or naming the outside specification is a problem;
    /// the same words in an untracked scratch file of a git checkout are not.
    #[test]
    fn rust_comments_are_checked_and_only_tracked_files() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        std::fs::create_dir_all(root.join("src")).unwrap();
        let bad = concat!(
            "//! The operations of issue",
            " 15, as interface",
            ".md says.\n"
        );
        std::fs::write(root.join("src/lib.rs"), bad).unwrap();
        std::fs::write(root.join("src/ok.rs"), "// a tissue 5 sample\n").unwrap();
        let found = check(root);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].starts_with("src/lib.rs:1: "), "{found:?}");

        let git = |args: &[&str]| {
            std::process::Command::new("git")
                .arg("-C")
                .arg(root)
                .args(args)
                .output()
                .map(|o| o.status.success())
                .unwrap_or(false)
        };
        if !git(&["init", "-q"]) || !git(&["add", "src/ok.rs"]) {
            return; // no git on this host: the walk above is what runs
        }
        assert!(check(root).is_empty(), "untracked src/lib.rs was checked");
        assert!(git(&["add", "src/lib.rs"]));
        assert_eq!(check(root).len(), 1);
    }
}
