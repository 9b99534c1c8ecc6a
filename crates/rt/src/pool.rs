//! Per-thread TLSF pools behind [`RtAllocator`](crate::RtAllocator).
//!
//! Exposed as [`crate::rt_pool`]. A thread calls [`enter`] once at start-up;
//! from then on its allocations are served in constant time from its own
//! TLSF pool (rlsf), which was mapped once, prefaulted and (best effort)
//! locked. Frees are routed by address: a block inside a pool goes back to
//! that pool — directly if the owner frees it, through the lock-free
//! [`RemoteFreeList`] if another thread does.
//!
//! # Registry
//!
//! Up to [`MAX_POOLS`] pools live in a static array of slots. A slot's
//! `base`/`len` are written once, before the slot is published, and never
//! change, so routing a free is a lock-free, allocation-free scan of at most
//! eight `(base, len)` pairs. Pool memory is never returned to the OS (blocks
//! may outlive the thread that allocated them); a thread that leaves (or
//! exits) orphans its pool. A later [`enter`] with the same `pool_bytes`
//! adopts it (a restarted RT thread gets its pool back); only when all slots
//! are taken does [`enter`] adopt the smallest larger orphan.
//!
//! # Ownership
//!
//! Only the thread whose thread-local `CURRENT` names a slot touches that
//! slot's TLSF structure and owner-only counters. Ownership moves only via
//! the slot `state` (`OWNED` → `ORPHANED` with Release in [`leave`],
//! `ORPHANED` → `OWNED` with Acquire on adoption).

use std::alloc::Layout;
use std::cell::Cell;
use std::fmt;
use std::mem::size_of;
use std::num::NonZeroUsize;
use std::ptr::{self, NonNull};
use std::sync::atomic::{AtomicPtr, AtomicU64, AtomicU8, AtomicUsize, Ordering};

use nix::errno::Errno;
use nix::sys::mman::{mlock, mmap_anonymous, MapFlags, ProtFlags};
use rlsf::Tlsf;

use crate::counting;
use crate::procfs::page_size;
use crate::remote_free::{FreeNode, RemoteFreeList, MIN_NODE_ALIGN, MIN_NODE_SIZE};

/// How many threads can own a pool at once (and how many pools can exist).
pub const MAX_POOLS: usize = 8;

/// Smallest pool [`enter`] accepts.
pub const MIN_POOL_BYTES: usize = 16 * 1024;

/// TLSF with 32-byte granularity, blocks up to 2 GiB (larger pools are
/// split), 16 second-level classes per power of two (≤ 6.25 % waste).
type PoolTlsf = Tlsf<'static, u32, u16, 26, 16>;

/// Remote frees returned to the pool per allocation, so an allocation stays
/// bounded even after a burst of foreign frees.
const DRAIN_BATCH: usize = 8;

const FREE: u8 = 0;
const OWNED: u8 = 1;
const ORPHANED: u8 = 2;

/// Bits of [`FreeNode::meta`] holding the allocation size; the top bits
/// hold log2 of the alignment.
const META_SHIFT: u32 = 58;
const META_SIZE_MASK: usize = (1 << META_SHIFT) - 1;

/// Allocation counters, global ([`stats`]) or of one pool ([`thread_stats`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PoolStats {
    /// Allocations served from a pool (a pool-to-pool realloc counts one).
    pub pool_allocs: u64,
    /// Blocks returned to a pool, by the owner or drained from remote frees.
    pub pool_frees: u64,
    /// Frees by a thread other than the owner (pushed on the lock-free list).
    pub remote_frees: u64,
    /// Calls into the system allocator made by a thread while it owned a
    /// pool (fallbacks, frees of pre-pool memory, ...). 0 in a clean cycle.
    pub system_allocs_on_rt_thread: u64,
    /// Allocations a pool could not serve (exhausted or too large) that fell
    /// back to the system allocator.
    pub fallback_allocs: u64,
    /// Requested bytes currently allocated from pools. Remote frees count as
    /// in use until the owner has returned them to its pool.
    pub bytes_in_use: u64,
    /// Maximum of `bytes_in_use`.
    pub high_water: u64,
}

