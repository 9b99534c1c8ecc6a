//! RtAllocator + rt_pool behaviour, with RtAllocator as this test binary's
//! global allocator. Every test works on deltas of its own pool's counters,
//! so tests running in parallel do not disturb each other.

use std::hint::black_box;
use std::rc::Rc;
use std::sync::mpsc;
use std::thread;

use motion_rt::counting::{system_calls_during, system_calls_on_this_thread};
use motion_rt::rt_pool::{self, PoolError, PoolStats};
use motion_rt::RtAllocator;

#[global_allocator]
static A: RtAllocator = RtAllocator;

fn delta(after: PoolStats, before: PoolStats) -> PoolStats {
    PoolStats {
        pool_allocs: after.pool_allocs - before.pool_allocs,
        pool_frees: after.pool_frees - before.pool_frees,
        remote_frees: after.remote_frees - before.remote_frees,
        system_allocs_on_rt_thread: after.system_allocs_on_rt_thread
            - before.system_allocs_on_rt_thread,
        fallback_allocs: after.fallback_allocs - before.fallback_allocs,
        bytes_in_use: after.bytes_in_use.wrapping_sub(before.bytes_in_use),
        high_water: after.high_water,
    }
}

/// A cycle-like workload: Boxes, Vecs (grown by realloc, some zeroed), Rc's
/// and Strings of varied sizes; every third Box goes to another thread.
/// Returns how many Boxes were sent.
fn workload(iterations: usize, tx: &mpsc::Sender<Box<[u8]>>) -> usize {
    let mut sent = 0;
    for i in 0..iterations {
        let size = 1 + (i * 37) % 3000;
        let fill = if i % 4 == 0 { 0 } else { i as u8 }; // 0 => alloc_zeroed
        let b: Box<[u8]> = vec![fill; size].into_boxed_slice();
        assert_eq!(b[size - 1], fill);

        let mut v: Vec<u64> = Vec::new();
        for k in 0..(i % 97) {
            v.push(k as u64); // grows through realloc
        }
        v.shrink_to_fit();
        black_box(&v);

        let r = Rc::new([i; 5]);
        let r2 = Rc::clone(&r);
        drop(r);
        assert_eq!(r2[4], i);

        let s = format!("cycle {i} {size}");
        black_box(&s);

        if i % 64 == 0 {
            let big = vec![7u8; 64 * 1024 + i];
            black_box(&big);
        }

        if i % 3 == 0 {
            tx.send(b).expect("receiver alive");
            sent += 1;
        } else {
            drop(b);
        }
    }
    sent
}

/// Receives Boxes, checks and drops them (remote frees), then reports.
fn spawn_receiver(
    rx: mpsc::Receiver<Box<[u8]>>,
    done: mpsc::Sender<usize>,
) -> thread::JoinHandle<()> {
    thread::spawn(move || {
        let mut n = 0;
        for b in rx {
            assert!(!b.is_empty());
            drop(b);
            n += 1;
        }
        done.send(n).unwrap();
    })
}

#[test]
fn rt_cycle_makes_no_system_calls_and_all_memory_returns() {
    // Channels created BEFORE the RT thread enters its pool.
    let (tx, rx) = mpsc::channel::<Box<[u8]>>();
    let (done_tx, done_rx) = mpsc::channel::<usize>();
    let receiver = spawn_receiver(rx, done_tx);

    let rt = thread::spawn(move || {
        // Warm-up outside the cycle: the first blocking recv of a thread
        // creates std's thread-local channel Context. Let that happen now,
        // from System, not later from the pool (where it would stay in use
        // until the thread exits).
        let _ = done_rx.recv_timeout(std::time::Duration::from_millis(1));
        // Big enough to hold every Box in flight even if the receiver does
        // not get the CPU during the loop (2-CPU machine, parallel tests).
        let info = rt_pool::enter(16 << 20).expect("enter pool");
        let before = rt_pool::thread_stats().unwrap();

        let (sent, calls) = system_calls_during(|| workload(10_000, &tx));
        let after_loop = rt_pool::thread_stats().unwrap();

        // Outside the measured cycle: tear down and wait for the receiver.
        drop(tx);
        let received = done_rx.recv().unwrap();
        rt_pool::drain_remote_frees();
        let end = rt_pool::thread_stats().unwrap();
        assert!(rt_pool::leave());
        (info, before, after_loop, end, sent, received, calls)
    });
    let (info, before, after_loop, end, sent, received, calls) = rt.join().unwrap();
    receiver.join().unwrap();

    let loop_delta = delta(after_loop, before);
    let total = delta(end, before);
    println!("pool {info:?}\nloop {loop_delta:?}\ntotal {total:?}");

    assert_eq!(
        calls, 0,
        "RT thread called the system allocator in the cycle"
    );
    assert_eq!(loop_delta.system_allocs_on_rt_thread, 0);
    assert_eq!(loop_delta.fallback_allocs, 0);
    assert!(loop_delta.pool_allocs > 10_000, "{loop_delta:?}");
    assert_eq!(received, sent);
    assert!(total.remote_frees >= sent as u64, "{total:?}");
    assert_eq!(total.pool_allocs, total.pool_frees, "{total:?}");
    assert_eq!(
        end.bytes_in_use, before.bytes_in_use,
        "memory did not return"
    );
    assert!(end.high_water > 64 * 1024);
}

