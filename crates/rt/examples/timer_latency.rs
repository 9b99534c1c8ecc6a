//! 1 kHz loop on a SCHED_FIFO thread with an RT pool: prints the checklist,
//! what `enter_realtime` applied, wake-up latency percentiles, missed
//! periods and the system-allocator calls made inside the loop.
//!
//! `cargo run --release -p motion-rt --example timer_latency -- [cycles] [cpu]`

use std::hint::black_box;
use std::rc::Rc;

use motion_rt::counting::system_calls_on_this_thread;
use motion_rt::{check_environment, enter_realtime, rt_pool, PeriodicTimer, RtAllocator, RtConfig};

#[global_allocator]
static ALLOC: RtAllocator = RtAllocator;

fn main() {
    let mut args = std::env::args().skip(1);
    let cycles: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(1000);
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cpu: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(cpus - 1);
    let cfg = RtConfig {
        cpu: Some(cpu),
        ..RtConfig::default()
    };
    for line in check_environment(&cfg) {
        println!("env  {line}");
    }

    let handle = std::thread::spawn(move || {
        let report = enter_realtime(&cfg);
        println!("rt   {report}");
        if let Err(e) = rt_pool::enter(1 << 20) {
            println!("pool {e}");
        }
        let mut latencies = Vec::with_capacity(cycles);
        let mut timer = PeriodicTimer::new(1_000_000);
        let calls_before = system_calls_on_this_thread();
        for i in 0..cycles {
            let w = timer.wait();
            latencies.push(w.latency_ns);
            // Stand-in for iceoryx2's per-sample Rc: served by the pool.
            black_box(Rc::new([i; 8]));
        }
        let calls = system_calls_on_this_thread() - calls_before;
        (
            latencies,
            timer.total_missed(),
            calls,
            rt_pool::thread_stats(),
        )
    });
    let (mut lat, missed, calls, pool) = handle.join().expect("rt thread");
    lat.sort_unstable();
    let pct = |p: usize| lat[(lat.len() - 1) * p / 100] as f64 / 1e3;
    println!(
        "loop {} cycles @ 1 ms: latency min {:.1} us  p50 {:.1} us  p99 {:.1} us  max {:.1} us; \
         missed {missed}; system-allocator calls in loop {calls}",
        lat.len(),
        pct(0),
        pct(50),
        pct(99),
        pct(100),
    );
    println!("pool {pool:?}");
}
