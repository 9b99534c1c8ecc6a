//! The repository as the docs see it: its root, its Markdown files and the
//! text files whose words are checked.

use std::fs;
use std::path::{Path, PathBuf};

/// The repository this binary was built from (`--root` overrides it).
pub fn default_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Directories never looked into: build output, virtual environments,
/// version control, caches.
fn skipped(name: &str) -> bool {
    name.starts_with('.') && name != ".ci"
        || matches!(
            name,
            "target" | "venv" | "__pycache__" | "node_modules" | "out"
        )
}

/// Every file below `root` (relative paths, sorted), but in skipped
/// directories.
pub fn files(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![PathBuf::new()];
    while let Some(rel) = todo.pop() {
        let Ok(entries) = fs::read_dir(root.join(&rel)) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let path = rel.join(&name);
            match e.file_type() {
                Ok(t) if t.is_dir() && !skipped(&name) => todo.push(path),
                Ok(t) if t.is_file() => out.push(path),
                _ => {}
            }
        }
    }
    out.sort();
    out
}

/// The Markdown files: the docs.
pub fn markdown(root: &Path) -> Vec<PathBuf> {
    files(root)
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect()
}

/// The files whose words must not point outside the repository: every
/// tracked text file — sources (their comments and doc comments), docs,
/// configs, scripts, the package's files. Tracked means what `git ls-files`
/// lists, so that a scratch file beside the checkout is not the repository's;
/// outside a git checkout (a source tarball), every file the walk finds.
pub fn worded(root: &Path) -> Vec<PathBuf> {
    const TEXT: &[&str] = &[
        "rs",
        "md",
        "toml",
        "sh",
        "py",
        "service",
        "conf",
        "json",
        "txt",
        "proptest-regressions",
    ];
    tracked(root)
        .unwrap_or_else(|| files(root))
        .into_iter()
        .filter(|p| {
            let ext = p.extension().map(|e| e.to_string_lossy().into_owned());
            let in_ci = p.starts_with(".ci");
            in_ci
                || ext.is_some_and(|e| TEXT.contains(&e.as_str()))
                || p.starts_with("deploy/debian")
        })
        .collect()
}

/// The files git tracks below `root` (relative paths, sorted), or `None`
/// when `root` is not a git checkout or git cannot be run.
fn tracked(root: &Path) -> Option<Vec<PathBuf>> {
    let out = std::process::Command::new("git")
        .arg("-C")
        .arg(root)
        .args(["ls-files", "-z", "--cached", "--", "."])
        .stderr(std::process::Stdio::null())
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let mut paths: Vec<PathBuf> = out
        .stdout
        .split(|&b| b == 0)
        .filter(|p| !p.is_empty())
        .map(|p| PathBuf::from(String::from_utf8_lossy(p).into_owned()))
        .filter(|p| root.join(p).is_file())
        .collect();
    paths.sort();
    Some(paths)
}