#[test]
fn same_workload_without_pool_does_reach_system() {
    // The check that makes the test above meaningful: the same workload on
    // a thread that never entered a pool is counted.
    let (tx, rx) = mpsc::channel::<Box<[u8]>>();
    let (done_tx, done_rx) = mpsc::channel::<usize>();
    let receiver = spawn_receiver(rx, done_tx);
    let calls = thread::spawn(move || {
        let (_, calls) = system_calls_during(|| workload(500, &tx));
        assert!(rt_pool::thread_stats().is_none());
        drop(tx);
        done_rx.recv().unwrap();
        calls
    })
    .join()
    .unwrap();
    receiver.join().unwrap();
    assert!(calls > 1000, "system counter is vacuous: {calls}");
}

#[test]
fn thread_that_never_entered_uses_system() {
    let (calls, stats) = thread::spawn(|| {
        let (b, calls) = system_calls_during(|| black_box(Box::new([1u8; 100])));
        let (_, free_calls) = system_calls_during(|| drop(black_box(b)));
        assert_eq!(free_calls, 1);
        (calls, rt_pool::thread_stats())
    })
    .join()
    .unwrap();
    assert_eq!(calls, 1);
    assert!(stats.is_none());
    assert!(system_calls_on_this_thread() > 0);
}

#[test]
fn exhaustion_falls_back_to_system_and_is_counted() {
    thread::spawn(|| {
        let info = rt_pool::enter(64 * 1024).expect("enter pool");
        let before = rt_pool::thread_stats().unwrap();
        let calls_before = system_calls_on_this_thread();

        // Fill the pool with 1 KiB blocks until one falls back.
        let mut blocks: Vec<Box<[u8; 1024]>> = Vec::with_capacity(4096);
        while rt_pool::thread_stats().unwrap().fallback_allocs == before.fallback_allocs {
            assert!(blocks.len() < 4096, "pool never ran out");
            let mut b = Box::new([0u8; 1024]);
            b[1023] = blocks.len() as u8;
            blocks.push(b);
        }
        // A request larger than the whole pool falls back too.
        let mut huge: Vec<u8> = Vec::with_capacity(info.len + 1);
        huge.push(1);
        let mid = delta(rt_pool::thread_stats().unwrap(), before);
        assert!(mid.fallback_allocs >= 2, "{mid:?}");
        assert!(mid.system_allocs_on_rt_thread >= 2, "{mid:?}");
        assert!(system_calls_on_this_thread() - calls_before >= 2);
        for (i, b) in blocks.iter().enumerate() {
            assert_eq!(b[1023], i as u8);
        }

        // Freed again: System blocks go to System, pool blocks to the pool.
        drop(huge);
        drop(blocks);
        let end = rt_pool::thread_stats().unwrap();
        assert_eq!(end.bytes_in_use, before.bytes_in_use);
        // After freeing, the pool serves again.
        let again = delta(rt_pool::thread_stats().unwrap(), before).fallback_allocs;
        let b = Box::new([0u8; 1024]);
        assert_eq!(
            delta(rt_pool::thread_stats().unwrap(), before).fallback_allocs,
            again
        );
        drop(b);
        rt_pool::leave();
    })
    .join()
    .unwrap();
}

#[test]
fn realloc_between_sources_keeps_data() {
    thread::spawn(|| {
        // Allocated from System before entering, grown inside the pool.
        let mut v: Vec<u32> = (0..1000).collect();
        rt_pool::enter(1 << 20).expect("enter pool");
        let before = rt_pool::thread_stats().unwrap();
        let (_, calls) = system_calls_during(|| v.extend(1000..5000));
        assert!(
            calls >= 1,
            "moving the System block into the pool frees it there"
        );
        assert!(v.iter().copied().eq(0..5000));
        // Now in the pool: growing again needs no System call.
        let (_, calls) = system_calls_during(|| v.extend(5000..20000));
        assert_eq!(calls, 0);
        assert!(v.iter().copied().eq(0..20000));

        // A pool Vec grown on a thread without a pool moves to System.
        let (tx, rx) = mpsc::channel();
        let h = thread::spawn(move || {
            let mut v: Vec<u32> = rx.recv().unwrap();
            let (_, calls) = system_calls_during(|| v.extend(20000..40000));
            assert!(calls >= 1);
            assert!(v.iter().copied().eq(0..40000));
        });
        tx.send(v).unwrap();
        drop(tx); // the channel itself was allocated in the pool
        h.join().unwrap();
        rt_pool::drain_remote_frees();
        let end = rt_pool::thread_stats().unwrap();
        assert_eq!(end.bytes_in_use, before.bytes_in_use);
        assert!(end.remote_frees > before.remote_frees);
        rt_pool::leave();
    })
    .join()
    .unwrap();
}

