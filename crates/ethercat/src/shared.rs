//! Lock-free hand-over of "the newest value" between exactly one writer
//! thread and one reader thread: the process image between `motion-io`'s
//! thread (commands in, feedback out) and the bus thread.
//!
//! Two slots, each guarded by its own sequence counter (a seqlock), and an
//! index of the newest complete slot. The writer always fills the slot that
//! is *not* the newest, so a reader copying the newest slot collides with
//! the writer only if the writer completes one whole publication and starts
//! the next during that copy; the reader then retries a bounded number of
//! times and otherwise reports "no fresh value" — it never waits, never
//! takes a lock, never allocates (the slots are allocated once, up front).
//! The data words are atomics (relaxed loads/stores bracketed by the
//! sequence counter's acquire/release and fences), so no torn value is ever
//! *used*, and there is no data race in the Rust sense.

use std::sync::atomic::{fence, AtomicU64, AtomicUsize, Ordering};

/// Reader attempts before giving up for this call.
pub const READ_ATTEMPTS: usize = 8;

struct Slot {
    seq: AtomicU64,
    data: Box<[AtomicU64]>,
}

/// Single-writer, single-reader seqlock double buffer of `words` u64 words.
pub struct SeqBuffer {
    slots: [Slot; 2],
    latest: AtomicUsize,
    /// Completed publications (the writer's counter, readable by anyone).
    published: AtomicU64,
    /// Reads that gave up (counted for the status).
    read_failures: AtomicU64,
}

impl SeqBuffer {
    /// A buffer of `words` words, all 0, counting as never published.
    pub fn new(words: usize) -> SeqBuffer {
        let slot = || Slot {
            seq: AtomicU64::new(0),
            data: (0..words).map(|_| AtomicU64::new(0)).collect(),
        };
        SeqBuffer {
            slots: [slot(), slot()],
            latest: AtomicUsize::new(0),
            published: AtomicU64::new(0),
            read_failures: AtomicU64::new(0),
        }
    }

    /// Number of words.
    pub fn words(&self) -> usize {
        self.slots[0].data.len()
    }

    /// Publishes `src` (must be [`words`](Self::words) long; extra words are
    /// ignored, missing ones keep their old values). Only one thread may
    /// call this.
    pub fn write(&self, src: &[u64]) {
        let i = 1 - self.latest.load(Ordering::Relaxed);
        let slot = &self.slots[i];
        let s = slot.seq.load(Ordering::Relaxed);
        slot.seq.store(s.wrapping_add(1), Ordering::Relaxed);
        fence(Ordering::Release);
        for (d, v) in slot.data.iter().zip(src) {
            d.store(*v, Ordering::Relaxed);
        }
        slot.seq.store(s.wrapping_add(2), Ordering::Release);
        self.latest.store(i, Ordering::Release);
        self.published.fetch_add(1, Ordering::Release);
    }

    /// Copies the newest publication into `dst`; `false` (and `dst`
    /// partially overwritten) if no consistent copy was obtained within
    /// [`READ_ATTEMPTS`]. Only one thread may call this.
    pub fn read(&self, dst: &mut [u64]) -> bool {
        for _ in 0..READ_ATTEMPTS {
            let i = self.latest.load(Ordering::Acquire);
            let slot = &self.slots[i];
            let s1 = slot.seq.load(Ordering::Acquire);
            if s1 & 1 == 1 {
                std::hint::spin_loop();
                continue;
            }
            for (d, v) in dst.iter_mut().zip(slot.data.iter()) {
                *d = v.load(Ordering::Relaxed);
            }
            fence(Ordering::Acquire);
            let s2 = slot.seq.load(Ordering::Relaxed);
            if s1 == s2 {
                return true;
            }
            std::hint::spin_loop();
        }
        self.read_failures.fetch_add(1, Ordering::Relaxed);
        false
    }

    /// Completed publications so far.
    pub fn published(&self) -> u64 {
        self.published.load(Ordering::Acquire)
    }

    /// Reads that gave up.
    pub fn read_failures(&self) -> u64 {
        self.read_failures.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;

    #[test]
    fn newest_wins() {
        let b = SeqBuffer::new(3);
        let mut d = [9u64; 3];
        assert!(b.read(&mut d));
        assert_eq!(d, [0, 0, 0]);
        assert_eq!(b.published(), 0);
        b.write(&[1, 2, 3]);
        b.write(&[4, 5, 6]);
        assert!(b.read(&mut d));
        assert_eq!(d, [4, 5, 6]);
        b.write(&[7, 8, 9]);
        assert!(b.read(&mut d));
        assert_eq!(d, [7, 8, 9]);
        assert_eq!(b.published(), 3);
        assert_eq!(b.words(), 3);
    }

    /// A writer hammering the buffer: every copy the reader accepts is one
    /// that was written as a whole (all words equal), never a mix.
    #[test]
    fn never_torn_under_contention() {
        const W: usize = 48;
        let b = Arc::new(SeqBuffer::new(W));
        let stop = Arc::new(AtomicBool::new(false));
        let writer = {
            let b = b.clone();
            let stop = stop.clone();
            std::thread::spawn(move || {
                let mut v = 1u64;
                while !stop.load(Ordering::Relaxed) {
                    b.write(&[v; W]);
                    v += 1;
                }
                v
            })
        };
        let mut d = [0u64; W];
        let mut ok = 0u64;
        let mut last = 0;
        let t0 = std::time::Instant::now();
        while t0.elapsed() < std::time::Duration::from_millis(300) {
            if b.read(&mut d) {
                assert!(d.iter().all(|&x| x == d[0]), "torn: {d:?}");
                assert!(d[0] >= last, "went back in time");
                last = d[0];
                ok += 1;
            }
        }
        stop.store(true, Ordering::Relaxed);
        let written = writer.join().unwrap();
        assert!(ok > 0);
        assert!(written > 1);
        // Failed reads (the writer kept overtaking) are possible under this
        // contention and their share depends on the machine's load: what
        // must hold is that none was torn and that reads got through.
        println!("{} failed reads, {ok} good reads", b.read_failures());
    }
}
