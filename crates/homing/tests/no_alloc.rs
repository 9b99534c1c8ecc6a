//! The engine step never touches the heap: counted with a wrapping global
//! allocator over complete homing runs of every sequence, over the
//! coordination, feedback-trouble and stored-reference paths, and over the
//! operations around homing (power, jog, move, stream, limits, faults).

mod common;

use motion_homing::*;
use motion_plant::{Plant, PlantConfig};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static CALLS: Cell<u64> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        CALLS.with(|c| c.set(c.get() + 1));
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        CALLS.with(|c| c.set(c.get() + 1));
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        CALLS.with(|c| c.set(c.get() + 1));
        System.realloc(p, l, n)
    }
}

#[global_allocator]
static A: Counting = Counting;

fn calls() -> u64 {
    CALLS.with(|c| c.get())
}

#[test]
fn engine_step_makes_no_allocation() {
    let mut steps = 0u64;
    let mut during = 0u64;
    for seq in [
        HomeSequence::Switch,
        HomeSequence::Marker,
        HomeSequence::SwitchThenMarker,
        HomeSequence::Torque,
        HomeSequence::TorqueThenMarker,
    ] {
        let cfg = AxisConfig {
            marker: true,
            home_sequence: seq,
            home_speed: 20.0,
            home_return_speed: 5.0,
            home_acceleration: 500.0,
            home_deceleration: 500.0,
            home_torque_level: 30.0,
            home_torque_threshold: 20.0,
            home_torque_time: 0.005,
            ..AxisConfig::default()
        };
        let mut axis = Axis::new(cfg);
        let mut plant = Plant::new(PlantConfig {
            start: -20.0,
            switch: Some((0.0, 5.0)),
            marker_every: 10.0,
            marker_at: 2.5,
            hard_stop: Some((-30.0, 30.0)),
            ..PlantConfig::default()
        });
        let mut fb = plant.feedback();
        let req = Request {
            home: true,
            ..Request::default()
        };
        for k in 0..20_000u64 {
            let before = calls();
            let cmd = axis.step(k * 1_000_000, Some(&fb), &req);
            during += calls() - before;
            steps += 1;
            fb = plant.step(&cmd, 0.001);
        }
        assert!(axis.status().pc, "{seq:?}: {:?}", axis.status());
    }
    assert!(steps == 100_000);
    assert_eq!(during, 0, "allocator calls inside Axis::step");
}

/// The limit-switch sequences, and a switch search that reverses at a
/// limit (a far-side start), step without the heap too: the reversal
/// swaps one static plan for another.
#[test]
fn limit_switch_homing_and_reversal_make_no_allocation() {
    let runs = [
        (HomeSequence::LimitSwitch, false, 0.0),
        (HomeSequence::LimitSwitchThenMarker, false, 0.0),
        (HomeSequence::SwitchThenMarker, true, -20.0),
    ];
    for (seq, reverse, start) in runs {
        let cfg = AxisConfig {
            marker: true,
            home_sequence: seq,
            home_direction: HomeDirection::BidirectionalReverse,
            home_reverse_at_limit: reverse,
            home_offset: 1.0,
            home_speed: 20.0,
            home_return_speed: 5.0,
            home_acceleration: 500.0,
            home_deceleration: 500.0,
            ..AxisConfig::default()
        };
        let mut axis = Axis::new(cfg);
        let mut plant = Plant::new(PlantConfig {
            start,
            switch: Some((0.0, 5.0)),
            marker_every: 10.0,
            marker_at: 2.5,
            hard_stop: Some((-30.0, 30.0)),
            overtravel: Some((-25.0, 25.0)),
            ..PlantConfig::default()
        });
        let mut fb = plant.feedback();
        let req = Request {
            home: true,
            ..Request::default()
        };
        let mut during = 0;
        for k in 0..20_000u64 {
            during += counted(|| {
                let cmd = axis.step(k * 1_000_000, Some(&fb), &req);
                fb = plant.step(&cmd, 0.001);
            });
        }
        let st = axis.status();
        assert!(st.pc && st.reversed_at_limit == reverse, "{seq:?}: {st:?}");
        assert_eq!(during, 0, "{seq:?}: allocator calls inside Axis::step");
    }
}

/// Counts allocator calls inside `f`.
fn counted(f: impl FnOnce()) -> u64 {
    let before = calls();
    f();
    calls() - before
}

