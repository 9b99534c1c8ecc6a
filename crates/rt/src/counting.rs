//! Per-thread count of calls that reach the system allocator.
//!
//! The product rule is "the RT cycle makes no call into the system
//! allocator". This counter is what proves it: [`RtAllocator`] bumps a
//! thread-local `u64` on every `alloc`, `alloc_zeroed`, `realloc` and
//! `dealloc` it forwards to [`std::alloc::System`] (a plain thread-local add,
//! no atomic, no lock). Read it before and after the cycle; the difference
//! must be 0.
//!
//! The counter only moves when [`RtAllocator`] is the binary's
//! `#[global_allocator]`; in any other binary it stays 0 (see
//! [`rt_pool::enter`](crate::rt_pool::enter), which refuses to start then).
//!
//! [`RtAllocator`]: crate::RtAllocator

use std::cell::Cell;

thread_local! {
    // const-initialised, no destructor: reading or bumping it inside the
    // allocator can never allocate, recurse or fail during thread teardown.
    static SYSTEM_CALLS: Cell<u64> = const { Cell::new(0) };
}

/// Calls the current thread has made into the system allocator through
/// [`RtAllocator`](crate::RtAllocator) since it started (alloc, alloc_zeroed,
/// realloc and dealloc each count one).
#[inline]
pub fn system_calls_on_this_thread() -> u64 {
    SYSTEM_CALLS.try_with(Cell::get).unwrap_or(0)
}

/// Runs `f` and returns its result with the number of system-allocator calls
/// the current thread made during it.
pub fn system_calls_during<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let before = system_calls_on_this_thread();
    let r = f();
    let after = system_calls_on_this_thread();
    (r, after.wrapping_sub(before))
}

#[inline]
pub(crate) fn note_system_call() {
    let _ = SYSTEM_CALLS.try_with(|c| c.set(c.get().wrapping_add(1)));
}
