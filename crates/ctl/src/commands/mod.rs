//! The subcommands; each returns the exit code (see `motionctl --help`).

mod arm;
mod csv;
mod gear;
mod home;
mod jog;
mod moves;
mod simple;
mod stats;
mod status;
mod stream;
mod trace;

use crate::cli::{Cli, Command, Target};
use motion_control::{Client, ClientError, Operation, REQ_STOP, REQ_UNHOME};
use motion_report::ErrorEntry;
use simple::Simple;
use std::path::PathBuf;

/// How a command fails: a refused command line, and every other failure.
pub use motion_report::errors::{argument_error, fail};

pub const EXIT_OK: i32 = 0;
pub const EXIT_FAILED: i32 = 1;
pub const EXIT_USAGE: i32 = 2;
pub const EXIT_NO_SUPERVISOR: i32 = 3;

pub fn run(cli: Cli) -> i32 {
    let json = cli.command.json();
    let (prefix, runtime_dir) = match target(&cli.target) {
        Ok(t) => t,
        Err(errors) => return fail(json, errors, EXIT_USAGE),
    };
    if let Err(e) = motion_rt::termination::install() {
        return fail(json, vec![ErrorEntry::message(e)], EXIT_FAILED);
    }
    let mut client = match Client::connect(&prefix, runtime_dir.as_deref()) {
        Ok(c) => c,
        Err(e) => return client_error(json, &e),
    };
    match cli.command {
        Command::Status(a) => status::status(&mut client, &a),
        Command::Home(a) => home::home(&mut client, &a),
        Command::Stop(a) => simple::axes(&mut client, Simple::Kind(REQ_STOP), &a),
        Command::Unhome(a) => simple::axes(&mut client, Simple::Kind(REQ_UNHOME), &a),
        Command::Enable(a) => simple::axes(&mut client, Simple::Op(Operation::Enable), &a),
        Command::Disable(a) => simple::axes(&mut client, Simple::Op(Operation::Disable), &a),
        Command::Reset(a) => simple::axes(&mut client, Simple::Op(Operation::Reset), &a),
        Command::Jog(a) => jog::jog(&mut client, &a),
        Command::Move(a) => moves::move_axis(&mut client, &a),
        Command::Stream(a) => stream::stream(&mut client, &a),
        Command::Change(a) => simple::change(&mut client, &a),
        Command::Redefine(a) => simple::redefine(&mut client, &a),
        Command::Gear(a) => gear::gear(&mut client, &a),
        Command::Stats(a) => stats::stats(&mut client, &a),
        Command::Trace(a) => trace::trace(&mut client, &a),
        Command::Arm(a) => arm::arm(&mut client, &a),
        Command::Disarm(a) => simple::axes(&mut client, Simple::Op(Operation::Disarm), &a),
    }
}

/// The service prefix and runtime directory of the supervisor to talk to.
fn target(t: &Target) -> Result<(String, Option<PathBuf>), Vec<ErrorEntry>> {
    let mut prefix = "motion".to_string();
    let mut runtime_dir = None;
    if let Some(path) = &t.config {
        let (m, _) = motion_config::load(Some(path))
            .map_err(|problems| problems.iter().map(ErrorEntry::from).collect::<Vec<_>>())?;
        prefix = m.supervisor.service_prefix.clone();
        runtime_dir = m.supervisor.runtime_dir.clone();
    }
    if let Some(p) = &t.service_prefix {
        prefix = p.clone();
    }
    if let Some(d) = &t.runtime_dir {
        runtime_dir = Some(d.clone());
    }
    Ok((prefix, runtime_dir))
}

/// A client error, with the exit code it means.
pub fn client_error(json: bool, e: &ClientError) -> i32 {
    let code = match e {
        ClientError::NoSupervisor(_) | ClientError::Timeout { .. } | ClientError::WrongSession => {
            EXIT_NO_SUPERVISOR
        }
        _ => EXIT_FAILED,
    };
    fail(json, vec![ErrorEntry::message(e.to_string())], code)
}

/// The signal that interrupted us, as an exit code.
pub fn signal_code() -> Option<i32> {
    motion_rt::termination::received().map(|s| 128 + s)
}
