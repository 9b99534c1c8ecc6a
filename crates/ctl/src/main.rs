//! `motionctl`: the operator's tool for a running `motion-supervisor` (see
//! `motionctl --help`). It joins the supervisor through its session file
//! and talks to it over the control and status services.

use motionctl::cli;
mod commands;

use clap::Parser;

fn main() {
    motion_rt::logging::init("motionctl");
    // A panic: the default message on stderr, and with --json one error
    // object on stdout (unless a report is out already).
    motion_report::panic::install_hook(std::env::args_os().any(|a| a == "--json"));
    let code = match cli::Cli::try_parse() {
        Ok(c) => commands::run(c),
        Err(e) => commands::argument_error(e),
    };
    std::process::exit(code);
}
