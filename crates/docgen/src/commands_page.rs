//! The command reference of `docs/commands.md`, from the clap definitions
//! the binaries parse with: per binary and subcommand its usage, what it
//! does, and each argument with its help.

use clap::{Arg, Command};

pub fn render(commands: &[Command]) -> String {
    let mut out = String::new();
    for cmd in commands {
        let mut cmd = cmd.clone().disable_help_subcommand(true);
        cmd.build();
        section(&cmd, 2, &mut out);
    }
    out
}

fn section(cmd: &Command, level: usize, out: &mut String) {
    let name = cmd.get_bin_name().unwrap_or(cmd.get_name());
    *out += &format!("{} `{name}`\n\n", "#".repeat(level));
    if let Some(about) = cmd.get_long_about().or(cmd.get_about()) {
        *out += &format!("{}\n\n", about.to_string().trim());
    }
    let usage = cmd.clone().render_usage().to_string();
    let usage = usage.trim_start_matches("Usage:").trim();
    *out += &format!("```text\n{usage}\n```\n\n");
    let args: Vec<&Arg> = cmd
        .get_arguments()
        .filter(|a| !a.is_hide_set() && !matches!(a.get_id().as_str(), "help" | "version"))
        .collect();
    if !args.is_empty() {
        *out += "| argument | meaning |\n|---|---|\n";
        for a in args {
            *out += &format!("| `{}` | {} |\n", spelled(a), help(a));
        }
        out.push('\n');
    }
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        section(sub, (level + 1).min(6), out);
    }
}

/// `--speed <V>`, `-c, --config <FILE>`, `<AXIS>...`.
fn spelled(a: &Arg) -> String {
    let value = a
        .get_value_names()
        .map(|v| {
            v.iter()
                .map(|n| format!("<{n}>"))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .unwrap_or_else(|| format!("<{}>", a.get_id().as_str().to_uppercase()));
    let takes = a.get_num_args().is_some_and(|n| n.takes_values());
    let many = a.get_num_args().is_some_and(|n| n.max_values() > 1);
    let dots = if many || matches!(a.get_action(), clap::ArgAction::Append) {
        "..."
    } else {
        ""
    };
    let mut names = Vec::new();
    if let Some(s) = a.get_short() {
        names.push(format!("-{s}"));
    }
    if let Some(l) = a.get_long() {
        names.push(format!("--{l}"));
    }
    match (names.is_empty(), takes) {
        (true, _) => format!("{value}{dots}"),
        (false, true) => format!("{} {value}{dots}", names.join(", ")),
        (false, false) => names.join(", "),
    }
}

fn help(a: &Arg) -> String {
    let mut text = a
        .get_long_help()
        .or(a.get_help())
        .map(|h| h.to_string())
        .unwrap_or_default();
    let defaults: Vec<String> = a
        .get_default_values()
        .iter()
        .map(|v| v.to_string_lossy().into_owned())
        .collect();
    let takes = a.get_num_args().is_some_and(|n| n.takes_values());
    if !defaults.is_empty() && takes {
        text += &format!(" (default: {})", defaults.join(", "));
    }
    let possible: Vec<String> = a
        .get_possible_values()
        .iter()
        .filter(|p| !p.is_hide_set())
        .map(|p| format!("`{}`", p.get_name()))
        .collect();
    if !possible.is_empty() && takes {
        text += &format!(" (one of {})", possible.join(", "));
    }
    crate::markdown::cell(&text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_command_and_argument_is_on_the_page() {
        let page = render(&crate::assets::commands());
        for want in [
            "## `motion-supervisor`",
            "### `motion-supervisor check`",
            "### `motionctl jog`",
            "| `--speed <V>` |",
            "## `motion-io`",
            "### `motion-opcua trust`",
        ] {
            assert!(page.contains(want), "{want} missing in\n{page}");
        }
    }
}