#[test]
fn coordination_feedback_trouble_and_references_make_no_allocation() {
    const T: u64 = 1_000_000;
    let stm = AxisConfig {
        counts_per_unit: 1000.0,
        marker: true,
        home_sequence: HomeSequence::SwitchThenMarker,
        home_speed: 20.0,
        home_return_speed: 2.0,
        home_acceleration: 500.0,
        home_deceleration: 500.0,
        marker_min_distance: 0.5,
        ..AxisConfig::default()
    };
    let plant = |rack: f64, marker_at: f64| {
        Plant::new(PlantConfig {
            start: -20.0,
            switch: Some((rack, 5.0 + rack)),
            marker_every: 10.0,
            marker_at: marker_at + rack,
            ..PlantConfig::default()
        })
    };
    let mut during = 0;

    // Two gantry sides under a hold / move-duration coordinator, with lost
    // frames, one implausible jump and one forged marker latch; then a third
    // axis whose marker is refused as ambiguous, and a coordinator stop.
    let mut axes = [
        Axis::new(stm),
        Axis::new(AxisConfig {
            home_offset: 0.5,
            ..stm
        }),
        Axis::new(AxisConfig {
            refuse_ambiguous_marker: true,
            ..stm
        }),
    ];
    let mut plants = [plant(0.0, 2.5), plant(0.3, 2.5), plant(0.0, -0.1)];
    let mut fb = [
        plants[0].feedback(),
        plants[1].feedback(),
        plants[2].feedback(),
    ];
    let (mut hold, mut duration) = (true, 0);
    let mut forged = [false; 3];
    for k in 0..20_000u64 {
        let req = Request {
            home: k >= 1000,
            hold,
            move_duration_ns: duration,
            stop: k == 19_000,
            stop_code: Some((codes::ERR_GANTRY_SKEW, 0)),
            ..Request::default()
        };
        for i in 0..3 {
            let mut seen = Some(fb[i]);
            if k % 7 == 3 {
                seen = None;
            }
            if k == 500 {
                seen = Some(Feedback {
                    position: 40.0,
                    ..fb[i]
                });
            }
            let armed = axes[i].last_command().marker_arm.id;
            if armed != 0 && !forged[i] {
                if let Some(f) = seen.as_mut() {
                    forged[i] = true;
                    f.marker_latch = LatchFeedback {
                        id: armed,
                        latched: true,
                        position: 77.0,
                    };
                }
            }
            let mut cmd = Command::default();
            during += counted(|| {
                cmd = axes[i].step(k * T, seen.as_ref(), &req);
            });
            fb[i] = plants[i].step(&cmd, 0.001);
        }
        let all_wait = axes[..2].iter().all(|a| a.status().waiting);
        hold = !all_wait;
        duration = if all_wait {
            axes[..2]
                .iter()
                .map(|a| a.status().min_move_ns)
                .max()
                .unwrap()
        } else {
            0
        };
    }
    assert!(
        axes[0].status().pc && axes[1].status().pc,
        "{:?}",
        axes[0].status()
    );
    assert_eq!(axes[2].status().err, codes::ERR_AMBIGUOUS_MARKER);
    for a in &axes {
        let n = a.status().implausible;
        assert_eq!((n.jumps, n.marker_latches), (1, 1), "{n:?}");
    }

    // Absolute homing, the stored reference, a restart and its restore
    // (accepted and refused).
    let abs = AxisConfig {
        absolute: true,
        home_mode: HomeMode::Absolute,
        home_position: 10.0,
        travel_limits: Some((-50.0, 150.0)),
        ..AxisConfig::default()
    };
    let fb = Feedback {
        position: 123.4,
        ..Feedback::default()
    };
    let home = Request {
        home: true,
        ..Request::default()
    };
    let mut a = Axis::new(abs);
    let mut b = Axis::new(abs);
    let mut results = [Ok(()); 3];
    during += counted(|| {
        a.step(0, Some(&fb), &home);
        let offset = a.reference_offset().unwrap();
        b.step(0, Some(&fb), &Request::default());
        results = [
            b.restore_reference(0, offset, 0.0),
            b.restore_reference(0, offset, 0.0),
            b.restore_reference(0, 500.0, 0.0),
        ];
    });
    assert!(results[0].is_ok() && results[1].is_ok() && results[2].is_err());
    assert_eq!(during, 0, "allocator calls inside the engine");
}

