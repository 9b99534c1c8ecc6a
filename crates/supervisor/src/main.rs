use clap::Parser;
use motion_supervisor::{cli, commands};

/// Every allocation of the process goes through the real-time aware
/// allocator: the cycle thread serves its own from a locked TLSF pool.
#[global_allocator]
static ALLOCATOR: motion_rt::RtAllocator = motion_rt::RtAllocator;

fn main() {
    motion_rt::logging::init("motion-supervisor");
    let code = match cli::Cli::try_parse() {
        Ok(c) => commands::run(c),
        Err(e) => commands::argument_error(e),
    };
    std::process::exit(code);
}
