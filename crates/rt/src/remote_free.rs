//! Lock-free list of blocks freed by threads that do not own their pool.
//!
//! A block allocated from an RT thread's pool may be dropped on another
//! thread (a sample handed over, an `Arc` whose last clone dies elsewhere).
//! That thread must not touch the pool's TLSF structure (only the owner
//! does, so the owner never takes a lock), and it must not take a lock the RT
//! thread could wait on either: a lock held by a SCHED_OTHER thread that gets
//! preempted would stall the RT cycle for as long as that thread is kept off
//! the CPU (priority inversion).
//!
//! So the foreign thread pushes the block onto this intrusive Treiber stack:
//! the freed block's own first two words hold the link and the block's
//! size/alignment, so pushing needs no memory. Pushes are lock-free (a CAS
//! loop); the owner takes the whole list with one `swap` (wait-free) and
//! returns the blocks to its pool at its next allocation. Taking the whole
//! list rather than popping one node avoids the ABA problem of Treiber-stack
//! pops.

use std::ptr;
use std::sync::atomic::{AtomicPtr, Ordering};

/// Smallest block the list can thread through: two words.
pub(crate) const MIN_NODE_SIZE: usize = std::mem::size_of::<FreeNode>();
/// Alignment a block needs to hold a node.
pub(crate) const MIN_NODE_ALIGN: usize = std::mem::align_of::<FreeNode>();

/// Header written into a freed block.
#[repr(C)]
pub(crate) struct FreeNode {
    pub(crate) next: *mut FreeNode,
    /// Opaque to the list; the pool stores the size and alignment here.
    pub(crate) meta: usize,
}

/// Multi-producer, single-consumer (take-all) intrusive stack.
pub(crate) struct RemoteFreeList {
    head: AtomicPtr<FreeNode>,
}

impl RemoteFreeList {
    pub(crate) const fn new() -> Self {
        Self {
            head: AtomicPtr::new(ptr::null_mut()),
        }
    }

    /// Pushes `block` (lock-free, allocation-free).
    ///
    /// # Safety
    ///
    /// `block` must be at least [`MIN_NODE_SIZE`] bytes, aligned to
    /// [`MIN_NODE_ALIGN`], no longer used by the caller, and not pushed twice.
    pub(crate) unsafe fn push(&self, block: *mut u8, meta: usize) {
        let node = block.cast::<FreeNode>();
        // SAFETY: the caller guarantees size/alignment and exclusive use.
        unsafe { ptr::addr_of_mut!((*node).meta).write(meta) };
        let mut head = self.head.load(Ordering::Relaxed);
        loop {
            // SAFETY: as above; the node is not yet visible to anyone.
            unsafe { ptr::addr_of_mut!((*node).next).write(head) };
            // Release: the owner that takes the list sees `next`, `meta` and
            // everything the freeing thread wrote before freeing.
            match self
                .head
                .compare_exchange_weak(head, node, Ordering::Release, Ordering::Relaxed)
            {
                Ok(_) => return,
                Err(current) => head = current,
            }
        }
    }

    /// Takes every pushed node (most recent first); null if empty.
    pub(crate) fn take_all(&self) -> *mut FreeNode {
        // Cheap check first: the common case on the RT thread is "empty", and
        // a plain load does not dirty the cache line.
        if self.head.load(Ordering::Relaxed).is_null() {
            return ptr::null_mut();
        }
        self.head.swap(ptr::null_mut(), Ordering::Acquire)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn push_take_concurrently() {
        #[repr(align(16))]
        #[allow(dead_code)] // only its size and alignment matter
        struct Block([usize; 2]);
        const PER_THREAD: usize = 10_000;
        let list = Arc::new(RemoteFreeList::new());
        let mut handles = Vec::new();
        for t in 0..4usize {
            let list = Arc::clone(&list);
            handles.push(std::thread::spawn(move || {
                for i in 0..PER_THREAD {
                    let b = Box::into_raw(Box::new(Block([0; 2])));
                    unsafe { list.push(b.cast(), t * PER_THREAD + i) };
                }
            }));
        }
        let mut seen = vec![false; 4 * PER_THREAD];
        let mut count = 0;
        let mut drain = |seen: &mut Vec<bool>| {
            let mut n = list.take_all();
            while !n.is_null() {
                unsafe {
                    let next = (*n).next;
                    let meta = (*n).meta;
                    assert!(!seen[meta]);
                    seen[meta] = true;
                    count += 1;
                    drop(Box::from_raw(n.cast::<Block>()));
                    n = next;
                }
            }
        };
        while handles.iter().any(|h| !h.is_finished()) {
            drain(&mut seen);
        }
        for h in handles {
            h.join().unwrap();
        }
        drain(&mut seen);
        assert_eq!(count, 4 * PER_THREAD);
        assert!(seen.iter().all(|&s| s));
    }
}
