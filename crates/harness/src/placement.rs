//! Where a thread of the test process runs (the emulated EtherCAT drives;
//! the benches' spy, streaming program and measuring threads): pinned to a
//! CPU, SCHED_FIFO when a priority is given, memory locked — through
//! `motion-rt`, as the supervisor sets up its cycle.

/// Pins the calling thread to `cpu` (if given), SCHED_FIFO at `priority`
/// (if given), memory locked. Returns what the OS refused, as warnings.
pub fn enter(cpu: Option<usize>, priority: Option<i32>) -> Vec<String> {
    if let Some(priority) = priority {
        return motion_rt::enter_realtime(&motion_rt::RtConfig {
            cpu,
            priority,
            lock_memory: true,
            ..motion_rt::RtConfig::default()
        })
        .warnings;
    }
    // Normal scheduling: only the pinning (the crate motion-rt pins with)
    // and the memory lock.
    let pinned = cpu.map(motion_rt::pin_to_cpu).and_then(Result::err);
    use nix::sys::mman::{mlockall, MlockAllFlags as F};
    let locked = mlockall(F::MCL_CURRENT | F::MCL_FUTURE).err();
    let locked = locked.map(|e| format!("mlockall: {e}"));
    pinned.into_iter().chain(locked).collect()
}
