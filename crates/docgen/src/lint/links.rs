//! Relative links and images resolve: the file (or directory) exists in the
//! repository, and an `#anchor` names a heading of the Markdown file it
//! points into.

use crate::markdown::{anchors, links};
use std::path::{Component, Path, PathBuf};

/// The problems of the links in `text` (the file `rel` below `root`), by
/// line.
pub fn check(root: &Path, rel: &Path, text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let dir = rel.parent().unwrap_or(Path::new(""));
    for link in links(text) {
        let t = link.target.as_str();
        if t.contains("://") || t.starts_with("mailto:") {
            continue;
        }
        let (path, anchor) = match t.split_once('#') {
            Some((p, a)) => (p, Some(a)),
            None => (t, None),
        };
        if path.is_empty() {
            let anchor = anchor.unwrap_or("");
            if !anchors(text).iter().any(|a| a == anchor) {
                out.push((link.line, format!("{t}: no heading here has that anchor")));
            }
            continue;
        }
        let target = {
            match inside(&dir.join(path)) {
                Some(p) => p,
                None => {
                    out.push((link.line, format!("{t}: points outside the repository")));
                    continue;
                }
            }
        };
        let full = root.join(&target);
        if !full.exists() {
            out.push((
                link.line,
                format!("{t}: {} does not exist", target.display()),
            ));
            continue;
        }
        let Some(anchor) = anchor else { continue };
        if target.extension().is_some_and(|e| e == "md") {
            let Ok(page) = std::fs::read_to_string(&full) else {
                continue;
            };
            if !anchors(&page).iter().any(|a| a == anchor) {
                out.push((
                    link.line,
                    format!(
                        "{t}: no heading of {} has the anchor #{anchor}",
                        target.display()
                    ),
                ));
            }
        }
    }
    out
}

/// `path` with `.` and `..` resolved, if it stays inside the repository.
fn inside(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::Normal(s) => out.push(s),
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn broken_links_and_anchors_are_found() {
        let root = crate::repo::default_root();
        let text = "[ok](../README.md#motion-supervisor) [no](../nope.md) \
                    [anchor](../README.md#no-such-heading) [up](../../x) [web](https://x.org/a)\n\
                    [self](#here) [gone](#gone)\n# Here\n";
        let p = check(&root, Path::new("docs/page.md"), text);
        let what: Vec<&str> = p.iter().map(|(_, w)| w.as_str()).collect();
        assert_eq!(p.len(), 4, "{what:?}");
        assert!(what[0].contains("nope.md does not exist"));
        assert!(what[1].contains("#no-such-heading"));
        assert!(what[2].contains("outside the repository"));
        assert!(what[3].contains("#gone"));
    }
}
