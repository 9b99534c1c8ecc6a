//! The command line (fixed names; docs/commands.md, `motion-opcua`).

use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// An OPC UA server for a running motion-supervisor: the machine's axes, I/O
/// processes and latency statistics as an address space, Home/Stop/Unhome and
/// Enable/Disable/Reset/Jog/Move as methods. Secure by default (Sign & Encrypt, trusted client certificates,
/// anonymous read-only, operators by password hash).
#[derive(Parser, Debug)]
#[command(name = "motion-opcua", version)]
pub struct Cli {
    /// The machine config (the daemon's), with its [opcua] section.
    #[arg(long, value_name = "FILE")]
    pub config: PathBuf,
    /// The daemon's runtime directory (its session file), as given to
    /// `motion-supervisor run --runtime-dir`; default: the config's.
    #[arg(long, value_name = "DIR")]
    pub runtime_dir: Option<PathBuf>,
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Reads a password on stdin and prints its salted argon2 hash alone on
    /// the last line (for [[opcua.user]] password_hash).
    HashPassword,
    /// Trusts a client certificate (DER or PEM): copied into the trust list,
    /// effective for the next connection, without a restart.
    Trust {
        /// The client's certificate file.
        cert: PathBuf,
    },
}