/// What [`enter`] set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PoolInfo {
    /// Registry slot (0..[`MAX_POOLS`]).
    pub slot: usize,
    /// Start address of the pool mapping.
    pub base: usize,
    /// Length of the pool mapping in bytes (header included).
    pub len: usize,
    /// The pool was left by an earlier thread and adopted.
    pub adopted: bool,
    /// `mlock` of the pool succeeded (it is also locked by an earlier or
    /// later `mlockall(MCL_FUTURE)` / `MCL_CURRENT`).
    pub locked: bool,
}

/// Why [`enter`] failed. The thread keeps using the system allocator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoolError {
    /// The thread already owns a pool.
    AlreadyEntered,
    /// [`RtAllocator`](crate::RtAllocator) is not the `#[global_allocator]`,
    /// so a pool would never be used.
    AllocatorNotInstalled,
    /// `pool_bytes` below [`MIN_POOL_BYTES`].
    TooSmall {
        /// Bytes requested.
        requested: usize,
    },
    /// All [`MAX_POOLS`] slots are owned (or orphaned and too small).
    NoFreeSlot,
    /// `mmap` of the pool failed.
    Map(Errno),
}

impl fmt::Display for PoolError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::AlreadyEntered => f.write_str("this thread already owns an RT pool"),
            Self::AllocatorNotInstalled => f.write_str(
                "RtAllocator is not the #[global_allocator]; add \
                 `#[global_allocator] static A: motion_rt::RtAllocator = motion_rt::RtAllocator;`",
            ),
            Self::TooSmall { requested } => write!(
                f,
                "RT pool of {requested} bytes is too small (minimum {MIN_POOL_BYTES})"
            ),
            Self::NoFreeSlot => write!(
                f,
                "all {MAX_POOLS} RT pool slots are in use (or orphaned and smaller than requested)"
            ),
            Self::Map(e) => write!(f, "mmap of the RT pool failed: {e}"),
        }
    }
}

impl std::error::Error for PoolError {}

struct Counters {
    pool_allocs: AtomicU64,
    pool_frees: AtomicU64,
    remote_frees: AtomicU64,
    system_allocs_on_rt_thread: AtomicU64,
    fallback_allocs: AtomicU64,
    bytes_in_use: AtomicU64,
    high_water: AtomicU64,
}

impl Counters {
    const fn new() -> Self {
        Self {
            pool_allocs: AtomicU64::new(0),
            pool_frees: AtomicU64::new(0),
            remote_frees: AtomicU64::new(0),
            system_allocs_on_rt_thread: AtomicU64::new(0),
            fallback_allocs: AtomicU64::new(0),
            bytes_in_use: AtomicU64::new(0),
            high_water: AtomicU64::new(0),
        }
    }

    fn snapshot(&self) -> PoolStats {
        PoolStats {
            pool_allocs: self.pool_allocs.load(Ordering::Relaxed),
            pool_frees: self.pool_frees.load(Ordering::Relaxed),
            remote_frees: self.remote_frees.load(Ordering::Relaxed),
            system_allocs_on_rt_thread: self.system_allocs_on_rt_thread.load(Ordering::Relaxed),
            fallback_allocs: self.fallback_allocs.load(Ordering::Relaxed),
            bytes_in_use: self.bytes_in_use.load(Ordering::Relaxed),
            high_water: self.high_water.load(Ordering::Relaxed),
        }
    }
}

/// Owner-only counter bump: a plain load + store, no locked instruction.
#[inline]
fn bump_owned(c: &AtomicU64, by: u64) -> u64 {
    let v = c.load(Ordering::Relaxed).wrapping_add(by);
    c.store(v, Ordering::Relaxed);
    v
}

struct Slot {
    state: AtomicU8,
    /// Start of the mapping; 0 until published, then never changes.
    base: AtomicUsize,
    /// Length of the mapping; written before `base`, never changes.
    len: AtomicUsize,
    /// Frees by foreign threads.
    remote: RemoteFreeList,
    /// Owner-only: remote frees taken from `remote`, not yet returned.
    pending: AtomicPtr<FreeNode>,
    /// Only `remote_frees` is written by non-owners (atomic RMW); the rest
    /// are owner-only.
    counters: Counters,
}

impl Slot {
    const fn new() -> Self {
        Self {
            state: AtomicU8::new(FREE),
            base: AtomicUsize::new(0),
            len: AtomicUsize::new(0),
            remote: RemoteFreeList::new(),
            pending: AtomicPtr::new(ptr::null_mut()),
            counters: Counters::new(),
        }
    }
}

