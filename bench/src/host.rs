//! The machine a bench runs on (the facts come from `motion_rt::host`),
//! other real-time threads seen while it runs, and the bench's own threads
//! set up like the cycle's ([`enter_rt`], the harness's placement).

pub use motion_harness::placement::enter as enter_rt;
pub use motion_rt::host::{cpus, loadavg, other_rt_tasks, Host};
use std::collections::BTreeSet;

/// Other real-time threads (not this bench's): each is warned about once,
/// when first seen, and all are reported at the end, since they compete
/// with what is measured.
pub struct OtherRt {
    /// The bench's name, for the warning.
    bench: &'static str,
    seen: BTreeSet<String>,
}

impl OtherRt {
    pub fn new(bench: &'static str) -> Self {
        Self {
            bench,
            seen: BTreeSet::new(),
        }
    }

    /// Looks for other real-time threads now (`when` says when, for the
    /// warning).
    pub fn note(&mut self, when: &str) {
        for t in other_rt_tasks() {
            if self.seen.insert(t.to_string()) {
                eprintln!(
                    "{}: WARNING: another real-time thread is running ({when}): {t} — \
                     it competes with what is measured; the numbers are not representative",
                    self.bench
                );
            }
        }
    }

    pub fn is_empty(&self) -> bool {
        self.seen.is_empty()
    }

    pub fn list(&self) -> Vec<String> {
        self.seen.iter().cloned().collect()
    }
}
