//! What the machine the bench runs on is like: kernel, preemption model,
//! CPUs, RT throttling, and other real-time threads. Printed and recorded
//! with the numbers because they decide what the numbers mean.

use motion_bench::sys;
use std::collections::BTreeSet;

/// The kernel and its real-time settings, read once at the start.
pub struct Env {
    pub kernel: String,
    pub preemption: String,
    pub is_rt: bool,
    pub cpus: usize,
    pub throttling: String,
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
        }
    }
}

/// Other real-time threads seen during the bench: each is warned about
/// once, when first seen, and all are reported at the end, since they
/// compete with both tools.
#[derive(Default)]
pub struct OtherRt(pub BTreeSet<String>);

impl OtherRt {
    /// Looks for other real-time threads now (`when` says when, for the
    /// warning).
    pub fn note(&mut self, when: &str) {
        for t in sys::other_rt_tasks() {
            if self.0.insert(t.to_string()) {
                eprintln!(
                    "jitter: WARNING: another real-time thread is running ({when}): {t} — \
                     it competes with both tools; the numbers are not representative"
                );
            }
        }
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn list(&self) -> Vec<String> {
        self.0.iter().cloned().collect()
    }
}
