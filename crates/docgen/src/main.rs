//! `motion-docgen`: the one generator of everything the docs derive from
//! the code, and the check that they still do.
//!
//! * `motion-docgen [assets [DIR]]` — the Debian package's man pages (every
//!   binary and subcommand, and `motion-machine.toml(5)` from the key table)
//!   and shell completions, into `DIR` (default: `assets/` beside this
//!   executable, i.e. `target/release/assets` after `cargo build --release`,
//!   where the `[package.metadata.deb]` assets of `crates/supervisor` look).
//!   Run it before `cargo deb`.
//! * `motion-docgen docs` — rewrites the generated regions of the Markdown
//!   pages (`docs/configuration.md` from the key table, `docs/errors.md`
//!   from the code table, `docs/commands.md` from the clap definitions,
//!   `docs/protocol.md` from the layout description).
//! * `motion-docgen docs --check` — changes nothing; fails when a generated
//!   region differs from what the code would generate, a relative link does
//!   not resolve, a complete configuration example does not load, a command
//!   shown is refused by its binary's parser, a text file points outside the
//!   repository, or `README.md` is longer than 400 lines.
//!
//! A build helper, never shipped. Why a separate binary and not hidden
//! options of the shipped ones: their command lines are fixed and stay free
//! of build-only switches; why not a build script: a build script may write
//! only into its own `OUT_DIR`, which cargo-deb cannot name.

mod assets;
mod commands_page;
mod config_page;
mod errors_page;
mod keys;
mod lint;
mod machine_page;
mod markdown;
mod protocol_page;
mod regions;
mod repo;

use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Writes the man pages, completions and generated doc pages of
/// motion-supervisor from the code, and checks the docs.
#[derive(Parser, Debug)]
#[command(name = "motion-docgen", version)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// The man pages and shell completions of the Debian package (the
    /// default).
    Assets {
        /// Where to write them; default: `assets/` beside this executable.
        dir: Option<PathBuf>,
    },
    /// Rewrites the generated regions of the docs; with --check, checks the
    /// docs instead.
    Docs {
        /// Change nothing; fail on a stale region, a broken link, a
        /// configuration example that does not load, a command its parser
        /// refuses, a word pointing outside the repository, a long README.
        #[arg(long)]
        check: bool,
        /// The repository; default: the one this binary was built from.
        #[arg(long, value_name = "DIR")]
        root: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        None => assets_into(None),
        Some(Command::Assets { dir }) => assets_into(dir),
        Some(Command::Docs { check, root }) => {
            let root = root.unwrap_or_else(repo::default_root);
            let problems = if check {
                check_docs(&root)
            } else {
                write_docs(&root)
            };
            for p in &problems {
                eprintln!("{p}");
            }
            if problems.is_empty() {
                ExitCode::SUCCESS
            } else {
                eprintln!("motion-docgen: {} problem(s)", problems.len());
                ExitCode::FAILURE
            }
        }
    }
}

fn assets_into(dir: Option<PathBuf>) -> ExitCode {
    let out = match dir {
        Some(dir) => dir,
        None => match std::env::current_exe() {
            Ok(exe) => exe.with_file_name("assets"),
            Err(e) => {
                eprintln!(
                    "motion-docgen: cannot find my own path ({e}): name the output directory"
                );
                return ExitCode::from(2);
            }
        },
    };
    match assets::write_all(&out) {
        Ok(files) => {
            println!("motion-docgen: {} files in {}", files.len(), out.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("motion-docgen: {}: {e}", out.display());
            ExitCode::FAILURE
        }
    }
}

/// Each page's text, and the text with its regions generated (problems of
/// the markers or the generators, by page).
fn generated(root: &Path) -> (Vec<(PathBuf, String, String)>, Vec<String>) {
    let gens = regions::generators();
    let mut pages = Vec::new();
    let mut problems = Vec::new();
    let mut used: Vec<(&str, PathBuf)> = Vec::new();
    for rel in repo::markdown(root) {
        let Ok(text) = std::fs::read_to_string(root.join(&rel)) else {
            continue;
        };
        let mut make = |name: &str| -> Result<String, String> {
            let g = gens
                .iter()
                .find(|g| g.name == name)
                .ok_or_else(|| format!("no generator is called {name}"))?;
            used.push((g.name, rel.clone()));
            (g.make)(root)
        };
        match regions::rewrite(&text, &mut make) {
            Ok(new) => pages.push((rel, text, new)),
            Err(e) => problems.push(format!("{}: {e}", rel.display())),
        }
    }
    for g in &gens {
        let places: Vec<String> = used
            .iter()
            .filter(|(n, _)| *n == g.name)
            .map(|(_, p)| p.display().to_string())
            .collect();
        if places.len() != 1 {
            problems.push(format!(
                "the region {} (from {}) must be on exactly one page; it is on {places:?}",
                g.name, g.from
            ));
        }
    }
    (pages, problems)
}

fn write_docs(root: &Path) -> Vec<String> {
    let (pages, mut problems) = generated(root);
    for (rel, old, new) in pages {
        if old != new {
            match std::fs::write(root.join(&rel), new) {
                Ok(()) => println!("motion-docgen: wrote {}", rel.display()),
                Err(e) => problems.push(format!("{}: {e}", rel.display())),
            }
        }
    }
    problems
}

fn check_docs(root: &Path) -> Vec<String> {
    let (pages, mut problems) = generated(root);
    for (rel, old, new) in pages {
        if old != new {
            let line = old
                .lines()
                .zip(new.lines())
                .position(|(a, b)| a != b)
                .map_or(old.lines().count().min(new.lines().count()) + 1, |i| i + 1);
            problems.push(format!(
                "{}:{line}: a generated region differs from what the code generates: run \
                 `cargo run -p motion-docgen -- docs`",
                rel.display()
            ));
        }
    }
    problems.extend(lint::all(root));
    problems
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The docs of this repository, as CI checks them: generated regions
    /// current, links resolving, examples loading, commands parsing,
    /// nothing pointing outside.
    #[test]
    fn the_docs_are_true() {
        let problems = check_docs(&repo::default_root());
        assert!(problems.is_empty(), "\n{}", problems.join("\n"));
    }

    /// A stale region is found, and `docs` would rewrite it.
    #[test]
    fn a_stale_region_fails_the_check() {
        let root = std::env::temp_dir().join(format!("docgen-stale-{}", std::process::id()));
        std::fs::create_dir_all(root.join("docs")).unwrap();
        let page = "# Errors\n\n<!-- BEGIN motion-docgen errors: x -->\nstale\n\
                    <!-- END motion-docgen errors -->\n";
        std::fs::write(root.join("docs/errors.md"), page).unwrap();
        let (pages, problems) = generated(&root);
        assert!(
            problems.iter().any(|p| p.contains("region configuration")),
            "{problems:?}"
        );
        let stale = check_docs(&root);
        assert!(
            stale
                .iter()
                .any(|p| p.starts_with("docs/errors.md:3: a generated region")),
            "{stale:?}"
        );
        assert!(pages[0].2.contains("### ERR 12 / 45\n"));
        std::fs::remove_dir_all(&root).unwrap();
    }
}
