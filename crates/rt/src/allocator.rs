//! [`RtAllocator`]: the `GlobalAlloc` that routes between the system
//! allocator and per-thread RT pools.

use std::alloc::{GlobalAlloc, Layout, System};
use std::ptr::{self, NonNull};

use crate::{counting, pool};

/// Global allocator for binaries with real-time threads.
///
/// ```no_run
/// #[global_allocator]
/// static ALLOC: motion_rt::RtAllocator = motion_rt::RtAllocator;
///
/// fn main() {
///     // Start-up of the RT thread, outside its cycle:
///     motion_rt::rt_pool::enter(4 << 20).expect("RT pool");
/// }
/// ```
///
/// - A thread that has not called [`rt_pool::enter`](crate::rt_pool::enter)
///   uses [`System`] (glibc malloc), counted per thread in
///   [`counting`](crate::counting).
/// - A thread that has entered allocates from its own TLSF pool in constant
///   time; if the pool cannot serve a request it falls back to [`System`]
///   and counts it (never returns null while the system has memory).
/// - Frees are routed by address, from any thread: pool blocks go back to
///   their pool (lock-free remote free if the freeing thread is not the
///   owner), everything else to [`System`].
///
/// Nothing on these paths allocates, locks or panics; the thread-local
/// state it touches is `const`-initialised and has no destructor.
#[derive(Debug, Default, Clone, Copy)]
pub struct RtAllocator;

#[inline]
fn note_system_call() {
    counting::note_system_call();
    if let Some(idx) = pool::current_slot() {
        pool::note_rt_system_call(idx);
    }
}

#[inline]
unsafe fn fallback(idx: usize, layout: Layout, zeroed: bool) -> *mut u8 {
    pool::note_fallback(idx);
    note_system_call();
    // SAFETY: forwarded GlobalAlloc contract.
    unsafe {
        if zeroed {
            System.alloc_zeroed(layout)
        } else {
            System.alloc(layout)
        }
    }
}

unsafe impl GlobalAlloc for RtAllocator {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if let Some(idx) = pool::current_slot() {
            // SAFETY: `idx` is this thread's slot.
            if let Some(p) = unsafe { pool::alloc_owned(idx, layout) } {
                return p.as_ptr();
            }
            // SAFETY: forwarded contract.
            return unsafe { fallback(idx, layout, false) };
        }
        note_system_call();
        // SAFETY: forwarded contract.
        unsafe { System.alloc(layout) }
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if let Some(idx) = pool::current_slot() {
            // SAFETY: `idx` is this thread's slot.
            if let Some(p) = unsafe { pool::alloc_owned(idx, layout) } {
                // SAFETY: fresh block of at least `layout.size()` bytes.
                unsafe { ptr::write_bytes(p.as_ptr(), 0, layout.size()) };
                return p.as_ptr();
            }
            // SAFETY: forwarded contract.
            return unsafe { fallback(idx, layout, true) };
        }
        note_system_call();
        // SAFETY: forwarded contract.
        unsafe { System.alloc_zeroed(layout) }
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if let Some(idx) = pool::find_slot(ptr as usize) {
            // SAFETY: `ptr` lies in pool `idx`, so it was allocated there
            // (system blocks never overlap a live mapping); non-null.
            unsafe { pool::free_in(idx, NonNull::new_unchecked(ptr), layout) };
            return;
        }
        note_system_call();
        // SAFETY: not a pool block, so it came from System.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let from_pool = pool::find_slot(ptr as usize);
        let current = pool::current_slot();
        if from_pool.is_none() && current.is_none() {
            note_system_call();
            // SAFETY: a System block on a thread without pool.
            return unsafe { System.realloc(ptr, layout, new_size) };
        }
        if let (Some(from), Some(cur)) = (from_pool, current) {
            if from == cur {
                // Own pool: TLSF grows/shrinks in place when it can.
                // SAFETY: own slot; `ptr`/`layout` is an allocation of it.
                let p = unsafe {
                    pool::realloc_owned(cur, NonNull::new_unchecked(ptr), layout, new_size)
                };
                if let Some(p) = p {
                    return p.as_ptr();
                }
            }
        }
        // Different sources: alloc (pool or System, by the current
        // thread's state) + copy + free (routed by address). A
        // pre-pool System block reallocated on an RT thread moves
        // into the pool (the System free is counted).
        // SAFETY: the caller guarantees `new_size` with `align` is a
        // valid layout (GlobalAlloc::realloc contract).
        let new_layout = unsafe { Layout::from_size_align_unchecked(new_size, layout.align()) };
        // SAFETY: forwarded contract.
        let new = unsafe { self.alloc(new_layout) };
        if !new.is_null() {
            // SAFETY: both blocks are valid for the smaller size and
            // distinct.
            unsafe {
                ptr::copy_nonoverlapping(ptr, new, layout.size().min(new_size));
                self.dealloc(ptr, layout);
            }
        }
        new
    }
}