static SLOTS: [Slot; MAX_POOLS] = [const { Slot::new() }; MAX_POOLS];
/// One past the highest slot index ever published.
static PUBLISHED: AtomicUsize = AtomicUsize::new(0);

/// Global counters that cannot be summed from slots.
static GLOBAL_BYTES_IN_USE: AtomicU64 = AtomicU64::new(0);
static GLOBAL_HIGH_WATER: AtomicU64 = AtomicU64::new(0);

thread_local! {
    /// Slot index + 1 of the pool this thread owns; 0 = none.
    /// const-initialised, no destructor: safe to read inside the allocator.
    static CURRENT: Cell<usize> = const { Cell::new(0) };
    /// Leaves the pool when the thread exits. Has a destructor, so it is
    /// touched only in `enter` (outside the allocator), never in it.
    static EXIT_GUARD: ExitGuard = const { ExitGuard };
}

struct ExitGuard;

impl Drop for ExitGuard {
    fn drop(&mut self) {
        leave();
    }
}

/// The slot the current thread owns.
#[inline]
pub(crate) fn current_slot() -> Option<usize> {
    match CURRENT.try_with(Cell::get).unwrap_or(0) {
        0 => None,
        n => Some(n - 1),
    }
}

fn set_current(slot: Option<usize>) {
    let _ = CURRENT.try_with(|c| c.set(slot.map_or(0, |s| s + 1)));
}

/// The pool `addr` lies in, if any. Lock-free and allocation-free.
#[inline]
pub(crate) fn find_slot(addr: usize) -> Option<usize> {
    let n = PUBLISHED.load(Ordering::Acquire).min(MAX_POOLS);
    for (i, slot) in SLOTS.iter().enumerate().take(n) {
        let base = slot.base.load(Ordering::Acquire);
        if base != 0 && addr.wrapping_sub(base) < slot.len.load(Ordering::Relaxed) {
            return Some(i);
        }
    }
    None
}

/// The layout actually requested from TLSF: at least two words, 16-byte
/// aligned, so a freed block can carry a [`FreeNode`].
#[inline]
fn canonical(layout: Layout) -> Option<Layout> {
    Layout::from_size_align(
        layout.size().max(MIN_NODE_SIZE),
        layout.align().max(MIN_NODE_ALIGN).max(16),
    )
    .ok()
}

#[inline]
fn encode_meta(size: usize, align: usize) -> usize {
    (size & META_SIZE_MASK) | ((align.trailing_zeros() as usize) << META_SHIFT)
}

#[inline]
fn decode_meta(meta: usize) -> (usize, usize) {
    (meta & META_SIZE_MASK, 1usize << (meta >> META_SHIFT))
}

/// The pool's TLSF header (at `base`, initialised before publication).
/// Only the owner of the slot may dereference it, and only briefly.
#[inline]
fn tlsf_ptr(slot: &Slot) -> *mut PoolTlsf {
    slot.base.load(Ordering::Relaxed) as *mut PoolTlsf
}

fn note_pool_alloc(slot: &Slot, size: usize) {
    bump_owned(&slot.counters.pool_allocs, 1);
    let now = bump_owned(&slot.counters.bytes_in_use, size as u64);
    if now > slot.counters.high_water.load(Ordering::Relaxed) {
        slot.counters.high_water.store(now, Ordering::Relaxed);
    }
    let global = GLOBAL_BYTES_IN_USE.fetch_add(size as u64, Ordering::Relaxed) + size as u64;
    if global > GLOBAL_HIGH_WATER.load(Ordering::Relaxed) {
        GLOBAL_HIGH_WATER.fetch_max(global, Ordering::Relaxed);
    }
}

fn note_pool_free(slot: &Slot, size: usize) {
    bump_owned(&slot.counters.pool_frees, 1);
    let c = &slot.counters.bytes_in_use;
    c.store(
        c.load(Ordering::Relaxed).wrapping_sub(size as u64),
        Ordering::Relaxed,
    );
    GLOBAL_BYTES_IN_USE.fetch_sub(size as u64, Ordering::Relaxed);
}

