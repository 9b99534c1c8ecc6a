//! The Debian package's generated assets: the man pages of every binary
//! and subcommand (`man/*.1.gz`, `clap_mangen`), the configuration's page
//! `motion-machine.toml(5)` (`man/motion-machine.toml.5.gz`, from the key
//! table), and the bash, zsh and fish completions (`completions/{bash,zsh,
//! fish}/`, `clap_complete`) of the four binaries — from the very clap
//! definitions the binaries parse with, so they cannot drift from the code.

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use clap::CommandFactory;
use clap_complete::Shell;
use flate2::write::GzEncoder;
use flate2::Compression;

/// The Debian changelog: its latest entry's date is the pages' date (the
/// release's, and the same on every build).
const CHANGELOG: &str = include_str!("../../../deploy/debian/changelog");

/// `2026-12-01` from the first trailer line of a Debian changelog,
/// ` -- Name <address>  Tue, 01 Dec 2026 21:30:00 +0000` (RFC 2822 date).
fn release_date(changelog: &str) -> Option<String> {
    const MONTHS: [&str; 12] = [
        "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
    ];
    let trailer = changelog.lines().find(|l| l.starts_with(" -- "))?;
    let (_, date) = trailer.split_once(">  ")?;
    let mut words = date.split_whitespace().skip(1);
    let day: u8 = words.next()?.parse().ok()?;
    let month_name = words.next()?;
    let month = MONTHS.iter().position(|m| *m == month_name)? + 1;
    let year: u16 = words.next()?.parse().ok()?;
    Some(format!("{year}-{month:02}-{day:02}"))
}

/// The shipped binaries' command lines.
pub fn commands() -> [clap::Command; 4] {
    [
        motion_supervisor::cli::Cli::command(),
        motion_io::cli::Options::command(),
        motionctl::cli::Cli::command(),
        motion_opcua::cli::Cli::command(),
    ]
}

/// Writes every man page and completion below `out` (emptied first, so a
/// removed subcommand leaves no stale page behind); returns the files.
pub fn write_all(out: &Path) -> io::Result<Vec<PathBuf>> {
    let (man, completions) = (out.join("man"), out.join("completions"));
    for dir in [&man, &completions] {
        if dir.exists() {
            fs::remove_dir_all(dir)?;
        }
        fs::create_dir_all(dir)?;
    }
    let mut files = Vec::new();
    for cmd in commands() {
        write_man_pages(cmd.clone(), &man, &mut files)?;
        write_completions(cmd, &completions, &mut files)?;
    }
    files.push(write_machine_page(&man)?);
    Ok(files)
}

/// One gzip-compressed page for `cmd` and for each of its visible
/// subcommands, named as `clap_mangen::generate_to` names them
/// (`motionctl-home.1.gz`); gzip at the best level without a timestamp, as
/// Debian policy wants man pages (and as reproducible builds want them).
fn write_man_pages(cmd: clap::Command, dir: &Path, files: &mut Vec<PathBuf>) -> io::Result<()> {
    let mut cmd = cmd.disable_help_subcommand(true);
    cmd.build();
    let version = cmd.get_version().unwrap_or_default().to_owned();
    let date = date()?;
    let mut todo = vec![cmd];
    while let Some(cmd) = todo.pop() {
        todo.extend(cmd.get_subcommands().filter(|s| !s.is_hide_set()).cloned());
        let page = clap_mangen::Man::new(cmd)
            .date(&date)
            .manual("motion-supervisor")
            .source(format!("motion-supervisor {version}"));
        let path = dir.join(format!("{}.gz", page.get_filename()));
        let mut gz = GzEncoder::new(File::create(&path)?, Compression::best());
        page.render(&mut gz)?;
        gz.finish()?.flush()?;
        files.push(path);
    }
    Ok(())
}

/// Where each shell looks for a command's completion, by file name:
/// bash-completion loads `completions/NAME` on first use, zsh autoloads
/// `_NAME` from its function path, fish loads `NAME.fish`.
fn completion_file(shell: Shell, bin: &str) -> String {
    match shell {
        Shell::Zsh => format!("_{bin}"),
        Shell::Fish => format!("{bin}.fish"),
        _ => bin.to_owned(),
    }
}

