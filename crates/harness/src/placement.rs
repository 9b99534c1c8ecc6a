//! Where the harness's own threads run (the frame spy, the emulated
//! EtherCAT drives): pinned to a CPU, SCHED_FIFO when a priority is given,
//! memory locked — through `motion-rt`, as the supervisor sets up its cycle.

/// Pins the calling thread to `cpu`, SCHED_FIFO at `priority` if given,
/// memory locked. Returns what the OS refused, as warnings.
pub fn enter(cpu: usize, priority: Option<i32>) -> Vec<String> {
    if let Some(priority) = priority {
        return motion_rt::enter_realtime(&motion_rt::RtConfig {
            cpu: Some(cpu),
            priority,
            lock_memory: true,
            ..motion_rt::RtConfig::default()
        })
        .warnings;
    }
    // Normal scheduling: only the pinning (the crate motion-rt pins with)
    // and the memory lock.
    let mut w = Vec::new();
    if !core_affinity::set_for_current(core_affinity::CoreId { id: cpu }) {
        w.push(format!("cannot pin to cpu {cpu}"));
    }
    use nix::sys::mman::{mlockall, MlockAllFlags};
    if let Err(e) = mlockall(MlockAllFlags::MCL_CURRENT | MlockAllFlags::MCL_FUTURE) {
        w.push(format!("mlockall: {e}"));
    }
    w
}
