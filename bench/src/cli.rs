//! Value parsers shared by the benches' clap command lines, for the checks
//! a `value_parser!` range cannot express: they depend on this machine.
//! Clap names the flag and the value in front of the message, so the
//! messages only say what is wrong with it.

use crate::sys;

/// A CPU index this process may use (`0..sys::cpus()`): a pinned
/// real-time thread on a CPU that is not there would fail only after the
/// bench has started its peers.
pub fn cpu(s: &str) -> Result<usize, String> {
    let cpu: usize = s.parse().map_err(|e| format!("{e}"))?;
    let n = sys::cpus();
    if cpu >= n {
        return Err(format!("this machine has {n} CPUs (0..={})", n - 1));
    }
    Ok(cpu)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_zero_exists_and_beyond_the_last_does_not() {
        assert_eq!(cpu("0"), Ok(0));
        assert!(cpu(&sys::cpus().to_string()).is_err());
        assert!(cpu("-1").is_err());
        assert!(cpu("x").is_err());
    }
}