fn write_completions(
    mut cmd: clap::Command,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> io::Result<()> {
    let bin = cmd.get_name().to_owned();
    for shell in [Shell::Bash, Shell::Zsh, Shell::Fish] {
        let sub = dir.join(shell.to_string());
        fs::create_dir_all(&sub)?;
        let path = sub.join(completion_file(shell, &bin));
        let mut file = File::create(&path)?;
        clap_complete::generate(shell, &mut cmd, &bin, &mut file);
        file.flush()?;
        files.push(path);
    }
    Ok(())
}

/// The pages' date: the latest changelog entry's.
fn date() -> io::Result<String> {
    release_date(CHANGELOG).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "no date in deploy/debian/changelog",
        )
    })
}

/// `motion-machine.toml.5.gz`, gzip-compressed as the command pages.
fn write_machine_page(dir: &Path) -> io::Result<PathBuf> {
    let source = format!("motion-supervisor {}", env!("CARGO_PKG_VERSION"));
    let page = crate::machine_page::render(&date()?, &source);
    let path = dir.join("motion-machine.toml.5.gz");
    let mut gz = GzEncoder::new(File::create(&path)?, Compression::best());
    gz.write_all(page.as_bytes())?;
    gz.finish()?.flush()?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    /// Every binary and every visible subcommand has a page, every binary a
    /// completion for each shell, and a page is a real roff page.
    #[test]
    fn writes_a_page_per_command_and_a_completion_per_shell() {
        let out = std::env::temp_dir().join(format!("docgen-{}", std::process::id()));
        let files = write_all(&out).unwrap();
        let names: Vec<String> = files
            .iter()
            .map(|p| p.strip_prefix(&out).unwrap().display().to_string())
            .collect();
        for want in [
            "man/motion-supervisor.1.gz",
            "man/motion-supervisor-run.1.gz",
            "man/motion-supervisor-home.1.gz",
            "man/motion-supervisor-check.1.gz",
            "man/motion-io.1.gz",
            "man/motionctl.1.gz",
            "man/motionctl-status.1.gz",
            "man/motionctl-home.1.gz",
            "man/motionctl-stop.1.gz",
            "man/motionctl-unhome.1.gz",
            "man/motionctl-stats.1.gz",
            "man/motionctl-trace.1.gz",
            "man/motion-opcua.1.gz",
            "man/motion-opcua-trust.1.gz",
            "completions/bash/motion-opcua",
            "completions/bash/motionctl",
            "completions/zsh/_motion-io",
            "completions/fish/motion-supervisor.fish",
            "man/motion-machine.toml.5.gz",
        ] {
            assert!(
                names.iter().any(|n| n == want),
                "{want} missing in {names:?}"
            );
        }
        let mut page = String::new();
        flate2::read::GzDecoder::new(File::open(out.join("man/motionctl-home.1.gz")).unwrap())
            .read_to_string(&mut page)
            .unwrap();
        assert!(page.starts_with(".ie \\n(.g .ds Aq"), "{page}");
        assert!(
            page.contains(".TH motionctl-home 1 ") && page.contains(" motion-supervisor\n"),
            "{page}"
        );
        assert!(page.contains("\\-\\-parallel"), "{page}");
        fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn the_pages_date_is_the_latest_changelog_entry() {
        let log = "p (0.2.0-1) unstable; urgency=medium\n\n  * x\n\n \
                   -- A B <a@b.example>  Wed, 03 Feb 2027 10:00:00 +0000\n\n\
                   p (0.1.0-1) unstable; urgency=medium\n\n  * y\n\n \
                   -- A B <a@b.example>  Tue, 01 Dec 2026 21:30:00 +0000\n";
        assert_eq!(release_date(log).as_deref(), Some("2027-02-03"));
        assert!(release_date(CHANGELOG).is_some());
        assert_eq!(release_date("no trailer"), None);
    }
}
