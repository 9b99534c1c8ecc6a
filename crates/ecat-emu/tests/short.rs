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
    let _t = turn();
    // quick stop bound 300 ms: the cycles below are checked against it
    let Some(mut r) = two_moving(|_| {}, |c| c.keys.quick_stop_timeout_ms = 300) else {
        return;
    };
    let before = r.backend.bus_status();
    r.emu().refuse_op(1, Some(code));
    r.emu().drop_out_of_op(1, to);
    r.until_axis(1, "axis 1 lost", |a| a.status_word & SW_DRIVE_LOST != 0);
    assert_eq!(r.fb.axes[1].status_word & SW_ENABLED, 0);
    // axis 0 runs on with valid data: its working counter is not blamed
    let from = r.drive(0).position;
    jog(&mut r, 100);
    let st = r.backend.bus_status();
    assert!(st.wkc_errors > before.wkc_errors, "no short working counter");
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

    let cycles = stop_healthy(&mut r, how);
    // the bounded stop: quick stop ≤ 300 cycles (the drive's ramp from 20
    // u/s takes 20), then disable voltage; the bus thread's own watchdog
    // first waits 2 × 50 cycles without a command
    let bound = match how {
        Stop::Silence => 100 + 300 + 20,
        _ => 300 + 20,
    };
    assert!(cycles <= bound, "{how:?}: {cycles} bus cycles > {bound}");
    if how == Stop::Silence {
        assert_eq!(r.backend.bus_status().bus_watchdog_trips, 1);
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
    let _t = turn();
    let Some(mut r) = two_moving(|_| {}, |_| {}) else {
        return;
    };
    r.emu().refuse_op(1, Some(al::SYNC_ERROR));
    r.emu().drop_out_of_op(1, Dropped::SafeOp(al::SYNC_ERROR));
    r.until_axis(1, "axis 1 lost", |a| a.status_word & SW_DRIVE_LOST != 0);
    jog(&mut r, 100);
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
    jog(&mut r, 100);
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
    // the other axis ran on throughout
    assert_eq!(r.drive(0).state, State::OperationEnabled);
    assert_eq!(r.fb.axes[0].status_word & SW_NO_DATA, 0);
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
    let _t = turn();
    // the refusing drive's SM watchdog must not expire during the test (it
    // would leave OP and explain the shortfall)
    let Some(mut r) = two_moving(
        |d| d.ignores_quick_stop = true,
        |c| {
            c.keys.quick_stop_timeout_ms = 100;
            c.keys.sm_watchdog_ms = 5_000;
        },
    ) else {
        return;
    };
    r.emu().refuse_process_data(1, true);
    r.until("no data on axis 0", Duration::from_secs(1), |r| {
        r.fb.axes[0].status_word & SW_NO_DATA != 0
    });
    let c0 = r.backend.bus_status().cycles;
    let t0 = Instant::now();
    let mut fb = FeedbackFrame::ZERO;
    let mut quick_stop = false;
    while !off(&r, 0) {
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

/// SubDevice 1's process data uncounted for 30 cycles while axis 0 moves
/// at 20 counts per cycle: no axis' data is valid meanwhile, drive 0
/// holds its last target, its command runs 600 counts ahead. When the data
/// returns drive 0 is not jumped there (0.6 units in one cycle): it is held
/// where it stands until the command comes back near it.
#[test]
fn data_back_after_a_gap_is_resynchronised_never_jumped() {
    let _t = turn();
    let Some(mut r) = two_moving(|_| {}, |c| c.keys.sm_watchdog_ms = 5_000) else {
        return;
    };
    r.emu().record_targets(0, true);
    r.emu().refuse_process_data(1, true);
    r.until("no data on axis 0", Duration::from_secs(1), |r| {
        r.fb.axes[0].status_word & SW_NO_DATA != 0
    });
    jog(&mut r, 30);
    r.emu().refuse_process_data(1, false);
    let mut n = 0;
    while r.fb.axes[0].status_word & SW_NO_DATA != 0 {
        jog(&mut r, 1);
        n += 1;
        assert!(n < 1000, "no data again");
    }
    jog(&mut r, 50);
    let steps = |t: &[i32]| -> i32 { t.windows(2).map(|w| (w[1] - w[0]).abs()).max().unwrap() };
    let t = r.emu().take_targets(0);
    // a lost frame on a loaded host doubles a step now and then
    let worst = steps(&t);
    eprintln!("largest step of drive 0's target: {worst} counts");
    assert!(worst <= 3 * STEP as i32, "a jump of {worst} counts");
    let st = r.backend.bus_status();
    assert!(st.axes[0].resyncs >= 1, "{:?}", st.axes[0]);
    // held: its command ran away, the drive stands still, enabled
    let v = r.drive(0);
    assert_eq!(v.state, State::OperationEnabled, "{v:?}");
    assert_eq!(v.velocity, 0.0, "{v:?}");
    // the command from where the drive stands (as the engine plans after
    // a loss): followed again at once, steps of one cycle's travel
    let pos = r.fb.axes[0].position;
    r.axis(0).target_position = pos;
    r.axis(1).target_position = r.fb.axes[1].position;
    jog(&mut r, 100);
    let t = r.emu().take_targets(0);
    let worst = steps(&t);
    assert!(worst <= 3 * STEP as i32, "a jump of {worst} counts");
    eprintln!("{t:?}");
    let moved = t.last().unwrap() - t.first().unwrap();
    assert!(moved > 90 * STEP as i32, "follows again: {moved} counts");
}