/// Returns up to `max` remote frees to the pool; the number returned.
///
/// # Safety
///
/// The caller owns slot `idx`.
unsafe fn drain(idx: usize, max: usize) -> usize {
    let slot = &SLOTS[idx];
    let mut node = slot.pending.load(Ordering::Relaxed);
    if node.is_null() {
        node = slot.remote.take_all();
    }
    let mut n = 0;
    while !node.is_null() && n < max {
        // SAFETY: nodes on the list are freed pool blocks written by `push`;
        // read them before the block goes back to TLSF.
        let (next, meta) = unsafe { ((*node).next, (*node).meta) };
        let (size, align) = decode_meta(meta);
        // SAFETY: the block came from this pool with this (canonical) align.
        unsafe {
            (*tlsf_ptr(slot)).deallocate(NonNull::new_unchecked(node.cast::<u8>()), align);
        }
        note_pool_free(slot, size);
        node = next;
        n += 1;
    }
    slot.pending.store(node, Ordering::Relaxed);
    n
}

/// # Safety
///
/// The caller owns slot `idx`.
unsafe fn drain_all(idx: usize) -> usize {
    let mut total = 0;
    loop {
        // SAFETY: forwarded.
        let n = unsafe { drain(idx, usize::MAX) };
        if n == 0 {
            return total;
        }
        total += n;
    }
}

/// Allocates from the current thread's pool (`idx` = [`current_slot`]).
/// `None` when the pool cannot serve the request.
///
/// # Safety
///
/// `idx` is the current thread's slot.
#[inline]
pub(crate) unsafe fn alloc_owned(idx: usize, layout: Layout) -> Option<NonNull<u8>> {
    let slot = &SLOTS[idx];
    // SAFETY (all blocks): we own the slot.
    unsafe { drain(idx, DRAIN_BATCH) };
    let cl = canonical(layout)?;
    let p = match unsafe { (*tlsf_ptr(slot)).allocate(cl) } {
        Some(p) => p,
        None => {
            // Exhausted: return every pending remote free, then retry once.
            if unsafe { drain_all(idx) } == 0 {
                return None;
            }
            unsafe { (*tlsf_ptr(slot)).allocate(cl)? }
        }
    };
    note_pool_alloc(slot, layout.size());
    Some(p)
}

/// Grows/shrinks a block of the current thread's own pool, in place when
/// TLSF can. `None` leaves the block untouched.
///
/// # Safety
///
/// `idx` is the current thread's slot and `ptr`/`layout` an allocation of
/// that pool.
pub(crate) unsafe fn realloc_owned(
    idx: usize,
    ptr: NonNull<u8>,
    layout: Layout,
    new_size: usize,
) -> Option<NonNull<u8>> {
    let slot = &SLOTS[idx];
    let new_layout = canonical(Layout::from_size_align(new_size, layout.align()).ok()?)?;
    // SAFETY: own slot; same canonical alignment as at allocation.
    let p = unsafe { (*tlsf_ptr(slot)).reallocate(ptr, new_layout)? };
    note_pool_free(slot, layout.size());
    note_pool_alloc(slot, new_size);
    Some(p)
}

/// Frees a block of pool `idx` from any thread.
///
/// # Safety
///
/// `ptr`/`layout` is a live allocation of pool `idx`.
#[inline]
pub(crate) unsafe fn free_in(idx: usize, ptr: NonNull<u8>, layout: Layout) {
    let slot = &SLOTS[idx];
    let Some(cl) = canonical(layout) else {
        // Cannot happen: the block was allocated with this canonical layout.
        return;
    };
    if current_slot() == Some(idx) {
        // SAFETY: we own the slot; block allocated with this align.
        unsafe { (*tlsf_ptr(slot)).deallocate(ptr, cl.align()) };
        note_pool_free(slot, layout.size());
    } else {
        slot.counters.remote_frees.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the block is ≥ 16 bytes, 16-aligned (canonical layout) and
        // the caller gives it up.
        unsafe {
            slot.remote
                .push(ptr.as_ptr(), encode_meta(layout.size(), cl.align()))
        };
    }
}

/// Counts a system-allocator call made while owning pool `idx`.
#[inline]
pub(crate) fn note_rt_system_call(idx: usize) {
    bump_owned(&SLOTS[idx].counters.system_allocs_on_rt_thread, 1);
}

/// Counts a fallback of pool `idx` to the system allocator.
#[inline]
pub(crate) fn note_fallback(idx: usize) {
    bump_owned(&SLOTS[idx].counters.fallback_allocs, 1);
}

