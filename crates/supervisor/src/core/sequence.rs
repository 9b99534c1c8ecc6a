//! Home sequences: which axes start when, and what happens when one fails.
//!
//! A home request names a set of axes (or all). They are homed in *home
//! order*: the groups of equal `home_order` one after the other (the axes of
//! a group in parallel), or — when no axis has an order — one at a time in
//! config order; `parallel` starts them all at once. When an axis of the
//! sequence fails, every axis of it still homing is stopped with ERR 12 /
//! EXERR 1, and the later groups are not started; the report names the
//! axis that failed (LinuxCNC #2983: one failing joint must stop the whole
//! sequence).
//!
//! One exception, for buses: an axis whose homing failed because its *I/O
//! process* was lost (ERR 12 / EXERR 40 with the process detached) does not
//! stop axes on other I/O processes — those carry on, as a controller with
//! several buses must (losing one bus aborts only its axes). It still ends
//! the sequence when the config declares a home order (later groups may
//! depend on this axis being homed); without declared orders nothing
//! depends on it, and the remaining axes are homed.
//!
//! Pure and allocation-free per cycle: a few sequences in a fixed array, axes
//! as bit masks.

/// Sequences that may run at once (on disjoint axes).
pub const MAX_RUNS: usize = 8;

/// Key of axes without a `home_order` when others have one: after every
/// ordered group, one at a time in config order (only when named).
const UNORDERED: u32 = 1 << 20;

/// What an axis looks like to the sequencer this cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AxisView {
    /// Started and not finished (a rising edge pending, in process, or
    /// decelerating after an abort).
    pub running: bool,
    /// Finished with an error.
    pub failed: bool,
    /// The error is the loss of its I/O process (not of the axis itself).
    pub io_lost: bool,
}

/// What the sequencer asks the cycle to do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Give axis `i` a rising edge of its Home instruction.
    Start(usize),
    /// Stop axis `i` (ERR 12 / EXERR 1): the sequence failed or timed out.
    Stop(usize),
}

#[derive(Clone, Copy, Debug)]
struct Run {
    members: u64,
    started: u64,
    finished: u64,
    parallel: bool,
    deadline_ns: u64,
    /// First member that failed.
    failed: Option<u8>,
    timed_out: bool,
    /// Members already told to stop.
    stop_sent: u64,
    /// An axis lost its I/O process: start no later group.
    blocked: Option<u8>,
}

#[derive(Clone, Debug)]
pub struct Sequencer {
    key: Vec<u32>,
    has_orders: bool,
    runs: [Option<Run>; MAX_RUNS],
    /// Per axis: the sequence it was part of was aborted because this axis failed.
    aborted_by: Vec<Option<u8>>,
    timed_out: Vec<bool>,
}

impl Sequencer {
    /// `orders[i]`: axis `i`'s `home_order`, if it has one; `together`:
    /// groups of axes that always start in the same cycle (the sides of a
    /// gantry).
    pub fn new(orders: &[Option<u32>]) -> Self {
        Self::with_groups(orders, &[])
    }

    pub fn with_groups(orders: &[Option<u32>], together: &[Vec<usize>]) -> Self {
        let has_orders = orders.iter().any(Option::is_some);
        let key = orders
            .iter()
            .enumerate()
            .map(|(i, o)| match (has_orders, o) {
                (true, Some(o)) => (*o).min(UNORDERED - 1),
                (true, None) => UNORDERED + i as u32,
                (false, _) => i as u32,
            })
            .collect::<Vec<u32>>();
        let mut key = key;
        for g in together {
            if let Some(k) = g.iter().filter_map(|&i| key.get(i).copied()).min() {
                for &i in g {
                    if let Some(x) = key.get_mut(i) {
                        *x = k;
                    }
                }
            }
        }
        Self {
            key,
            has_orders,
            runs: [None; MAX_RUNS],
            aborted_by: vec![None; orders.len()],
            timed_out: vec![false; orders.len()],
        }
    }

