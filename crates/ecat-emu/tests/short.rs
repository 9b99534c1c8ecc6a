//! A drive short on process data, against the backend on the wire (veth
//! pair, root; skipped otherwise): a SubDevice that still answers its AL
//! status but no longer its process data — dropped to SAFE-OP with an AL
//! error (its output sync manager deactivated: 1 of 3 in the working
//! counter), or to PRE-OP (0 of 3) — or one in OP whose process data the
//! working counter does not show at all.
//!
//! What must hold, read from the emulated drives themselves: the other
//! drives keep valid data and every stop reaches them within its bound
//! (motion-io's watchdog stop, the shutdown of SIGTERM, a disable, the
//! emergency stop, the bus thread's own watchdog when no command comes);
//! the short one stops by its own reaction to the lost outputs; a drive
//! whose data returns is never jumped to a target that ran away and never
//! enabled again by itself.
//!
//! The bounds count bus cycles (what the stop counts; a loaded host
//! stretches a cycle beyond its period); the milliseconds are only shown.

mod common;

use std::time::{Duration, Instant};

use common::*;
use ecat_emu::{al, Dropped, State};
use motion_frames::backend::Backend;
use motion_frames::{
    FeedbackFrame, CW_ENABLE, CW_FAULT_RESET, SW_DRIVE_LOST, SW_ENABLED, SW_FAULT, SW_NO_DATA,
};

/// Counts per cycle both axes move at before the fault (20 units/s).
const STEP: i64 = 20;

/// A step of a drive's target this large is a jump: ten cycles' travel at
/// once. A loaded host that keeps the bus thread or the test's own thread
/// off the CPU for a few cycles makes steps of a few cycles' travel (the
/// newest command then goes out); the jump under test is a whole 30-cycle
/// gap's travel (600 counts).
const JUMP: i32 = 10 * STEP as i32;

/// How a test stops the drives.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stop {
    /// motion-io's watchdog (commands stopped): `watchdog_stop` every cycle.
    Watchdog,
    /// SIGTERM: `shutdown`, paced and bounded by the backend itself.
    Shutdown,
    /// The operator's disable: `CW_ENABLE` off on axis 0.
    Disable,
    /// `emergency_stop`.
    Emergency,
    /// Nothing at all: motion-io's main loop blocked, no command reaches
    /// the bus thread, whose own watchdog stops the drives.
    Silence,
}

/// Both axes enabled and moving at [`STEP`] counts per cycle (drive 0
/// changed by `drive0`).
fn two_moving(
    drive0: impl FnOnce(&mut ecat_emu::DriveConfig),
    tweak: impl FnOnce(&mut motion_config::EthercatBus),
) -> Option<Rig> {
    let mut d0 = drive("EMU-0");
    drive0(&mut d0);
    let mut r = rig_with(vec![d0, drive("EMU-1")], tweak)?;
    r.enable(0);
    r.enable(1);
    jog(&mut r, 200);
    Some(r)
}

/// Runs `body` on a fresh rig from `setup` (two axes moving), up to three
/// times. A loaded host can lose frames in a row (the bus thread or the
/// emulator off the CPU for a few ms): the drives are then lost, and
/// stopped by design when their command ran away meanwhile. An attempt that
/// failed while more drives were lost than the test itself made
/// (`expected`) shows the host, not the backend: it is made again; any
/// other failure, or the third, stands.
fn retried(expected: u64, setup: impl Fn() -> Option<Rig>, body: impl Fn(&mut Rig)) {
    let _t = turn();
    for attempt in 1..=3 {
        let Some(mut r) = setup() else { return };
        let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| body(&mut r)));
        let losses = r.backend.bus_status().losses;
        match ran {
            Ok(()) => return,
            Err(_) if losses > expected && attempt < 3 => eprintln!(
                "attempt {attempt}: {} drive loss(es) the host made: again",
                losses - expected
            ),
            Err(e) => std::panic::resume_unwind(e),
        }
    }
}

