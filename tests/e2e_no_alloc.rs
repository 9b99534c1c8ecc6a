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

/// With the operations and a setpoint stream running: a jog, a move, a
/// gear, and a program streaming a sine at 1 kHz to the gear's master
/// (acquired after warm-up, so the cycle that maps the program's publisher
/// is measured too), the cycle still makes no system-allocator call.
#[test]
fn a_running_stream_makes_no_system_allocator_call() {
    use motion_control::Client;
    use std::time::{Duration, Instant};
    let _serial = serial();
    let cfg = Machine::fixture("ops")
        .set("axis.X.stream_timeout_ms", 500)
        .write("noalloc_stream");
    let mut run = spawn_supervisor(&["run", "--config", cfg.arg(), "--duration", "8", "--json"]);
    let motionctl = motion_harness::bins::test_bin("motionctl");
    motion_harness::daemon::wait_ready(
        &motionctl,
        &cfg.prefix,
        &mut run,
        motion_harness::Attached::All,
        Duration::from_secs(20),
    )
    .expect("ready");
    let p = cfg.prefix.as_str();
    ctl(p, &["home", "X"]).expect_code(0);
    ctl(p, &["enable", "X", "Z"]).expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || {
        motion_harness::daemon::status(&motionctl, p)
            .is_some_and(|s| s.axes.iter().take(2).all(|a| a.servo_action))
    }));
    ctl(p, &["jog", "Z", "--speed", "2", "--for", "0.5"]).expect_code(0);
    ctl(p, &["move", "Z", "--to", "0"]).expect_code(0);
    // Z geared to X while X streams (every cycle steps a geared slave).
    ctl(p, &["gear", "Z", "--master", "X", "--ratio", "-1"]).expect_code(0);
    {
        let mut c = Client::connect(p, None).expect("client");
        let mut s = c.stream("noalloc", &["X".to_string()]).expect("acquired");
        let t0 = Instant::now();
        let mut k = 0u64;
        while t0.elapsed() < Duration::from_secs(3) {
            k += 1;
            let t = k as f64 * 1e-3;
            // starts at rest: within stream_acceleration from the first
            s.publish(k * 1_000_000, &[0.5 * (1.0 - (t * 3.0).cos())], None)
                .expect("published");
            std::thread::sleep(Duration::from_micros(900));
        }
        s.release().expect("released");
    }
    let ended = run.wait(Duration::from_secs(30), Duration::from_secs(5));
    let v: RunReport = ended.expect_code(0).report();
    assert!(v.latency.cycles > 5000, "{v:#?}");
    let calls = &ended.json()["allocations"]["system_calls_in_cycle"];
    assert_eq!(calls, 0, "{}", ended.stdout);
    assert_clean(&cfg.prefix);
}