fn round_up(v: usize, to: usize) -> Option<usize> {
    Some(v.checked_add(to - 1)? / to * to)
}

/// True if allocations of this thread reach [`RtAllocator`](crate::RtAllocator).
fn allocator_installed() -> bool {
    let (_, calls) = counting::system_calls_during(|| {
        drop(std::hint::black_box(Box::new(0u64)));
    });
    calls > 0
}

/// Creates (or adopts) a TLSF pool of at least `pool_bytes` for the calling
/// thread; its allocations are then served from the pool.
///
/// Call at start-up, outside the cycle: it maps and prefaults the whole pool
/// (one page fault per page, now rather than in the cycle), `mlock`s it
/// (best effort; `mlockall(MCL_FUTURE)` locks it too) and registers an exit
/// hook that [`leave`]s when the thread ends.
pub fn enter(pool_bytes: usize) -> Result<PoolInfo, PoolError> {
    if current_slot().is_some() {
        return Err(PoolError::AlreadyEntered);
    }
    if pool_bytes < MIN_POOL_BYTES {
        return Err(PoolError::TooSmall {
            requested: pool_bytes,
        });
    }
    if !allocator_installed() {
        return Err(PoolError::AllocatorNotInstalled);
    }
    // Register the exit hook now (registration may allocate: from System,
    // since the thread has no pool yet).
    EXIT_GUARD.with(|_| {});

    let page = page_size();
    let header = round_up(size_of::<PoolTlsf>(), 64).ok_or(PoolError::Map(Errno::ENOMEM))?;
    let total = pool_bytes
        .checked_add(header)
        .and_then(|t| round_up(t, page))
        .ok_or(PoolError::Map(Errno::ENOMEM))?;

    // A thread restarted with the same size gets its old pool back.
    if let Some(info) = adopt(|len| len == total) {
        return Ok(info);
    }

    // Claim a never-used slot.
    for (i, slot) in SLOTS.iter().enumerate() {
        if slot
            .state
            .compare_exchange(FREE, OWNED, Ordering::Acquire, Ordering::Relaxed)
            .is_err()
        {
            continue;
        }
        let base = match map_pool(total, page) {
            Ok(b) => b,
            Err(e) => {
                slot.state.store(FREE, Ordering::Release);
                return Err(PoolError::Map(e));
            }
        };
        // SAFETY: `base` is a fresh, writable, page-aligned mapping of
        // `total` bytes; the header fits in the first `header` bytes.
        let locked = unsafe {
            let tlsf = base.as_ptr().cast::<PoolTlsf>();
            tlsf.write(PoolTlsf::new());
            let arena = NonNull::slice_from_raw_parts(base.add(header), total - header);
            (*tlsf).insert_free_block_ptr(arena);
            mlock(base.cast(), total).is_ok()
        };
        slot.len.store(total, Ordering::Relaxed);
        slot.base.store(base.as_ptr() as usize, Ordering::Release);
        PUBLISHED.fetch_max(i + 1, Ordering::Release);
        set_current(Some(i));
        return Ok(PoolInfo {
            slot: i,
            base: base.as_ptr() as usize,
            len: total,
            adopted: false,
            locked,
        });
    }
    // Registry full: take the smallest orphaned pool that is big enough.
    adopt(|len| len >= total).ok_or(PoolError::NoFreeSlot)
}

/// Adopts the smallest orphaned pool whose length satisfies `fits`.
fn adopt(fits: impl Fn(usize) -> bool) -> Option<PoolInfo> {
    loop {
        let (i, len) = SLOTS
            .iter()
            .enumerate()
            .filter(|(_, s)| s.state.load(Ordering::Acquire) == ORPHANED)
            .map(|(i, s)| (i, s.len.load(Ordering::Relaxed)))
            .filter(|&(_, len)| fits(len))
            .min_by_key(|&(_, len)| len)?;
        let slot = &SLOTS[i];
        if slot
            .state
            .compare_exchange(ORPHANED, OWNED, Ordering::Acquire, Ordering::Relaxed)
            .is_err()
        {
            continue; // another thread adopted it first; look again
        }
        set_current(Some(i));
        // SAFETY: we own the slot now.
        unsafe { drain_all(i) };
        let base = slot.base.load(Ordering::Relaxed);
        // SAFETY: the published mapping of `len` bytes at `base`.
        let locked =
            unsafe { mlock(NonNull::new_unchecked(base as *mut libc::c_void), len) }.is_ok();
        return Some(PoolInfo {
            slot: i,
            base,
            len,
            adopted: true,
            locked,
        });
    }
}