/// `n` cycles with both axes' targets advancing by [`STEP`] (and the
/// velocity that goes with it, as the engine sends it).
fn jog(r: &mut Rig, n: usize) {
    for _ in 0..n {
        for i in 0..2 {
            r.axis(i).target_position += STEP;
            r.axis(i).target_velocity = (STEP * 1000) as f64;
        }
        r.tick();
    }
}

/// Drive `i`'s power stage is off (its state says so).
fn off(r: &Rig, i: usize) -> bool {
    let v = r.drive(i);
    !v.enabled
        && matches!(
            v.state,
            State::SwitchOnDisabled | State::ReadyToSwitchOn | State::Fault
        )
}

/// Runs `how` until drive 0 is off and at rest; returns the bus cycles
/// it took from the first stop cycle (and shows the milliseconds).
fn stop_healthy(r: &mut Rig, how: Stop) -> u64 {
    let c0 = r.backend.bus_status().cycles;
    let t0 = Instant::now();
    let mut fb = FeedbackFrame::ZERO;
    let mut done = false;
    loop {
        match how {
            Stop::Watchdog => done |= r.backend.watchdog_stop(0.001, &mut fb),
            Stop::Shutdown => {
                // paced by the backend; returns when complete or bounded
                done = r.backend.shutdown(0.001, &mut fb);
                assert!(done, "the controlled stop did not complete: {fb:?}");
            }
            Stop::Disable => {
                r.axis(0).control_word = 0;
                r.tick();
            }
            Stop::Emergency => r.backend.emergency_stop(&mut fb),
            Stop::Silence => {}
        }
        if how != Stop::Disable {
            std::thread::sleep(CYCLE);
        }
        if off(r, 0) && r.drive(0).velocity == 0.0 {
            break;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(3),
            "{how:?}: drive 0 not off: {:?}; feedback {:?}",
            r.drive(0),
            &fb.axes[..2]
        );
    }
    let cycles = r.backend.bus_status().cycles - c0;
    eprintln!(
        "{how:?}: the healthy drive off and at rest {:.1} ms ({cycles} bus cycles) after the \
         stop began: {:?}",
        t0.elapsed().as_secs_f64() * 1e3,
        r.drive(0)
    );
    if how == Stop::Watchdog {
        // complete as the backend sees it, the short drive not waited for
        let t1 = Instant::now();
        while !done {
            std::thread::sleep(CYCLE);
            done = r.backend.watchdog_stop(0.001, &mut fb);
            assert!(t1.elapsed() < Duration::from_secs(1), "{:?}", &fb.axes[..2]);
        }
    }
    cycles
}

/// Drive 1 falls out of OP (`to`) while both move and stays out (OP refused
/// with `code`); axis 0 keeps valid data, axis 1 is reported lost; `how`
/// stops drive 0 within its bound; drive 1 stops by its own reaction.
fn short_then_stop(to: Dropped, code: u16, how: Stop) {
    // quick stop bound 300 ms: the cycles below are checked against it; the
    // drives' SM watchdogs 2 s (a host that stalls the bus thread does not
    // stop them first)
    let setup = || {
        two_moving(
            |_| {},
            |c| {
                c.keys.quick_stop_timeout_ms = 300;
                c.keys.sm_watchdog_ms = 2_000;
            },
        )
    };
    retried(1, setup, |r| short_then_stop_on(r, to, code, how));
}

