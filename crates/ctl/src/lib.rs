//! The library side of `motionctl`: only its command line, so that the man
//! pages and shell completions are generated from the clap definition the
//! binary parses with (`crates/docgen`). Everything else lives in the binary.

pub mod cli;
pub mod spec_args;
