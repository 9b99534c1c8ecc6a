//! What the machine the bench runs on is like — kernel, preemption model,
//! CPUs, RT throttling — and other real-time threads seen during the bench
//! (another benchmark, say): printed and recorded with the numbers because
//! they decide what the numbers mean.

use motion_bench::sys;
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
/// when first seen, and all are reported at the end.
#[derive(Default)]
pub struct OtherRt(pub BTreeSet<String>);

impl OtherRt {
    pub fn note(&mut self, when: &str) {
        for t in sys::other_rt_tasks() {
            if self.0.insert(t.to_string()) {
                eprintln!(
                    "cpcost: WARNING: another real-time thread is running ({when}): {t} — \
                     it competes with the cycle; the numbers are not representative"
                );
            }
        }
    }

    pub fn list(&self) -> Vec<String> {
        self.0.iter().cloned().collect()
    }
}
