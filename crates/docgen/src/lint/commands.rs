//! Commands shown in the docs: every line of a shell block (```` ```sh ````,
//! `shell`, `bash`, `console`) that runs one of the binaries is parsed with
//! that binary's own clap definition — not run — and must be accepted.
//! Lines are split like a shell splits them (quotes, `\` continuations,
//! comments); pipelines and lists (`|`, `&&`, `||`, `;`, `&`) are checked
//! command by command; a prompt (`$ `), environment assignments, `sudo` and
//! its options, redirections and a path before the binary are skipped.

use crate::markdown::fences;

const SHELLS: &[&str] = &["sh", "shell", "bash", "console", "zsh"];

/// The binaries whose command lines are checked, with their parsers.
fn parser(bin: &str) -> Option<clap::Command> {
    use clap::CommandFactory;
    let [sup, io, ctl, opcua] = crate::assets::commands();
    match bin {
        "motion-supervisor" => Some(sup),
        "motion-io" => Some(io),
        "motionctl" => Some(ctl),
        "motion-opcua" => Some(opcua),
        "motion-docgen" => Some(crate::Cli::command()),
        _ => None,
    }
}

pub fn check(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for f in fences(text) {
        if !f
            .info
            .split_whitespace()
            .next()
            .is_some_and(|w| SHELLS.contains(&w))
        {
            continue;
        }
        for (line, cmdline) in lines(&f.body) {
            for problem in check_line(&cmdline) {
                out.push((f.line + line, problem));
            }
        }
    }
    out
}

/// The block's command lines (continuations joined), with their offsets.
fn lines(body: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut current = String::new();
    let mut start = 0;
    for (i, l) in body.lines().enumerate() {
        if current.is_empty() {
            start = i;
        }
        let l = if current.is_empty() {
            l.trim_start().strip_prefix("$ ").unwrap_or(l)
        } else {
            l
        };
        match l.strip_suffix('\\') {
            Some(head) => {
                current += head;
                current.push(' ');
            }
            None => {
                current += l;
                out.push((start, std::mem::take(&mut current)));
            }
        }
    }
    if !current.is_empty() {
        out.push((start, current));
    }
    out
}

/// The problems of one command line.
fn check_line(line: &str) -> Vec<String> {
    let Some(words) = shlex::split(line) else {
        return vec![format!("cannot split `{}` as a shell would", line.trim())];
    };
    let mut out = Vec::new();
    for command in words.split(|w| matches!(w.as_str(), "|" | "||" | "&&" | ";" | "&")) {
        let Some((bin, args)) = our_command(command) else {
            continue;
        };
        let Some(cmd) = parser(&bin) else { continue };
        let mut argv = vec![bin.clone()];
        argv.extend(args);
        if let Err(e) = cmd.try_get_matches_from(&argv) {
            use clap::error::ErrorKind::{DisplayHelp, DisplayVersion};
            if !matches!(e.kind(), DisplayHelp | DisplayVersion) {
                let first = e.to_string();
                let first = first
                    .lines()
                    .next()
                    .unwrap_or("")
                    .trim_start_matches("error: ");
                out.push(format!(
                    "`{}` is refused by its parser: {first}",
                    argv.join(" ")
                ));
            }
        }
    }
    out
}

/// The binary a command runs and its arguments, if it is one of ours.
fn our_command(words: &[String]) -> Option<(String, Vec<String>)> {
    let mut rest = words
        .iter()
        .skip_while(|w| w.contains('=') && !w.starts_with('-'))
        .peekable();
    let mut first = rest.next()?;
    if first == "sudo" {
        // sudo's own options: -u USER, -g GROUP, and flags.
        loop {
            first = rest.next()?;
            match first.as_str() {
                "-u" | "-g" => {
                    rest.next()?;
                }
                f if f.starts_with('-') => {}
                _ => break,
            }
        }
    }
    let bin = first.rsplit('/').next().unwrap_or(first).to_string();
    parser(&bin)?;
    let args = rest
        .filter(|w| !(w.starts_with('>') || w.starts_with("2>") || w.starts_with('<')))
        .cloned()
        .collect();
    Some((bin, args))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn our_commands_are_parsed_others_skipped() {
        let good = "```sh\n$ motionctl jog X --speed -5   # hold to run\n\
                    sudo -u motion motionctl status --json | jq .\n\
                    ./target/release/motion-supervisor home --config deploy/gantry.toml\n\
                    cargo build --release && ./target/release/motion-supervisor home\n\
                    echo -n 'pw' | motion-opcua --config /etc/motion/machine.toml hash-password\n\
                    motion-io scan \\\n  --interface eth0\n\
                    RUST_LOG=debug motion-supervisor check --json 2>/dev/null\n\
                    systemctl enable --now motion-supervisor\n```\n\
                    ```text\nmotionctl bogus\n```\n";
        assert_eq!(check(good), []);
        let bad = "\n```sh\nmotionctl jog X --sped 5\nmotionctl move X\nmotion-io scan\n\
                   motion-supervisor home --parallell\nmotionctl stop 'X\n```\n";
        let p = check(bad);
        let lines: Vec<usize> = p.iter().map(|(l, _)| *l).collect();
        assert_eq!(lines, [3, 4, 5, 6, 7], "{p:?}");
        assert!(p[0].1.contains("--sped"), "{p:?}");
    }
}
