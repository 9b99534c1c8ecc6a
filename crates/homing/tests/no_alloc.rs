//! The engine step never touches the heap: counted with a wrapping global
//! allocator over complete homing runs of every sequence.

use motion_homing::*;
use motion_plant::{Plant, PlantConfig};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static CALLS: Cell<u64> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        CALLS.with(|c| c.set(c.get() + 1));
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        CALLS.with(|c| c.set(c.get() + 1));
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        CALLS.with(|c| c.set(c.get() + 1));
        System.realloc(p, l, n)
    }
}

#[global_allocator]
static A: Counting = Counting;

fn calls() -> u64 {
    CALLS.with(|c| c.get())
}

#[test]
fn engine_step_makes_no_allocation() {
    let mut steps = 0u64;
    let mut during = 0u64;
    for seq in [
        HomeSequence::Switch,
        HomeSequence::Marker,
        HomeSequence::SwitchThenMarker,
        HomeSequence::Torque,
        HomeSequence::TorqueThenMarker,
    ] {
        let cfg = AxisConfig {
            marker: true,
            home_sequence: seq,
            home_speed: 20.0,
            home_return_speed: 5.0,
            home_acceleration: 500.0,
            home_deceleration: 500.0,
            home_torque_level: 30.0,
            home_torque_threshold: 20.0,
            home_torque_time: 0.005,
            ..AxisConfig::default()
        };
        let mut axis = Axis::new(cfg);
        let mut plant = Plant::new(PlantConfig {
            start: -20.0,
            switch: Some((0.0, 5.0)),
            marker_every: 10.0,
            marker_at: 2.5,
            hard_stop: Some((-30.0, 30.0)),
            ..PlantConfig::default()
        });
        let mut fb = plant.feedback();
        let req = Request {
            home: true,
            ..Request::default()
        };
        for k in 0..20_000u64 {
            let before = calls();
            let cmd = axis.step(k * 1_000_000, Some(&fb), &req);
            during += calls() - before;
            steps += 1;
            fb = plant.step(&cmd, 0.001);
        }
        assert!(axis.status().pc, "{seq:?}: {:?}", axis.status());
    }
    assert!(steps == 100_000);
    assert_eq!(during, 0, "allocator calls inside Axis::step");
}

#[test]
fn the_counter_counts() {
    let before = calls();
    let v = std::hint::black_box(vec![1u8; 64]);
    drop(v);
    assert_eq!(calls() - before, 2);
}
