//! Filling an entry from the table allocates nothing: the status service
//! fills a frame of up to 64 axes every 10 ms, and nothing in it may wait
//! on the allocator.

use motion_homing::AxisConfig;
use motion_status::{axis, AxisNote, AxisSnap, AxisStatusEntry, Source};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(l) }
    }

    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static A: Counting = Counting;

#[test]
fn a_fill_allocates_nothing() {
    let mut a = AxisSnap {
        raw: Some(1.0),
        axis: Some(2.0),
        skew: Some(0.1),
        homes_started: 1,
        ..Default::default()
    };
    a.status.homed = true;
    a.status.event_raw = Some(0.5);
    a.status.switch_edge_raw = Some(0.25);
    let (cfg, note) = (AxisConfig::default(), AxisNote::default());
    let mut e = AxisStatusEntry::default();
    let before = ALLOCS.load(Ordering::Relaxed);
    for now in 0..1000 {
        e.set_identity("X", a.status.phase.name(), 0);
        axis::fill(&mut e, &Source::new(&a, &cfg, &note, now));
    }
    assert_eq!(ALLOCS.load(Ordering::Relaxed) - before, 0);
    assert!(e.homed() && e.switch_to_marker() == Some(0.25));
}
