//! The checks that keep the docs true, each a list of problems
//! (`path:line: what`): links that do not resolve, configuration examples
//! that the configuration's parser refuses, commands their binary's parser
//! refuses, words that point outside the repository, a front door longer
//! than 400 lines.

mod commands;
mod examples;
mod links;
mod outside;

use std::path::Path;

/// Every problem of the docs below `root`.
pub fn all(root: &Path) -> Vec<String> {
    let mut problems = Vec::new();
    for rel in crate::repo::markdown(root) {
        let Ok(text) = std::fs::read_to_string(root.join(&rel)) else {
            problems.push(format!("{}: not UTF-8 text", rel.display()));
            continue;
        };
        let at = |line: usize, what: String| format!("{}:{line}: {what}", rel.display());
        for (line, what) in links::check(root, &rel, &text) {
            problems.push(at(line, what));
        }
        for (line, what) in examples::check(&text) {
            problems.push(at(line, what));
        }
        for (line, what) in commands::check(&text) {
            problems.push(at(line, what));
        }
    }
    problems.extend(outside::check(root));
    problems
}