fn short_then_stop_on(r: &mut Rig, to: Dropped, code: u16, how: Stop) {
    let before = r.backend.bus_status();
    r.emu().refuse_op(1, Some(code));
    r.emu().drop_out_of_op(1, to);
    r.until_axis(1, "axis 1 lost", |a| a.status_word & SW_DRIVE_LOST != 0);
    assert_eq!(r.fb.axes[1].status_word & SW_ENABLED, 0);
    // axis 0 runs on with valid data: its working counter is not blamed
    let from = r.drive(0).position;
    jog(r, 100);
    let st = r.backend.bus_status();
    assert!(
        st.wkc_errors > before.wkc_errors,
        "no short working counter"
    );
    assert_eq!(
        st.axes[0].no_data_wkc, before.axes[0].no_data_wkc,
        "axis 0's data taken for invalid: {:?}",
        st.axes[0]
    );
    // (100 cycles of 20 counts: 2 units; a cycle whose set-point the bus
    // took twice on a loaded host moves 0)
    let v = r.drive(0);
    assert_eq!(v.state, State::OperationEnabled);
    assert!(v.position - from > 1.5, "{from} → {v:?}");

    let cycles = stop_healthy(r, how);
    // the bounded stop: quick stop ≤ 300 cycles (the drive's ramp from 20
    // u/s takes 20), then disable voltage; the bus thread's own watchdog
    // first waits 2 × 50 cycles without a command
    let bound = match how {
        Stop::Silence => 100 + 300 + 20,
        _ => 300 + 20,
    };
    assert!(cycles <= bound, "{how:?}: {cycles} bus cycles > {bound}");
    if how == Stop::Silence {
        let st = r.backend.bus_status();
        assert_eq!(
            st.bus_watchdog_trips,
            1,
            "{st:?}\n{:?}\n{:?}",
            r.drive(0),
            r.drive(1)
        );
    }
    // the short drive: its own reaction to the lost outputs (ETG.6010's
    // abort connection option: quick stop, a fault after an SM watchdog)
    let v = r.drive(1);
    let own = if code == al::SM_WATCHDOG && to != Dropped::PreOp {
        State::Fault
    } else {
        State::SwitchOnDisabled
    };
    assert_eq!((v.state, v.velocity, v.enabled), (own, 0.0, false), "{v:?}");
}

#[test]
fn safe_op_with_an_al_error_the_others_stop_by_the_watchdog() {
    short_then_stop(
        Dropped::SafeOp(al::SYNC_ERROR),
        al::SYNC_ERROR,
        Stop::Watchdog,
    );
}

#[test]
fn safe_op_after_an_sm_watchdog_the_others_stop_by_the_shutdown() {
    short_then_stop(
        Dropped::SafeOp(al::SM_WATCHDOG),
        al::SM_WATCHDOG,
        Stop::Shutdown,
    );
}

#[test]
fn safe_op_with_an_al_error_the_other_is_disabled() {
    short_then_stop(
        Dropped::SafeOp(al::SYNC_ERROR),
        al::SYNC_ERROR,
        Stop::Disable,
    );
}

#[test]
fn pre_op_the_others_stop_by_the_emergency_stop() {
    short_then_stop(Dropped::PreOp, al::SYNC_ERROR, Stop::Emergency);
}

#[test]
fn pre_op_no_command_the_bus_thread_stops_the_others_by_itself() {
    short_then_stop(Dropped::PreOp, al::SYNC_ERROR, Stop::Silence);
}

/// The short drive comes back: OP again, its data valid, never enabled by
/// itself although enable is still asked for, no step of its target; the
/// other axis, which ran on, still follows.
#[test]
fn a_short_drive_back_in_op_is_neither_enabled_nor_jumped() {
    retried(1, || two_moving(|_| {}, |_| {}), back_in_op);
}

fn back_in_op(r: &mut Rig) {
    let wkc0 = r.backend.bus_status().axes[0].no_data_wkc;
    r.emu().refuse_op(1, Some(al::SYNC_ERROR));
    r.emu().drop_out_of_op(1, Dropped::SafeOp(al::SYNC_ERROR));
    r.until_axis(1, "axis 1 lost", |a| a.status_word & SW_DRIVE_LOST != 0);
    jog(r, 100);
    r.until("drive 1 at rest", Duration::from_secs(2), |r| {
        r.drive(1).velocity == 0.0
    });
    let at = r.drive(1).position;
    r.emu().refuse_op(1, None);
    // its command ran on meanwhile, enable still asked for
    let n = r.until("axis 1 back", Duration::from_secs(3), |r| {
        let a = r.fb.axes[1].status_word;
        a & (SW_NO_DATA | SW_DRIVE_LOST) == 0 && r.emu().view(1).unwrap().al_status == 0x08
    });
    eprintln!("axis 1 back after {n} cycles: {:?}", r.fb.axes[1]);
    // (the frame or two before the backend saw it back carried the outputs
    // of its last cycle before the loss: ignored by a drive not enabled)
    r.emu().record_targets(1, true);
    jog(r, 100);
    let v = r.drive(1);
    assert_eq!(v.state, State::SwitchOnDisabled, "{v:?}");
    assert!((v.position - at).abs() < 1e-9, "moved: {at} → {v:?}");
    assert_eq!(
        r.fb.axes[1].status_word & (SW_ENABLED | SW_FAULT),
        SW_FAULT,
        "a lost drive's fault until a reset"
    );
    let targets = r.emu().take_targets(1);
    let here = (at * 1000.0).round() as i32;
    assert!(
        targets.iter().all(|t| (t - here).abs() <= 1),
        "a target away from the drive: {:?}",
        targets.iter().find(|t| (*t - here).abs() > 1)
    );
    // the other axis' data was never blamed for the short drive's
    assert_eq!(r.backend.bus_status().axes[0].no_data_wkc, wkc0);
    // a reset and an enable from where it stands: it follows again
    let pos = r.fb.axes[1].position;
    r.axis(1).target_position = pos;
    r.axis(1).control_word = CW_ENABLE | CW_FAULT_RESET;
    r.until_axis(1, "enabled after the reset", |a| {
        a.status_word & SW_ENABLED != 0
    });
}