#[test]
fn two_pools_exchange_blocks() {
    // Two RT threads send each other boxes: every free is a remote free
    // into the other pool while that pool keeps allocating.
    const N: usize = 20_000;
    let (to_b, from_a) = mpsc::sync_channel::<Box<[u64]>>(256);
    let (to_a, from_b) = mpsc::sync_channel::<Box<[u64]>>(256);
    let (ready_tx, ready_rx) = mpsc::channel::<()>();
    let ready_tx2 = ready_tx.clone();
    let a = thread::spawn(move || {
        rt_pool::enter(2 << 20).unwrap();
        ready_tx.send(()).unwrap();
        let before = rt_pool::thread_stats().unwrap();
        for i in 0..N {
            let b: Box<[u64]> = vec![i as u64; 1 + i % 40].into_boxed_slice();
            to_b.send(b).unwrap();
            let got = from_b.recv().unwrap();
            assert!(got.iter().all(|&x| x == got[0]));
        }
        drop(to_b);
        while from_b.recv().is_ok() {}
        (before, rt_pool::current_pool().unwrap())
    });
    let b = thread::spawn(move || {
        rt_pool::enter(2 << 20).unwrap();
        ready_tx2.send(()).unwrap();
        let before = rt_pool::thread_stats().unwrap();
        for i in 0..N {
            let got = from_a.recv().unwrap();
            assert!(got.iter().all(|&x| x == got[0]));
            let b: Box<[u64]> = vec![i as u64 * 3; 1 + i % 23].into_boxed_slice();
            to_a.send(b).unwrap();
        }
        drop(to_a);
        while from_a.recv().is_ok() {}
        (before, rt_pool::current_pool().unwrap())
    });
    ready_rx.recv().unwrap();
    ready_rx.recv().unwrap();
    let (before_a, slot_a) = a.join().unwrap();
    let (before_b, slot_b) = b.join().unwrap();
    assert_ne!(slot_a, slot_b);
    // Both threads exited (and so left); check the remote frees happened.
    let end_a = rt_pool::slot_stats(slot_a).unwrap();
    let end_b = rt_pool::slot_stats(slot_b).unwrap();
    assert!(end_a.remote_frees - before_a.remote_frees >= N as u64);
    assert!(end_b.remote_frees - before_b.remote_frees >= N as u64);
}

#[test]
fn orphaned_pool_is_adopted_and_drained() {
    let size = (1 << 20) + 4096 * 3;
    let (slot, blocks) = thread::spawn(move || {
        let info = rt_pool::enter(size).unwrap();
        let blocks: Vec<Box<[u8; 256]>> = (0..100).map(|i| Box::new([i as u8; 256])).collect();
        // Thread exits without leave(): the exit hook orphans the pool.
        (info.slot, blocks)
    })
    .join()
    .unwrap();
    let pending = rt_pool::slot_stats(slot).unwrap();
    drop(blocks); // remote frees into an orphaned pool: parked on its list
    let after_drop = rt_pool::slot_stats(slot).unwrap();
    assert!(after_drop.remote_frees >= pending.remote_frees + 101);
    assert_eq!(after_drop.bytes_in_use, pending.bytes_in_use);

    let adopted = thread::spawn(move || {
        let info = rt_pool::enter(size).unwrap();
        let s = rt_pool::thread_stats().unwrap();
        rt_pool::leave();
        (info, s)
    })
    .join()
    .unwrap();
    // Same size => the same pool comes back, its parked frees returned.
    assert!(adopted.0.adopted, "{:?}", adopted.0);
    assert_eq!(adopted.0.slot, slot);
    assert!(adopted.1.bytes_in_use < pending.bytes_in_use);
    assert!(adopted.1.pool_frees >= pending.pool_frees + 101);
    assert!(matches!(
        thread::spawn(|| {
            rt_pool::enter(512 << 10)?;
            let again = rt_pool::enter(512 << 10);
            rt_pool::leave();
            again
        })
        .join()
        .unwrap(),
        Err(PoolError::AlreadyEntered)
    ));
}

#[test]
fn timer_wait_and_clock_make_no_system_calls() {
    thread::spawn(|| {
        let mut timer = motion_rt::PeriodicTimer::new(200_000);
        let _ = timer.wait(); // first call outside the measurement
        let (_, calls) = system_calls_during(|| {
            for _ in 0..50 {
                black_box(timer.wait());
                black_box(motion_rt::now_ns());
            }
        });
        assert_eq!(calls, 0);
    })
    .join()
    .unwrap();
}