/// The operations around homing: enable, home, jog (an S-curve, renewed, to the soft
/// limit, by lease), moves (superseded, refused), the stream at the cycle
/// rate and at 100 Hz with a refused setpoint, a limit switch hit, a drive
/// fault, reset, disable, an S-curve move changed (MCD), and refusals of
/// every kind.
#[test]
fn operations_make_no_allocation() {
    const T: u64 = common::MS;
    let cfg = AxisConfig {
        max_deceleration: 2000.0,
        marker: true,
        marker_latch: true,
        registration: true,
        ..common::op_axis()
    };
    let mut axis = Axis::new(cfg);
    let mut plant = Plant::new(PlantConfig {
        overtravel: Some((-12.0, 12.0)),
        switch: Some((0.5, 1.0)),
        marker_every: 2.0,
        marker_at: 0.25,
        ..PlantConfig::default()
    });
    let mut fb = plant.feedback();
    // S-curves (jerk) for the first jog and move, trapezoids after.
    let jog = |speed: f64| {
        Operation::Jog(JogSpec {
            speed,
            accel: Some(500.0),
            decel: Some(500.0),
            lease: Some(time::ns_to_s(300 * T)),
            jerk: (speed > 10.0).then_some(20_000.0),
        })
    };
    let mv = |target: f64, supersede: bool| {
        Operation::Move(MoveSpec {
            supersede,
            jerk: (!supersede).then_some(5_000.0),
            ..common::move_spec(target)
        })
    };
    // MCD on the S-curve move, then on nothing (refused).
    let change = Operation::Change(ChangeSpec {
        speed: Some(10.0),
        jerk: Some(3_000.0),
        ..ChangeSpec::none()
    });
    // (step, request) of the script; every other step is empty.
    let sp = |t_ms: u64, p: f64| Request {
        setpoint: Some(Setpoint {
            t_ns: t_ms * T,
            position: p,
            velocity: None,
        }),
        ..Request::default()
    };
    let op = |o: Operation| Request {
        op: Some(o),
        ..Request::default()
    };
    let script = |k: u64| -> Request {
        match k {
            1 => op(Operation::Enable),
            10 => Request {
                home: true,
                ..Request::default()
            },
            15 => op(Operation::Arm(ArmSpec::on(
                LatchInput::Switch,
                LatchEdge::Rising,
            ))),
            20 => op(jog(20.0)),
            // Refused while jogging (3 / 25).
            30 => op(Operation::Redefine(RedefineSpec::by(1.0))),
            21..=700 if k % 50 == 0 => Request {
                jog_renew: true,
                ..Request::default()
            },
            790 => op(Operation::Arm(ArmSpec {
                window: Some((-6.0, 0.0)),
                ..ArmSpec::on(LatchInput::Marker, LatchEdge::Falling)
            })),
            800 => op(mv(-5.0, false)),
            810 | 1450 => op(change),
            850 => op(jog(5.0)),
            860 => op(mv(2.0, true)),
            // At rest on 2.0: redefined by 1 (reads 3), then back to 2.
            1400 => op(Operation::Redefine(RedefineSpec::by(1.0))),
            1420 => op(Operation::Redefine(RedefineSpec::to(2.0))),
            1500 => op(Operation::StreamStart),
            1510 => op(Operation::Arm(ArmSpec::on(
                LatchInput::Switch,
                LatchEdge::Falling,
            ))),
            1520 => op(Operation::Disarm),
            // From where the move left it (2.0) at 1 u/s: every cycle,
            // then every tenth (100 Hz).
            1501..=2000 => sp(k - 1501, 2.0 + 0.001 * (k - 1501) as f64),
            2001..=2500 if k % 10 == 0 => sp(k - 1501, 2.0 + 0.001 * (k - 1501) as f64),
            2520 => sp(1020, f64::NAN),
            2700 => op(Operation::Reset),
            2710 => op(move_outside()),
            2720 => Request {
                home: false,
                ..Request::default()
            },
            2730 => op(Operation::Disable),
            2740 => op(Operation::Enable),
            2800 => {
                let mut r = op(Operation::StreamStart);
                r.stop = true;
                r
            }
            2810 => op(Operation::StreamEnd),
            2900 => Request {
                shutdown: true,
                ..Request::default()
            },
            2950 => op(Operation::Enable),
            3000 => op(Operation::Stop),
            _ => Request::default(),
        }
    };
    let mut during = 0;
    let mut changed = false;
    // Jogging, moving, streaming, a refused setpoint, a drive fault, two
    // redefines, a registration latched: seen.
    let mut seen = [false; 7];
    for k in 0..3200u64 {
        let req = script(k);
        let mut cmd = Command::default();
        during += counted(|| {
            cmd = axis.step(k * T, Some(&fb), &req);
        });
        fb = plant.step(&cmd, 0.001);
        if k == 3050 {
            plant.inject_fault();
        }
        let s = axis.status();
        changed |= k == 810 && s.moving && s.op.refused.is_none();
        for (i, b) in [
            s.jogging,
            s.moving,
            s.streaming,
            s.err == codes::ERR_SETPOINT_REFUSED,
            s.exerr == codes::EX_DRIVE_FAULT,
            s.redefines == 2,
            s.registration_position.is_some(),
        ]
        .into_iter()
        .enumerate()
        {
            seen[i] |= b;
        }
    }
    assert!(changed, "the change was accepted");
    assert_eq!(seen, [true; 7]);
    // The unhomed part: a jog into the limit switch and a reset.
    let mut axis = Axis::new(AxisConfig {
        max_deceleration: 2000.0,
        ..cfg
    });
    let mut plant = Plant::new(PlantConfig {
        overtravel: Some((-12.0, 12.0)),
        ..PlantConfig::default()
    });
    let mut fb = plant.feedback();
    let mut hit = false;
    for k in 0..2000u64 {
        let req = match k {
            1 => op(Operation::Enable),
            10 => op(Operation::Jog(JogSpec {
                speed: 20.0,
                accel: Some(500.0),
                decel: Some(500.0),
                lease: Some(time::ns_to_s(5_000 * T)),
                jerk: None,
            })),
            1500 => op(Operation::Reset),
            1510 => op(jog(-5.0)),
            _ => Request::default(),
        };
        let mut cmd = Command::default();
        during += counted(|| {
            cmd = axis.step(k * T, Some(&fb), &req);
        });
        fb = plant.step(&cmd, 0.001);
        hit |= axis.status().last_stop == StopCause::LimitSwitch;
    }
    assert!(hit);
    assert_eq!(axis.status().last_stop, StopCause::LeaseExpired);
    assert_eq!(during, 0, "allocator calls inside Axis::step");
}