/// SubDevice 1 stays in OP but its process data is not counted: the
/// shortfall explains nobody, so no axis' data can be trusted. A stop
/// still reaches drive 0, blind: quick stop until the bound (nothing tells
/// whether the drive honours it: this one ignores it), then disable
/// voltage; it ends in Switch on disabled by its own state machine.
#[test]
fn a_stop_reaches_the_drives_whatever_the_working_counter_says() {
    // the refusing drive's SM watchdog must not expire during the test (it
    // would leave OP and explain the shortfall)
    let setup = || {
        two_moving(
            |d| d.ignores_quick_stop = true,
            |c| {
                c.keys.quick_stop_timeout_ms = 100;
                c.keys.sm_watchdog_ms = 5_000;
            },
        )
    };
    retried(0, setup, blind_stop);
}

fn blind_stop(r: &mut Rig) {
    r.emu().refuse_process_data(1, true);
    r.until("no data on axis 0", Duration::from_secs(1), |r| {
        r.fb.axes[0].status_word & SW_NO_DATA != 0
    });
    let c0 = r.backend.bus_status().cycles;
    let t0 = Instant::now();
    let mut fb = FeedbackFrame::ZERO;
    let mut quick_stop = false;
    while !off(r, 0) {
        r.backend.watchdog_stop(0.001, &mut fb);
        std::thread::sleep(CYCLE);
        quick_stop |= r.drive(0).controlword == 0x0002;
        assert!(
            t0.elapsed() < Duration::from_secs(2),
            "drive 0 not off: {:?}",
            r.drive(0)
        );
    }
    let cycles = r.backend.bus_status().cycles - c0;
    eprintln!(
        "blind stop: drive 0 off {:.1} ms ({cycles} bus cycles) after the stop began: {:?}",
        t0.elapsed().as_secs_f64() * 1e3,
        r.drive(0)
    );
    assert!(quick_stop, "quick stop first");
    // quick stop until the 100-cycle bound, then disable voltage
    assert!((100..=130).contains(&cycles), "{cycles} bus cycles");
    let st = r.backend.bus_status();
    assert!(st.axes[0].blind_stop_cycles >= 100, "{:?}", st.axes[0]);
    // not complete as the backend sees it: nothing was seen
    assert!(!r.backend.watchdog_stop(0.001, &mut fb));
    // data again: the stop is seen complete
    r.emu().refuse_process_data(1, false);
    let t1 = Instant::now();
    while !r.backend.watchdog_stop(0.001, &mut fb) {
        std::thread::sleep(CYCLE);
        assert!(t1.elapsed() < Duration::from_secs(2), "{:?}", &fb.axes[..2]);
    }
}

/// SubDevice 1's process data uncounted for 30 cycles while both axes
/// move at 20 counts per cycle: no axis' data is valid meanwhile, but drive
/// 0's outputs still arrive and it goes on getting its command's target —
/// no jump when the data returns (before, it held the last target and
/// then jumped 0.6 units in one cycle).
#[test]
fn a_working_counter_not_to_be_trusted_leaves_the_drives_following() {
    let setup = || two_moving(|_| {}, |c| c.keys.sm_watchdog_ms = 5_000);
    retried(0, setup, following_without_data);
}

