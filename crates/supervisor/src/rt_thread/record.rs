//! What the real-time thread measures of its own cycles: warm-up, then
//! wake-up latency, compute time and I/O round trip into preallocated
//! HdrHistograms, the worst wake-ups with what the cycle before them did,
//! and the allocations made after warm-up; every `stats_every` cycles the
//! histogram set goes to the control thread (a box swapped through the
//! queues: nothing allocated or freed here).

use super::{recycle, RtSettings};
use crate::core::CycleInfo;
use crate::shared::Shared;
use crate::stats::{HistSet, LateCycle};
use motion_rt::{counting, rt_pool, Wakeup};
use std::sync::atomic::Ordering;

pub(super) struct Recorder {
    hist: Box<HistSet>,
    period_ns: u64,
    warmup_cycles: u64,
    warmup_limit: u64,
    /// Cycles with every I/O process attached.
    attached_cycles: u64,
    /// What the previous cycle did, for the worst wake-ups.
    prev: LateCycle,
    /// When the previous cycle went to sleep.
    prev_end_ns: u64,
    /// After warm-up: the thread's system-allocator calls and pool
    /// allocations when measuring began.
    baseline: Option<(u64, u64)>,
}

impl Recorder {
    /// Takes a histogram set from the free queue (before the thread's pool
    /// is entered: a new one is allocated if there is none).
    pub fn new(s: &RtSettings, shared: &Shared) -> Self {
        Self {
            hist: shared
                .stats_free
                .pop()
                .unwrap_or_else(|| Box::new(HistSet::new())),
            period_ns: s.machine.supervisor.cycle_ns(),
            warmup_cycles: s.warmup_cycles,
            warmup_limit: s.warmup_limit,
            attached_cycles: 0,
            prev: LateCycle::default(),
            prev_end_ns: 0,
            baseline: None,
        }
    }

    /// One cycle after its frames were published at `t_published`: its
    /// figures into the histograms once warm-up is over, or the end of
    /// warm-up (every I/O process attached long enough, or the limit).
    pub fn cycle(
        &mut self,
        shared: &Shared,
        wake: &Wakeup,
        t_published: u64,
        info: &CycleInfo,
        all_attached: bool,
        cycle: u64,
    ) {
        if all_attached {
            self.attached_cycles += 1;
        }
        if self.baseline.is_some() {
            self.measure(wake, t_published, info);
        } else if self.attached_cycles >= self.warmup_cycles || cycle >= self.warmup_limit {
            self.baseline = Some((
                counting::system_calls_on_this_thread(),
                rt_pool::thread_stats().map_or(0, |p| p.pool_allocs),
            ));
            shared.measuring.store(true, Ordering::Release);
        }
    }

    fn measure(&mut self, wake: &Wakeup, t_published: u64, info: &CycleInfo) {
        let h = &mut self.hist;
        let compute = t_published.saturating_sub(wake.woke_ns);
        h.note_late(LateCycle {
            latency_ns: wake.latency_ns,
            deadline_ns: wake.deadline_ns,
            prev_slack_ns: wake.deadline_ns as i64 - self.prev_end_ns as i64,
            ..self.prev
        });
        self.prev.prev_compute_ns = compute;
        self.prev.prev_snapshot = false;
        self.prev.prev_stats = false;
        h.wakeup.saturating_record(wake.latency_ns.max(1));
        h.compute.saturating_record(compute.max(1));
        if let Some(rt) = info.roundtrip_ns {
            h.roundtrip.saturating_record(rt.max(1));
        }
        h.late_replies += u64::from(info.late_replies);
        if wake.missed > 0 || t_published > wake.deadline_ns + self.period_ns {
            h.deadline_misses += 1;
        }
        if h.start_ns == 0 {
            h.start_ns = wake.deadline_ns;
        }
        h.end_ns = wake.deadline_ns;
        h.cycles += 1;
    }

    /// This cycle handed a status snapshot over (noted for the next
    /// cycle's late wake-up, if it is one).
    pub fn snapshot_handed_over(&mut self) {
        self.prev.prev_snapshot = true;
    }

    /// Hands the histogram set over (swapped for an empty one) and
    /// publishes the allocation counts since warm-up.
    pub fn hand_over(&mut self, shared: &Shared) {
        self.prev.prev_stats = true;
        if let Some(fresh) = shared.stats_free.pop() {
            let full = std::mem::replace(&mut self.hist, fresh);
            if let Err(full) = shared.stats_full.push(full) {
                recycle(&shared.stats_free, full);
            }
        }
        if let Some((sys0, pool0)) = self.baseline {
            let sys = counting::system_calls_on_this_thread() - sys0;
            let pool = rt_pool::thread_stats().map_or(0, |p| p.pool_allocs) - pool0;
            shared.system_calls_in_cycle.store(sys, Ordering::Release);
            shared.pool_allocs_in_cycle.store(pool, Ordering::Release);
        }
    }

    /// The cycle goes to sleep at `now_ns`.
    pub fn asleep(&mut self, now_ns: u64) {
        self.prev_end_ns = now_ns;
    }
}