#[test]
fn gearing_makes_no_allocation() {
    // A master jogged back and forth, a slave geared to it with a clutch,
    // then at ratio 4 into its travel limit (1025 / 1), then geared on the
    // master's actual position while the master's drive faults (1025 / 3).
    const T: u64 = common::MS;
    let cfg = common::op_axis();
    let (mut m, mut s) = (Axis::new(cfg), Axis::new(cfg));
    let (mut mp, mut sp) = (
        Plant::new(PlantConfig::default()),
        Plant::new(PlantConfig::default()),
    );
    let (mut mfb, mut sfb) = (mp.feedback(), sp.feedback());
    let op = |o: Operation| Request {
        op: Some(o),
        ..Request::default()
    };
    let jog = |speed: f64| {
        op(Operation::Jog(JogSpec {
            speed,
            accel: Some(500.0),
            decel: Some(500.0),
            lease: Some(5.0),
            jerk: None,
        }))
    };
    let gear = |ratio: f64, actual: bool, clutch: Option<f64>| {
        op(Operation::Gear(GearSpec {
            actual,
            clutch,
            ..GearSpec::to(0, ratio)
        }))
    };
    let home = Request {
        home: true,
        ..Request::default()
    };
    let (mut during, mut seen) = (0, [false; 3]);
    for k in 0..4000u64 {
        let (mreq, sreq) = match k {
            1 => (op(Operation::Enable), op(Operation::Enable)),
            10 => (home, home),
            20 => (jog(2.0), gear(-1.5, false, Some(50.0))),
            500 => (jog(-2.0), Request::default()),
            1000 => (op(Operation::Stop), Request::default()),
            1100 => (Request::default(), gear(4.0, false, None)),
            1110 => (jog(5.0), Request::default()),
            // The cycle stops the master of a faulted slave.
            1700 => (op(Operation::Stop), Request::default()),
            2500 => (op(Operation::Reset), op(Operation::Reset)),
            2510 => (Request::default(), gear(1.0, true, None)),
            2520 => (jog(-3.0), Request::default()),
            _ => (Request::default(), Request::default()),
        };
        let stopped = matches!(mreq.op, Some(Operation::Stop));
        let (mut mc, mut sc) = (Command::default(), Command::default());
        during += counted(|| {
            mc = m.step(k * T, Some(&mfb), &mreq);
            let feed = MasterFeed {
                commanded: mc.position,
                actual: m.raw_position(),
                accel: m.acceleration_bound(),
                stopped,
                faulted: m.status().faulted,
            };
            let sreq = Request {
                master: Some(feed),
                ..sreq
            };
            sc = s.step(k * T, Some(&sfb), &sreq);
        });
        (mfb, sfb) = (mp.step(&mc, 0.001), sp.step(&sc, 0.001));
        if k == 2700 {
            mp.inject_fault();
        }
        let st = s.status();
        seen[0] |= st.gearing;
        seen[1] |= st.exerr == codes::EX_GEAR_SOFT_LIMIT;
        seen[2] |= st.exerr == codes::EX_GEAR_MASTER_FAULTED;
    }
    assert_eq!(seen, [true; 3]);
    assert_eq!(during, 0, "allocator calls inside Axis::step");
}

/// A move the travel limits refuse.
fn move_outside() -> Operation {
    common::move_to(50.0)
}

#[test]
fn the_counter_counts() {
    let before = calls();
    let v = std::hint::black_box(vec![1u8; 64]);
    drop(v);
    assert_eq!(calls() - before, 2);
}