    /// The axes "home all" homes: every axis, or, when some have a
    /// `home_order`, only those.
    pub fn all_mask(&self) -> u64 {
        let mut m = 0;
        for (i, k) in self.key.iter().enumerate() {
            if !self.has_orders || *k < UNORDERED {
                m |= 1 << i;
            }
        }
        m
    }

    /// Axes in some sequence.
    pub fn busy(&self) -> u64 {
        self.runs
            .iter()
            .flatten()
            .fold(0, |m, r| m | (r.members & !r.finished))
    }

    pub fn aborted_by(&self, i: usize) -> Option<u8> {
        self.aborted_by.get(i).copied().flatten()
    }

    pub fn timed_out(&self, i: usize) -> bool {
        self.timed_out.get(i).copied().unwrap_or(false)
    }

    /// Starts a sequence over `mask`; false if no slot is free (the caller
    /// checked the axes are not busy).
    pub fn begin(&mut self, mask: u64, parallel: bool, deadline_ns: u64) -> bool {
        let Some(slot) = self.runs.iter_mut().find(|r| r.is_none()) else {
            return false;
        };
        *slot = Some(Run {
            members: mask,
            started: 0,
            finished: 0,
            parallel,
            deadline_ns,
            failed: None,
            timed_out: false,
            stop_sent: 0,
            blocked: None,
        });
        for i in 0..self.key.len().min(64) {
            if mask & (1 << i) != 0 {
                self.aborted_by[i] = None;
                self.timed_out[i] = false;
            }
        }
        true
    }

