//! In-process exchange between SupervisorPorts and IoPorts: 1,000 round trips,
//! cleanup check, and heap allocations per operation (counting allocator).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::Duration;

use common::TestEnv;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use motion_frames::{
    axis_to_command, axis_to_feedback, command_to_axis, feedback_to_axis, CommandFrame,
    LAYOUT_VERSION,
};
use motion_homing::{Command, Edge, Feedback, LatchArm};
use motion_ipc::{monotonic_ns, IoPorts, SupervisorPorts};

// ---------------------------------------------------------------------------
// Counting allocator: counts allocations of the current thread only, so tests
// running in parallel threads do not disturb each other.
// ---------------------------------------------------------------------------

struct Counting;

thread_local! {
    static ALLOCS: Cell<u64> = const { Cell::new(0) };
}

fn bump() {
    let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: forwards to the system allocator; the counter is a const-initialized
// thread-local without destructor (no allocation, no re-entrancy).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        bump();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        bump();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        bump();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocs() -> u64 {
    ALLOCS.with(|c| c.get())
}

/// Runs `f`, returns its result and the number of heap allocations it made.
fn counted<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let before = allocs();
    let r = f();
    (r, allocs() - before)
}

#[derive(Default)]
struct Tally {
    name: &'static str,
    calls: u64,
    total: u64,
    max: u64,
}

impl Tally {
    fn new(name: &'static str) -> Self {
        Self {
            name,
            ..Self::default()
        }
    }
    fn add(&mut self, n: u64) {
        self.calls += 1;
        self.total += n;
        self.max = self.max.max(n);
    }
    fn print(&self) {
        println!(
            "  {:<44} calls {:>5}  allocations/call avg {:>5.2}  max {}",
            self.name,
            self.calls,
            self.total as f64 / self.calls.max(1) as f64,
            self.max
        );
    }
}

const CPU: f64 = 1000.0;
const AXES: usize = 4;

fn engine_command(i: u64) -> Command {
    Command {
        enable: true,
        position: i as f64 / CPU, // on the count grid: survives the round trip exactly
        velocity: 1.5,
        torque_limit_positive: 100.0,
        torque_limit_negative: 100.0,
        position_error_tolerance: 0.25,
        velocity_error_tolerance: 0.0,
        marker_arm: LatchArm {
            id: (i % 200) as u8 + 1,
            edge: Edge::Rising,
        },
        switch_arm: LatchArm {
            id: 3,
            edge: Edge::Falling,
        },
        fault_reset: false,
        drive_home: false,
    }
}

/// One motion-io answer: echo the commanded position as actual position.
fn io_answer(cmd: &CommandFrame) -> Feedback {
    let c = axis_to_command(&cmd.axes[0], CPU);
    Feedback {
        position: c.position,
        velocity: c.velocity,
        home_switch: true,
        ..Feedback::default()
    }
}

/// Both sides of I/O process "io" in `env`'s domain, each on its own node
/// (as in two processes), connected. Bind all three: the ports drop before
/// the nodes.
fn connected(env: &TestEnv) -> ([Node<ipc::Service>; 2], SupervisorPorts, IoPorts) {
    let sup_node = env.domain.create_node("motion-supervisor").unwrap();
    let io_node = env.domain.create_node("motion-io").unwrap();
    let mut sup = SupervisorPorts::create(&sup_node, &env.domain, "io").unwrap();
    let mut io = IoPorts::open(&io_node, &env.domain, "io").unwrap();
    sup.update_connections().unwrap();
    io.update_connections().unwrap();
    ([sup_node, io_node], sup, io)
}

