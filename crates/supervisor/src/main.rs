use motion_supervisor::{cli, commands};

/// Every allocation of the process goes through the real-time aware
/// allocator: the cycle thread serves its own from a locked TLSF pool.
#[global_allocator]
static ALLOCATOR: motion_rt::RtAllocator = motion_rt::RtAllocator;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let code = match cli::parse(&args) {
        Ok(cli::Cli::Help) => {
            print!("{}", cli::USAGE);
            0
        }
        Ok(c) => commands::run(c),
        Err(e) => {
            eprintln!("motion-supervisor: {e}\n\n{}", cli::USAGE);
            2
        }
    };
    std::process::exit(code);
}
