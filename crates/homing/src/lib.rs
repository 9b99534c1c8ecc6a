//! Sans-I/O homing engine (see crate docs in later commits).
pub mod codes;
pub mod config;
pub mod io;

pub use config::*;
pub use io::*;