#[test]
fn thousand_round_trips_in_one_process_and_nothing_left_behind() {
    let env = TestEnv::new("rt");
    {
        let (_nodes, mut sup, mut io) = connected(&env);

        let timeout = Duration::from_secs(2);
        let mut last_cmd_ts = 0;
        for i in 1..=1000u64 {
            let cmd = engine_command(i);
            let sent = sup
                .publish(|f| {
                    f.header.axis_count = AXES as u32;
                    for a in &mut f.axes[..AXES] {
                        *a = command_to_axis(&cmd, CPU);
                    }
                })
                .unwrap();
            assert_eq!(sent.sequence, i);
            assert_eq!(sent.receivers, 1);
            assert_eq!(sup.notify().unwrap(), 1);

            // motion-io side
            assert!(io.wait(timeout).unwrap(), "io not woken in cycle {i}");
            let c = io.receive_latest().unwrap().expect("command frame");
            let taken_ns = monotonic_ns();
            assert_eq!(c.header.layout_version, LAYOUT_VERSION);
            assert_eq!(c.header.sequence, i);
            assert_eq!(c.header.axis_count, AXES as u32);
            assert!(c.header.timestamp_ns >= last_cmd_ts);
            assert!(c.header.timestamp_ns <= taken_ns);
            last_cmd_ts = c.header.timestamp_ns;
            assert_eq!(axis_to_command(&c.axes[AXES - 1], CPU), cmd);
            let answers = c.header.sequence;
            let fb = io_answer(&c);
            drop(c);
            let fsent = io
                .send(|f| {
                    f.header.axis_count = AXES as u32;
                    f.answers_sequence = answers;
                    f.io_received_ns = taken_ns;
                    for a in &mut f.axes[..AXES] {
                        *a = feedback_to_axis(&fb, CPU);
                    }
                })
                .unwrap();
            assert_eq!(fsent.sequence, i);

            // supervisor side
            assert!(
                sup.wait(timeout).unwrap(),
                "supervisor not woken in cycle {i}"
            );
            let f = sup.receive_latest().unwrap().expect("feedback frame");
            assert_eq!(f.header.sequence, i);
            assert_eq!(f.answers_sequence, sent.sequence);
            assert_eq!(f.io_received_ns, taken_ns);
            assert!(f.header.timestamp_ns >= f.io_received_ns);
            assert_eq!(f.active_axes().len(), AXES);
            assert_eq!(axis_to_feedback(&f.axes[0], CPU), fb);
        }
        assert_eq!(sup.skipped(), 0);
        assert_eq!(io.skipped(), 0);
        assert!(!sup.try_wait().unwrap());
        assert!(!io.try_wait().unwrap());
        println!("shm while running: {:?}", env.shm_files());
        assert!(!env.shm_files().is_empty());
    }
    env.assert_clean_and_remove();
}

#[test]
fn heap_allocations_per_operation() {
    let env = TestEnv::new("al");
    {
        let (_nodes, mut sup, mut io) = connected(&env);

        let timeout = Duration::from_secs(2);
        let mut t_publish = Tally::new("SupervisorPorts::publish (loan+init+send)");
        let mut t_notify = Tally::new("SupervisorPorts::notify");
        let mut t_io_wait = Tally::new("IoPorts::wait (timed_wait, woken)");
        let mut t_io_recv = Tally::new("IoPorts::receive_latest (1 frame)");
        let mut t_drop = Tally::new("drop of a received sample");
        let mut t_io_send = Tally::new("IoPorts::send (publish+notify)");
        let mut t_sup_wait = Tally::new("SupervisorPorts::wait (timed_wait, woken)");
        let mut t_sup_recv = Tally::new("SupervisorPorts::receive_latest (1 frame)");
        let mut t_try_wait = Tally::new("SupervisorPorts::try_wait (nothing pending)");
        let mut t_timeout = Tally::new("SupervisorPorts::wait (1 ms timeout)");
        let mut t_convert = Tally::new("command_to_axis + axis_to_feedback");

        const WARMUP: u64 = 100;
        for i in 1..=1100u64 {
            let m = i > WARMUP;
            let cmd = engine_command(i);
            let (sent, n) = counted(|| {
                sup.publish(|f| {
                    f.header.axis_count = AXES as u32;
                    for a in &mut f.axes[..AXES] {
                        *a = command_to_axis(&cmd, CPU);
                    }
                })
                .unwrap()
            });
            if m {
                t_publish.add(n);
            }
            let (_, n) = counted(|| sup.notify().unwrap());
            if m {
                t_notify.add(n);
            }
            let (woken, n) = counted(|| io.wait(timeout).unwrap());
            assert!(woken);
            if m {
                t_io_wait.add(n);
            }
            let (c, n) = counted(|| io.receive_latest().unwrap().unwrap());
            if m {
                t_io_recv.add(n);
            }
            let answers = c.header.sequence;
            assert_eq!(answers, sent.sequence);
            let fb = io_answer(&c);
            let (_, n) = counted(|| drop(c));
            if m {
                t_drop.add(n);
            }
            let (_, n) = counted(|| {
                io.send(|f| {
                    f.header.axis_count = AXES as u32;
                    f.answers_sequence = answers;
                    f.io_received_ns = monotonic_ns();
                    for a in &mut f.axes[..AXES] {
                        *a = feedback_to_axis(&fb, CPU);
                    }
                })
                .unwrap()
            });
            if m {
                t_io_send.add(n);
            }
            let (woken, n) = counted(|| sup.wait(timeout).unwrap());
            assert!(woken);
            if m {
                t_sup_wait.add(n);
            }
            let (f, n) = counted(|| sup.receive_latest().unwrap().unwrap());
            if m {
                t_sup_recv.add(n);
            }
            assert_eq!(f.answers_sequence, sent.sequence);
            let (_, n) = counted(|| {
                let a = command_to_axis(&cmd, CPU);
                let b = axis_to_feedback(&f.axes[0], CPU);
                std::hint::black_box((a, b));
            });
            if m {
                t_convert.add(n);
            }
            drop(f);
            let (p, n) = counted(|| sup.try_wait().unwrap());
            assert!(!p);
            if m {
                t_try_wait.add(n);
            }
            if m && i % 100 == 0 {
                let (w, n) = counted(|| sup.wait(Duration::from_millis(1)).unwrap());
                assert!(!w);
                t_timeout.add(n);
            }
        }

        println!(
            "heap allocations per call, motion-ipc API, steady state \
             ({} measured cycles after {WARMUP} warm-up):",
            t_publish.calls
        );
        for t in [
            &t_publish,
            &t_notify,
            &t_io_wait,
            &t_io_recv,
            &t_drop,
            &t_io_send,
            &t_sup_wait,
            &t_sup_recv,
            &t_try_wait,
            &t_timeout,
            &t_convert,
        ] {
            t.print();
        }
        // conversions are documented allocation-free: hold them to it
        assert_eq!(t_convert.total, 0);
    }
    env.assert_clean_and_remove();
}

