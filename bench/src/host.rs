//! What the machine a bench runs on is like — kernel, preemption model,
//! CPUs, RT throttling, load — and other real-time threads seen during the
//! bench (another benchmark, say): printed and recorded with the numbers
//! because they decide what the numbers mean. Shared by the benches.

use crate::sys;
use std::collections::BTreeSet;

/// The kernel and its real-time settings, read once at the start.
pub struct Env {
    pub kernel: String,
    pub preemption: String,
    pub is_rt: bool,
    pub cpus: usize,
    pub throttling: String,
    /// Load average at the start.
    pub load_before: String,
}

impl Env {
    pub fn probe() -> Self {
        let (preemption, is_rt) = sys::preemption();
        Env {
            kernel: sys::kernel(),
            preemption,
            is_rt,
            cpus: sys::cpus(),
            throttling: sys::rt_throttling(),
            load_before: sys::loadavg(),
        }
    }
}

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
        for t in sys::other_rt_tasks() {
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
