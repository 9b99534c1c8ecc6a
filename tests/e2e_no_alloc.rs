//! The real-time cycle makes no call into the system allocator.
//!
//! iceoryx2 0.10 allocates one `Rc` per loaned sample, so the cycle does
//! allocate — from the thread's TLSF pool. The supervisor counts, on the
//! real-time thread, every call that reached the system allocator after
//! warm-up, over thousands of cycles of homing the default machine.

use motion_harness::*;
use motion_report::{HomeReport, RunReport};

#[test]
fn homing_the_default_machine_makes_no_system_allocator_call() {
    let _serial = serial();
    let prefix = unique_prefix("noalloc");
    let run = supervisor(&["home", "--json", "--service-prefix", &prefix]);
    let v: HomeReport = run.expect_code(0).report();
    let cycles = v.run.latency.cycles;
    let sys = v.run.allocations.system_calls_in_cycle;
    let pool = v.run.allocations.pool_allocs_in_cycle;
    assert!(cycles > 5000, "too few cycles measured: {cycles}");
    assert_eq!(sys, 0, "system-allocator calls in {cycles} cycles");
    // The counter is not vacuous: iceoryx2's per-sample allocation is there,
    // served by the pool (one per published frame).
    assert!(
        pool as f64 > 0.9 * cycles as f64,
        "pool allocations {pool} in {cycles} cycles"
    );
    assert_clean(&prefix);
}

#[test]
fn run_mode_makes_no_system_allocator_call() {
    let _serial = serial();
    let prefix = unique_prefix("noalloc_run");
    let run = supervisor(&[
        "run",
        "--duration",
        "3",
        "--json",
        "--service-prefix",
        &prefix,
    ]);
    let v: RunReport = run.expect_code(0).report();
    assert!(v.latency.cycles > 2000, "{v:#?}");
    // From the JSON itself: the typed field would read 0 were it missing.
    let calls = &run.json()["allocations"]["system_calls_in_cycle"];
    assert_eq!(calls, 0, "{}", run.stdout);
    assert_clean(&prefix);
}
