use clap::Parser;
use motion_supervisor::{cli, commands};

/// Every allocation of the process goes through the real-time aware
/// allocator: the cycle thread serves its own from a locked TLSF pool.
#[global_allocator]
static ALLOCATOR: motion_rt::RtAllocator = motion_rt::RtAllocator;

fn main() {
    motion_rt::logging::init("motion-supervisor");
    // A panic is logged (and with --json is one error object on stdout);
    // unwinding then drops the session, which stops every axis, ends the I/O
    // processes and cleans shared memory (Session::drop).
    std::panic::set_hook(Box::new(|info| log::error!("internal error: {info}")));
    motion_report::panic::install_hook(std::env::args_os().any(|a| a == "--json"));
    let code = match cli::Cli::try_parse() {
        Ok(c) => commands::run(c),
        Err(e) => commands::argument_error(e),
    };
    std::process::exit(code);
}