fn following_without_data(r: &mut Rig) {
    r.emu().record_targets(0, true);
    r.emu().refuse_process_data(1, true);
    r.until("no data on axis 0", Duration::from_secs(1), |r| {
        r.fb.axes[0].status_word & SW_NO_DATA != 0
    });
    jog(r, 30);
    r.emu().refuse_process_data(1, false);
    let mut n = 0;
    while r.fb.axes[0].status_word & SW_NO_DATA != 0 {
        jog(r, 1);
        n += 1;
        assert!(n < 1000, "no data again");
    }
    jog(r, 50);
    let t = r.emu().take_targets(0);
    let worst = largest_step(&t);
    eprintln!("largest step of drive 0's target: {worst} counts");
    assert!(worst <= JUMP, "a jump of {worst} counts");
    // 80 cycles or more of 20 counts (the frames recorded)
    let moved = t.last().unwrap() - t.first().unwrap();
    assert!(moved >= 70 * STEP as i32, "followed: {moved} counts");
    let a = r.fb.axes[0].status_word;
    assert_eq!(a & (SW_ENABLED | SW_FAULT), SW_ENABLED, "{a:#x}");
}

fn largest_step(t: &[i32]) -> i32 {
    t.windows(2).map(|w| (w[1] - w[0]).abs()).max().unwrap_or(0)
}

/// Every frame lost for 30 ms while both axes move at 20 units/s (their
/// SM watchdogs longer: the drives ride it out in Operation enabled, on
/// their last target): the drives are lost, their commands run 0.6 units
/// on. When the frames return neither is jumped there (0.6 units in one
/// cycle): each gets its actual position as its target and the backend's
/// fault, the bounded stop; after a reset each follows again from where it
/// stands.
#[test]
fn a_drive_back_after_a_loss_is_never_jumped_to_a_command_that_ran_away() {
    let setup = || two_moving(|_| {}, |c| c.keys.sm_watchdog_ms = 5_000);
    retried(2, setup, back_after_a_loss);
}

fn back_after_a_loss(r: &mut Rig) {
    r.emu().record_targets(0, true);
    r.emu().set_silent(true);
    r.until("axis 0 lost", Duration::from_secs(1), |r| {
        r.fb.axes[0].status_word & SW_DRIVE_LOST != 0
    });
    jog(r, 30);
    r.emu().set_silent(false);
    r.until("data again", Duration::from_secs(2), |r| {
        (0..2).all(|i| r.fb.axes[i].status_word & SW_NO_DATA == 0)
    });
    jog(r, 20);
    let t = r.emu().take_targets(0);
    let worst = largest_step(&t);
    eprintln!("largest step of drive 0's target: {worst} counts");
    assert!(worst <= JUMP, "a jump of {worst} counts");
    r.until("both stopped, faulted", Duration::from_secs(2), |r| {
        (0..2).all(|i| r.fb.axes[i].status_word & (SW_ENABLED | SW_FAULT) == SW_FAULT)
    });
    let st = r.backend.bus_status();
    eprintln!("{:?}", st.axes);
    assert!((0..2).all(|i| st.axes[i].gap_stops >= 1), "{:?}", st.axes);
    r.until("both drives off, at rest", Duration::from_secs(2), |r| {
        (0..2).all(|i| off(r, i) && r.drive(i).velocity == 0.0)
    });
    // a reset, enabled from where they stand: they follow again
    for i in 0..2 {
        r.axis(i).control_word = 0;
    }
    r.ticks(5);
    r.enable(0);
    r.enable(1);
    r.emu().record_targets(0, true);
    jog(r, 100);
    let t = r.emu().take_targets(0);
    assert!(largest_step(&t) <= JUMP, "{t:?}");
    let moved = t.last().unwrap() - t.first().unwrap();
    assert!(moved >= 70 * STEP as i32, "follows again: {moved} counts");
}