/// The raw iceoryx2 calls, one by one, with the same QoS as motion-ipc, to
/// split `publish` into loan / write / send and compare with the notes' table.
#[test]
fn heap_allocations_per_raw_iceoryx2_call() {
    let env = TestEnv::new("raw");
    {
        let node = env.domain.create_node("probe").unwrap();
        let topic = node
            .service_builder(&ServiceName::new(&format!("{}/probe", env.domain.prefix)).unwrap())
            .publish_subscribe::<CommandFrame>()
            .enable_safe_overflow(true)
            .subscriber_max_buffer_size(2)
            .history_size(0)
            .max_publishers(1)
            .max_subscribers(3)
            .open_or_create()
            .unwrap();
        let event = node
            .service_builder(
                &ServiceName::new(&format!("{}/probe_ready", env.domain.prefix)).unwrap(),
            )
            .event()
            .open_or_create()
            .unwrap();
        let publisher = topic.publisher_builder().create().unwrap();
        let subscriber = topic.subscriber_builder().create().unwrap();
        let notifier = event.notifier_builder().create().unwrap();
        let listener = event.listener_builder().create().unwrap();
        publisher.update_connections().unwrap();
        subscriber.update_connections().unwrap();
        notifier.update_connections().unwrap();

        let mut t_loan_uninit = Tally::new("publisher.loan_uninit()");
        let mut t_placement = Tally::new("PlacementDefault + assume_init");
        let mut t_write = Tally::new("sample.write_payload(CommandFrame::ZERO)");
        let mut t_loan = Tally::new("publisher.loan() (Default payload)");
        let mut t_send = Tally::new("sample.send()");
        let mut t_send_copy = Tally::new("publisher.send_copy(frame)");
        let mut t_receive = Tally::new("subscriber.receive() (Some)");
        let mut t_receive_none = Tally::new("subscriber.receive() (None)");
        let mut t_drop = Tally::new("drop(sample)");
        let mut t_notify = Tally::new("notifier.notify()");
        let mut t_timed_wait = Tally::new("listener.timed_wait(cb, 1 s) (woken)");
        let mut t_try_wait = Tally::new("listener.try_wait(cb) (nothing)");

        let frame = CommandFrame::default();
        for i in 0..1100u32 {
            let m = i >= 100;
            macro_rules! rec {
                ($t:ident, $e:expr) => {{
                    let (r, n) = counted(|| $e);
                    if m {
                        $t.add(n);
                    }
                    r
                }};
            }
            // loan_uninit + in-place init + send (what SupervisorPorts::publish does)
            let mut s = rec!(t_loan_uninit, publisher.loan_uninit().unwrap());
            let s = rec!(t_placement, unsafe {
                CommandFrame::placement_default(s.payload_mut().as_mut_ptr());
                s.assume_init()
            });
            rec!(t_send, s.send().unwrap());
            let r = rec!(t_receive, subscriber.receive().unwrap().unwrap());
            rec!(t_drop, drop(r));
            // loan_uninit + write_payload
            let s = publisher.loan_uninit().unwrap();
            let s = rec!(t_write, s.write_payload(CommandFrame::ZERO));
            drop(s);
            // loan() for Default payloads
            let s = rec!(t_loan, publisher.loan().unwrap());
            drop(s);
            rec!(t_send_copy, publisher.send_copy(frame).unwrap());
            drop(subscriber.receive().unwrap().unwrap());
            assert!(rec!(t_receive_none, subscriber.receive().unwrap()).is_none());
            rec!(t_notify, notifier.notify().unwrap());
            let n = rec!(
                t_timed_wait,
                listener.timed_wait(|_| {}, Duration::from_secs(1)).unwrap()
            );
            assert!(n > 0);
            let n = rec!(t_try_wait, listener.try_wait(|_| {}).unwrap());
            assert_eq!(n, 0);
        }
        println!("heap allocations per call, raw iceoryx2 0.10 (1000 measured, 100 warm-up):");
        for t in [
            &t_loan_uninit,
            &t_placement,
            &t_write,
            &t_loan,
            &t_send,
            &t_send_copy,
            &t_receive,
            &t_receive_none,
            &t_drop,
            &t_notify,
            &t_timed_wait,
            &t_try_wait,
        ] {
            t.print();
        }
    }
    env.assert_clean_and_remove();
}