/// Maps `len` bytes and touches every page.
fn map_pool(len: usize, page: usize) -> Result<NonNull<u8>, Errno> {
    let nz = NonZeroUsize::new(len).ok_or(Errno::EINVAL)?;
    // SAFETY: a fresh anonymous private mapping aliases nothing.
    let p = unsafe {
        mmap_anonymous(
            None,
            nz,
            ProtFlags::PROT_READ | ProtFlags::PROT_WRITE,
            MapFlags::MAP_PRIVATE,
        )?
    }
    .cast::<u8>();
    let mut off = 0;
    while off < len {
        // SAFETY: inside the mapping. A write (not a read) so a private page
        // is really allocated, not mapped to the shared zero page.
        unsafe { ptr::write_volatile(p.as_ptr().add(off), 0) };
        off += page;
    }
    Ok(p)
}

/// Stops serving this thread from its pool. Pending remote frees are
/// returned first; the pool is orphaned (blocks still allocated from it stay
/// valid and can be freed from any thread) and can be adopted by a later
/// [`enter`]. Returns false if the thread owned no pool. Called
/// automatically when a thread that entered exits.
pub fn leave() -> bool {
    let Some(idx) = current_slot() else {
        return false;
    };
    // SAFETY: we own the slot until the state store below.
    unsafe { drain_all(idx) };
    set_current(None);
    SLOTS[idx].state.store(ORPHANED, Ordering::Release);
    true
}

/// Returns every pending remote free to the current thread's pool (normally
/// done a few at a time by each allocation). Returns how many; 0 if the
/// thread owns no pool.
pub fn drain_remote_frees() -> usize {
    match current_slot() {
        // SAFETY: we own the slot.
        Some(idx) => unsafe { drain_all(idx) },
        None => 0,
    }
}

/// The registry slot of the current thread's pool.
pub fn current_pool() -> Option<usize> {
    current_slot()
}

/// Counters of the current thread's pool (they accumulate over the pool's
/// life, also across adoption: compare before/after).
pub fn thread_stats() -> Option<PoolStats> {
    current_slot().and_then(slot_stats)
}

/// Counters of pool `slot`, if it exists.
pub fn slot_stats(slot: usize) -> Option<PoolStats> {
    let s = SLOTS.get(slot)?;
    if s.base.load(Ordering::Acquire) == 0 {
        return None;
    }
    Some(s.counters.snapshot())
}

/// Counters summed over all pools.
pub fn stats() -> PoolStats {
    let mut total = PoolStats::default();
    for s in &SLOTS {
        let c = s.counters.snapshot();
        total.pool_allocs += c.pool_allocs;
        total.pool_frees += c.pool_frees;
        total.remote_frees += c.remote_frees;
        total.system_allocs_on_rt_thread += c.system_allocs_on_rt_thread;
        total.fallback_allocs += c.fallback_allocs;
    }
    total.bytes_in_use = GLOBAL_BYTES_IN_USE.load(Ordering::Relaxed);
    total.high_water = GLOBAL_HIGH_WATER.load(Ordering::Relaxed);
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meta_round_trip() {
        for (size, align) in [(1, 16), (24, 16), (4096, 4096), (META_SIZE_MASK, 1 << 40)] {
            assert_eq!(decode_meta(encode_meta(size, align)), (size, align));
        }
    }

    #[test]
    fn canonical_layout_fits_a_node() {
        let l = canonical(Layout::new::<u8>()).unwrap();
        assert!(l.size() >= MIN_NODE_SIZE && l.align() >= MIN_NODE_ALIGN);
        let l = canonical(Layout::from_size_align(100, 64).unwrap()).unwrap();
        assert_eq!((l.size(), l.align()), (100, 64));
    }

    #[test]
    fn enter_refuses_without_the_global_allocator() {
        // Unit tests run with the default allocator.
        let r = std::thread::spawn(|| enter(1 << 20)).join().unwrap();
        assert_eq!(r, Err(PoolError::AllocatorNotInstalled));
        assert_eq!(
            std::thread::spawn(|| enter(1)).join().unwrap(),
            Err(PoolError::TooSmall { requested: 1 })
        );
        assert!(!leave());
    }
}
