//! The bare echo peer, `ipc --role echo`: this binary re-run by the bench
//! for the `bare-*` modes. It answers every ping with a pong through plain
//! iceoryx2 ports, so that the bench can tell what motion-io adds to the
//! round trip from what iceoryx2 itself costs.
//!
//! Its command line is its own parser, not a subcommand of the bench's:
//! its flags mean other things than the bench's flags of the same name.

use clap::{Parser, ValueEnum};
use motion_bench::bare::{self, BareSide, PING, PONG};
use motion_bench::host;
use motion_bench::proc;
use motion_ipc::{cleanup_domain, Domain};
use std::time::{Duration, Instant};

/// The peer's role (`echo`, the only one).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Role {
    /// Answer every ping with a pong carrying its sequence number.
    Echo,
}

#[derive(Debug, Parser)]
#[command(
    name = "ipc --role echo",
    about = "The bare iceoryx2 echo peer of `ipc` (started by it): answers every ping under \
             PREFIX with a pong, until SIGTERM/SIGINT or the bench's end."
)]
pub struct EchoOpts {
    /// What this process is.
    #[arg(long, value_enum)]
    pub role: Role,
    /// Service prefix of the bench's mode (the domain it joins).
    #[arg(long, value_name = "PREFIX")]
    pub prefix: String,
    /// CPU to pin to.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub cpu: usize,
    /// SCHED_FIFO priority (default: normal scheduling).
    #[arg(long, value_name = "P", allow_negative_numbers = true)]
    pub priority: Option<i32>,
    /// Busy-poll the subscriber instead of waiting on the event.
    #[arg(long)]
    pub spin: bool,
}

/// The echo's arguments as the bench spawns it: under `prefix` on `cpu`,
/// SCHED_FIFO at `priority`, or spinning if None.
pub fn args(prefix: &str, cpu: usize, priority: Option<i32>) -> Vec<String> {
    let a = [
        "--role",
        "echo",
        "--prefix",
        prefix,
        "--cpu",
        &cpu.to_string(),
    ]
    .map(String::from);
    let how = match priority {
        None => vec!["--spin".to_string()],
        Some(p) => vec!["--priority".into(), p.to_string()],
    };
    a.into_iter().chain(how).collect()
}

/// The command line is the echo's: `--role` comes first.
pub fn wanted(args: &[String]) -> bool {
    args.get(1)
        .is_some_and(|a| a == "--role" || a.starts_with("--role="))
}

/// The echo peer's `main`: its exit code.
pub fn main() -> i32 {
    let o = EchoOpts::parse();
    // gone with the bench, however it ends
    let _ = nix::sys::prctl::set_pdeathsig(nix::sys::signal::Signal::SIGTERM);
    proc::install_stop_handler();
    for w in host::enter_rt(Some(o.cpu), o.priority) {
        eprintln!("ipc echo: warning: {w}");
    }
    match echo(&o.prefix, o.spin) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("ipc echo: {e}");
            1
        }
    }
}

/// Answers every ping with a pong carrying its sequence number, until
/// SIGTERM/SIGINT. Event mode sleeps in `ppoll` on the listener's
/// descriptor; spin mode polls the subscriber.
fn echo(prefix: &str, spin: bool) -> Result<(), String> {
    let until = Instant::now() + Duration::from_secs(10);
    let domain = loop {
        match Domain::join(prefix, None) {
            Ok(d) => break d,
            Err(e) if Instant::now() > until => return Err(e.to_string()),
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    };
    let node = domain
        .create_node("bench-echo")
        .map_err(|e| e.to_string())?;
    let mut x = BareSide::<PONG, PING>::create(&node, prefix, "pong", "ping")?;
    let r = bare::echo(&mut x, spin, proc::stop_requested);
    drop((x, node));
    let _ = cleanup_domain(&domain);
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_spawned_command_lines_are_the_echos_and_parse() {
        EchoOpts::command().debug_assert();
        let argv = |a: Vec<String>| [vec!["ipc".to_string()], a].concat();
        let event = argv(args("mbi7m1", 0, Some(70)));
        let shown = "--role echo --prefix mbi7m1 --cpu 0 --priority 70";
        assert!(event[1..].join(" ") == shown && wanted(&event));
        let o = EchoOpts::try_parse_from(&event).unwrap();
        assert_eq!((o.role, o.prefix.as_str()), (Role::Echo, "mbi7m1"));
        assert_eq!((o.cpu, o.priority, o.spin), (0, Some(70), false));
        let spin = argv(args("mbi7m3", 1, None));
        let shown = "--role echo --prefix mbi7m3 --cpu 1 --spin";
        assert_eq!(spin[1..].join(" "), shown);
        let o = EchoOpts::try_parse_from(&spin).unwrap();
        assert_eq!((o.cpu, o.priority, o.spin), (1, None, true));
        let v = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert!(wanted(&v(&["ipc", "--role=echo", "--prefix", "p"])));
        assert!(!wanted(&v(&["ipc"])) && !wanted(&v(&["ipc", "--count", "5", "--role", "echo"])));
        let parse = |a: &[&str]| EchoOpts::try_parse_from(a.iter().copied());
        assert!(parse(&["ipc", "--role", "echo"]).is_err());
        assert!(parse(&["ipc", "--role", "ping", "--prefix", "p"]).is_err());
    }
}
