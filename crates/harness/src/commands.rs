//! The binaries as a test runs them: `motion-supervisor`, `motionctl` and
//! `motion-io` from the test's profile directory, run to completion or
//! started as a [`Running`] child.

use std::process::Command;

use crate::bins::test_bin;
use crate::process::{Ended, Running};

fn command(name: &str, args: &[&str]) -> Command {
    let mut c = Command::new(test_bin(name));
    c.args(args);
    c
}

/// `motion-supervisor <args>`, spawning the test's `motion-io`.
pub fn supervisor_command(args: &[&str]) -> Command {
    let mut c = command("motion-supervisor", args);
    c.env("MOTION_IO_BIN", test_bin("motion-io"));
    c
}

/// Runs `motion-supervisor <args>` to completion.
pub fn supervisor(args: &[&str]) -> Ended {
    spawn_supervisor(args).finish()
}

/// Starts `motion-supervisor <args>`.
pub fn spawn_supervisor(args: &[&str]) -> Running {
    Running::start(&mut supervisor_command(args), "motion-supervisor")
}

/// Runs `motionctl <args>` to completion.
pub fn motionctl(args: &[&str]) -> Ended {
    spawn_motionctl(args).finish()
}

/// Starts `motionctl <args>`.
pub fn spawn_motionctl(args: &[&str]) -> Running {
    Running::start(&mut command("motionctl", args), "motionctl")
}

/// `motionctl --service-prefix P <args>` to completion.
pub fn ctl(prefix: &str, args: &[&str]) -> Ended {
    let mut all = vec!["--service-prefix", prefix];
    all.extend_from_slice(args);
    motionctl(&all)
}

/// Starts `motion-io <args>`.
pub fn spawn_io(args: &[&str]) -> Running {
    Running::start(&mut command("motion-io", args), "motion-io")
}
