//! PeriodicTimer behaviour on real threads. Timings are printed, never
//! asserted: only behaviour (deadline arithmetic, missed accounting, EINTR)
//! is checked.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::Duration;

use motion_rt::{enter_realtime, PeriodicTimer, RtConfig, SchedPolicy, Wakeup};

fn last_cpu() -> usize {
    thread::available_parallelism().map_or(1, |n| n.get()) - 1
}

fn check_deadline_chain(wakes: &[Wakeup], period: u64) {
    for pair in wakes.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        assert_eq!(
            b.deadline_ns,
            a.deadline_ns + (1 + a.missed) * period,
            "deadline chain broken: {a:?} -> {b:?}"
        );
    }
    for w in wakes {
        assert!(w.woke_ns >= w.deadline_ns, "woke before deadline: {w:?}");
        assert_eq!(w.latency_ns, w.woke_ns - w.deadline_ns);
        assert_eq!(w.missed, w.latency_ns / period);
    }
}

#[test]
fn one_ms_for_200_cycles_on_a_fifo_thread() {
    const PERIOD: u64 = 1_000_000;
    let (report, wakes, total_missed) = thread::spawn(|| {
        let report = enter_realtime(&RtConfig {
            cpu: Some(last_cpu()),
            priority: 80,
            lock_memory: true,
            prefault_stack: 128 * 1024,
        });
        let mut wakes = Vec::with_capacity(200);
        let mut timer = PeriodicTimer::new(PERIOD);
        for _ in 0..200 {
            wakes.push(timer.wait());
        }
        (report, wakes, timer.total_missed())
    })
    .join()
    .unwrap();

    println!("enter_realtime: {report}");
    if report.warnings.is_empty() {
        assert_eq!(report.policy, SchedPolicy::Fifo);
        assert_eq!(report.priority, 80);
        assert_eq!(report.cpu, Some(last_cpu()));
    }
    check_deadline_chain(&wakes, PERIOD);
    assert_eq!(total_missed, wakes.iter().map(|w| w.missed).sum::<u64>());

    let mut lat: Vec<u64> = wakes.iter().map(|w| w.latency_ns).collect();
    lat.sort_unstable();
    println!(
        "1 ms x 200 on {}: wake-up latency min {:.1} us, p50 {:.1} us, p99 {:.1} us, max {:.1} us, missed {}",
        report.policy,
        lat[0] as f64 / 1e3,
        lat[lat.len() / 2] as f64 / 1e3,
        lat[lat.len() * 99 / 100] as f64 / 1e3,
        lat[lat.len() - 1] as f64 / 1e3,
        total_missed
    );
}

#[test]
fn overrun_of_five_periods_counts_missed_and_keeps_phase() {
    const PERIOD: u64 = 10_000_000;
    let mut timer = PeriodicTimer::new(PERIOD);
    let first = timer.wait();
    // The "cycle" overruns: 5 periods of work.
    thread::sleep(Duration::from_nanos(5 * PERIOD));
    let late = timer.wait();
    let next = timer.wait();
    println!("first {first:?}\nlate {late:?}\nnext {next:?}");

    assert_eq!(
        late.deadline_ns,
        first.deadline_ns + (1 + first.missed) * PERIOD
    );
    assert!(
        late.missed == 4 || late.missed == 5,
        "expected 4 or 5 missed, got {late:?}"
    );
    assert_eq!(
        next.deadline_ns,
        late.deadline_ns + (1 + late.missed) * PERIOD
    );
    assert_eq!(
        (next.deadline_ns - first.deadline_ns) % PERIOD,
        0,
        "phase lost"
    );
    assert!(next.deadline_ns > late.woke_ns);
    assert_eq!(
        timer.total_missed(),
        first.missed + late.missed + next.missed
    );
}

static SIGNALS: AtomicU64 = AtomicU64::new(0);

extern "C" fn on_sigusr1(_: libc::c_int) {
    SIGNALS.fetch_add(1, Ordering::Relaxed);
}

#[test]
fn signals_do_not_cut_the_sleep_short() {
    use nix::sys::signal::{sigaction, SaFlags, SigAction, SigHandler, SigSet, Signal};
    // No SA_RESTART: clock_nanosleep returns EINTR after each handler.
    let action = SigAction::new(
        SigHandler::Handler(on_sigusr1),
        SaFlags::empty(),
        SigSet::empty(),
    );
    // SAFETY: the handler only touches an atomic.
    unsafe { sigaction(Signal::SIGUSR1, &action) }.unwrap();

    const PERIOD: u64 = 5_000_000;
    let stop = Arc::new(AtomicBool::new(false));
    let (tid_tx, tid_rx) = std::sync::mpsc::channel();
    let sleeper = {
        let stop = Arc::clone(&stop);
        thread::spawn(move || {
            // SAFETY: pthread_self is always valid.
            tid_tx
                .send(unsafe { libc::pthread_self() } as usize)
                .unwrap();
            let mut timer = PeriodicTimer::new(PERIOD);
            let wakes: Vec<Wakeup> = (0..20).map(|_| timer.wait()).collect();
            stop.store(true, Ordering::Relaxed);
            wakes
        })
    };
    let tid = tid_rx.recv().unwrap() as libc::pthread_t;
    let mut sent = 0u64;
    while !stop.load(Ordering::Relaxed) {
        // SAFETY: the sleeper thread is alive until `stop` is set... and
        // joinable (not yet joined) afterwards, so `tid` stays valid.
        unsafe { libc::pthread_kill(tid, libc::SIGUSR1) };
        sent += 1;
        thread::sleep(Duration::from_micros(700));
    }
    let wakes = sleeper.join().unwrap();
    let got = SIGNALS.load(Ordering::Relaxed);
    println!("signals sent {sent}, handled {got}");
    assert!(
        got >= 5,
        "the sleeper was not interrupted often enough: {got}"
    );
    // Every wait still ran to its absolute deadline.
    check_deadline_chain(&wakes, PERIOD);
}