    /// One cycle: notes which members finished (a member stopped from
    /// outside counts as failed when it ends with an error), ends failed or
    /// timed-out sequences, starts the next group.
    pub fn step(
        &mut self,
        now_ns: u64,
        view: impl Fn(usize) -> AxisView,
        mut act: impl FnMut(Action),
    ) {
        let n = self.key.len().min(64);
        for slot in self.runs.iter_mut() {
            let Some(run) = slot else { continue };
            // Who finished, who failed.
            for i in 0..n {
                let bit = 1u64 << i;
                if run.started & bit != 0 && run.finished & bit == 0 {
                    let v = view(i);
                    if !v.running {
                        run.finished |= bit;
                        let ends_run = !v.io_lost || self.has_orders;
                        if v.failed && run.failed.is_none() && !run.timed_out {
                            if v.io_lost && self.has_orders {
                                // Later groups are not started; the axes of
                                // other buses homing now carry on.
                                run.blocked = Some(i as u8);
                            } else if ends_run {
                                run.failed = Some(i as u8);
                            }
                        }
                    }
                }
            }
            if run.deadline_ns > 0 && now_ns >= run.deadline_ns && run.failed.is_none() {
                run.timed_out = true;
            }
            if run.failed.is_some() || run.timed_out {
                // Stop what still homes (once each), start nothing more, and
                // tell every member why.
                let running = run.started & !run.finished;
                let never = run.members & !run.started;
                for i in 0..n {
                    let bit = 1u64 << i;
                    let stop = running & bit != 0 && run.stop_sent & bit == 0;
                    if stop || never & bit != 0 {
                        if run.timed_out {
                            self.timed_out[i] = true;
                        } else {
                            self.aborted_by[i] = run.failed;
                        }
                    }
                    if stop {
                        run.stop_sent |= bit;
                        act(Action::Stop(i));
                    }
                }
                run.members = run.started;
                if running == 0 {
                    *slot = None;
                }
                continue;
            }
            if run.started & !run.finished != 0 {
                continue; // the current group is still homing
            }
            if let Some(b) = run.blocked {
                let never = run.members & !run.started;
                for i in 0..n {
                    if never & (1u64 << i) != 0 {
                        self.aborted_by[i] = Some(b);
                    }
                }
                *slot = None;
                continue;
            }
            // Next group: the smallest key among members not started.
            let mut next = u32::MAX;
            for i in 0..n {
                let bit = 1u64 << i;
                if run.members & bit != 0 && run.started & bit == 0 {
                    let k = if run.parallel { 0 } else { self.key[i] };
                    next = next.min(k);
                }
            }
            if next == u32::MAX {
                *slot = None; // every member homed
                continue;
            }
            for i in 0..n {
                let bit = 1u64 << i;
                let k = if run.parallel { 0 } else { self.key[i] };
                if run.members & bit != 0 && run.started & bit == 0 && k == next {
                    run.started |= bit;
                    act(Action::Start(i));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    /// Axes that finish `cycles` steps after they start; `fails` fail.
    struct Sim {
        left: RefCell<Vec<i32>>,
        fails: Vec<bool>,
        stopped: RefCell<Vec<bool>>,
        log: RefCell<Vec<(u64, Action)>>,
    }

    impl Sim {
        fn new(n: usize, fails: &[usize]) -> Self {
            Self {
                left: RefCell::new(vec![-1; n]),
                fails: (0..n).map(|i| fails.contains(&i)).collect(),
                stopped: RefCell::new(vec![false; n]),
                log: RefCell::new(Vec::new()),
            }
        }

        fn run(&self, s: &mut Sequencer, cycles: u64, homing: i32) {
            for k in 0..cycles {
                s.step(
                    k,
                    |i| {
                        let l = self.left.borrow()[i];
                        AxisView {
                            running: l > 0,
                            failed: l == 0 && (self.fails[i] || self.stopped.borrow()[i]),
                            io_lost: false,
                        }
                    },
                    |a| {
                        self.log.borrow_mut().push((k, a));
                        match a {
                            Action::Start(i) => self.left.borrow_mut()[i] = homing,
                            Action::Stop(i) => {
                                self.stopped.borrow_mut()[i] = true;
                                self.left.borrow_mut()[i] = 1;
                            }
                        }
                    },
                );
                for l in self.left.borrow_mut().iter_mut() {
                    if *l > 0 {
                        *l -= 1;
                    }
                }
            }
        }

        fn starts(&self) -> Vec<(u64, usize)> {
            self.log
                .borrow()
                .iter()
                .filter_map(|(k, a)| match a {
                    Action::Start(i) => Some((*k, *i)),
                    _ => None,
                })
                .collect()
        }
    }

    #[test]
    fn without_orders_config_order_one_at_a_time() {
        let mut s = Sequencer::new(&[None, None, None]);
        assert_eq!(s.all_mask(), 0b111);
        let sim = Sim::new(3, &[]);
        assert!(s.begin(0b111, false, 0));
        sim.run(&mut s, 40, 5);
        // each starts the cycle after the previous one finished (5 cycles)
        assert_eq!(sim.starts(), vec![(0, 0), (5, 1), (10, 2)]);
        assert_eq!(s.busy(), 0);
    }

    #[test]
    fn orders_make_parallel_groups_and_unordered_axes_stay_out() {
        // X order 1, Y order 0, Z none, W order 0
        let mut s = Sequencer::new(&[Some(1), Some(0), None, Some(0)]);
        assert_eq!(s.all_mask(), 0b1011, "Z is homed only when named");
        let sim = Sim::new(4, &[]);
        s.begin(s.all_mask(), false, 0);
        sim.run(&mut s, 40, 5);
        assert_eq!(sim.starts(), vec![(0, 1), (0, 3), (5, 0)]);
    }

    #[test]
    fn a_failure_stops_the_group_and_starts_nothing_more() {
        // Y (1) and W (3) in order 0 together, X (0) in order 1.
        let mut s = Sequencer::new(&[Some(1), Some(0), None, Some(0)]);
        let sim = Sim::new(4, &[1]);
        // Y fails after 3 cycles, W would take 10.
        s.begin(0b1011, false, 0);
        for k in 0..30 {
            s.step(
                k,
                |i| {
                    let l = sim.left.borrow()[i];
                    AxisView {
                        running: l > 0,
                        failed: l == 0 && (sim.fails[i] || sim.stopped.borrow()[i]),
                        io_lost: false,
                    }
                },
                |a| {
                    sim.log.borrow_mut().push((k, a));
                    match a {
                        Action::Start(i) => sim.left.borrow_mut()[i] = if i == 1 { 3 } else { 10 },
                        Action::Stop(i) => {
                            sim.stopped.borrow_mut()[i] = true;
                            sim.left.borrow_mut()[i] = 1;
                        }
                    }
                },
            );
            for l in sim.left.borrow_mut().iter_mut() {
                if *l > 0 {
                    *l -= 1;
                }
            }
        }
        let log = sim.log.borrow().clone();
        assert_eq!(
            log,
            vec![
                (0, Action::Start(1)),
                (0, Action::Start(3)),
                (3, Action::Stop(3)), // Y failed: W stopped at once
            ]
        );
        assert_eq!(s.aborted_by(3), Some(1));
        assert_eq!(
            s.aborted_by(0),
            Some(1),
            "X was never started, and says why"
        );
        assert_eq!(s.aborted_by(1), None);
        assert_eq!(s.busy(), 0);
    }

    /// Axis 1 loses its I/O process while 0 (another bus) homes with it.
    fn io_loss(orders: &[Option<u32>]) -> (Sequencer, Vec<(u64, Action)>) {
        let mut s = Sequencer::new(orders);
        let left = RefCell::new(vec![-1i32; 3]);
        let mut log = Vec::new();
        s.begin(0b111, false, 0);
        for k in 0..40 {
            s.step(
                k,
                |i| {
                    let l = left.borrow()[i];
                    AxisView {
                        running: l > 0,
                        failed: l == 0 && i == 1,
                        io_lost: l == 0 && i == 1,
                    }
                },
                |a| {
                    log.push((k, a));
                    if let Action::Start(i) = a {
                        left.borrow_mut()[i] = if i == 1 { 3 } else { 8 };
                    }
                },
            );
            for l in left.borrow_mut().iter_mut() {
                if *l > 0 {
                    *l -= 1;
                }
            }
        }
        (s, log)
    }

    #[test]
    fn losing_an_io_process_stops_no_other_bus() {
        // Orders: 0 and 1 together, 2 after them.
        let (s, log) = io_loss(&[Some(0), Some(0), Some(1)]);
        assert_eq!(log, vec![(0, Action::Start(0)), (0, Action::Start(1))]);
        assert_eq!(s.aborted_by(0), None, "axis 0 homes on");
        assert_eq!(s.aborted_by(2), Some(1), "the later order is not started");
        // No declared orders: nothing depends on axis 1, the rest is homed.
        let (_, log) = io_loss(&[None, None, None]);
        let starts: Vec<_> = log
            .iter()
            .filter(|(_, a)| matches!(a, Action::Start(_)))
            .collect();
        assert_eq!(starts.len(), 3);
        assert!(!log.iter().any(|(_, a)| matches!(a, Action::Stop(_))));
    }

    #[test]
    fn parallel_starts_everything_at_once() {
        let mut s = Sequencer::new(&[None, None, None]);
        let sim = Sim::new(3, &[]);
        s.begin(0b101, true, 0);
        sim.run(&mut s, 20, 5);
        assert_eq!(sim.starts(), vec![(0, 0), (0, 2)]);
    }

    #[test]
    fn a_timeout_stops_what_still_homes() {
        let mut s = Sequencer::new(&[None, None]);
        let sim = Sim::new(2, &[]);
        s.begin(0b11, false, 7);
        sim.run(&mut s, 30, 20);
        let log = sim.log.borrow().clone();
        assert_eq!(log, vec![(0, Action::Start(0)), (7, Action::Stop(0))]);
        assert!(s.timed_out(0) && s.timed_out(1));
        assert_eq!(s.busy(), 0);
    }
}
