//! Coordination hooks: a racked gantry homed as one machine axis.
//!
//! Each side is its own engine and plant; a tiny test-only coordinator keeps
//! `Request::hold` set and clears it for one cycle when both sides wait at
//! a barrier, with `move_duration_ns` = the longer side's minimal final move
//! (rounded up to a cycle).
//!
//! Machine (raw units), bidirectional switch then marker forward, V = 20,
//! R = 2, acceleration = deceleration = 500, cycle T = 1 ms:
//!
//! ```text
//!   side A: switch [0.0, 5.0], markers at 2.5 + 10k, home_offset 1.0
//!   side B: switch [0.3, 5.3], markers at 2.8 + 10k, home_offset 1.5  (racked 0.3)
//!   both start at -50, Home Position 0
//! ```
//!
//! Seek to the switch (A detects 0, B 0.3: B arrives 0.3 / 20 = 15 ms later),
//! stop, return at R until the switch clears, on to the first marker beyond
//! it: A -7.5, B -7.2 (the events, latched exactly); stop; move home to
//! event + offset: A -6.5, B -5.7. The return stops rest 0.004..0.008 past
//! the markers (R²/2D = 0.004 plus up to two cycles at R), so the final moves
//! are 1.004..1.008 (A) and 1.504..1.508 (B) long; at R = 2 with 4 ms ramps
//! they take at least d / 2 + 4 ms: 506..508 ms (A), 756..758 ms (B).

mod common;

use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::{Plant, PlantConfig};

const T: u64 = 1_000_000;

fn side(offset: f64) -> AxisConfig {
    AxisConfig {
        home_offset: offset,
        ..common::axis(
            HomeSequence::SwitchThenMarker,
            HomeDirection::BidirectionalForward,
        )
    }
}

fn plant(rack: f64) -> PlantConfig {
    PlantConfig {
        switch: Some((rack, 5.0 + rack)),
        marker_at: 2.5 + rack,
        ..common::machine()
    }
}

/// Every cycle's status and command of both sides.
struct Log {
    st: Vec<[Status; 2]>,
    cmd: Vec<[Command; 2]>,
    plants: [Plant; 2],
}

/// Runs both sides in lockstep under the test coordinator; `stop_at` sends
/// a stop with `stop_code` to both in that cycle.
fn gantry(stop_at: Option<(usize, Option<(u16, u16)>)>) -> Log {
    let mut axes = [Axis::new(side(1.0)), Axis::new(side(1.5))];
    let mut plants = [Plant::new(plant(0.0)), Plant::new(plant(0.3))];
    let mut fb = [plants[0].feedback(), plants[1].feedback()];
    let (mut hold, mut duration) = (true, 0);
    let mut log = Log {
        st: Vec::new(),
        cmd: Vec::new(),
        plants: plants.clone(),
    };
    for k in 0..20_000usize {
        let stop = stop_at.filter(|&(at, _)| at == k);
        let req = Request {
            home: true,
            hold,
            move_duration_ns: duration,
            stop: stop.is_some(),
            stop_code: stop.and_then(|(_, c)| c),
            ..Request::default()
        };
        let mut cmds = [Command::default(); 2];
        for i in 0..2 {
            cmds[i] = axes[i].step(k as u64 * T, Some(&fb[i]), &req);
            fb[i] = plants[i].step(&cmds[i], 1e-3);
        }
        let st = [*axes[0].status(), *axes[1].status()];
        log.st.push(st);
        log.cmd.push(cmds);
        // The coordinator, for the next cycle: release when both wait, with
        // the longer minimal final move rounded up to whole cycles.
        let all_wait = st.iter().all(|s| s.waiting);
        hold = !all_wait;
        duration = if all_wait {
            st.iter().map(|s| s.min_move_ns).max().unwrap().div_ceil(T) * T
        } else {
            0
        };
        if k > 10 && st.iter().all(|s| !s.ip && s.phase == Phase::Idle) {
            break;
        }
    }
    log.plants = plants;
    log
}

/// Cycles at which side `i` left a barrier, with the leg it then started.
fn releases(log: &Log, i: usize) -> Vec<(usize, u8)> {
    (1..log.st.len())
        .filter(|&k| log.st[k - 1][i].waiting && !log.st[k][i].waiting)
        .map(|k| (k, log.st[k - 1][i].leg))
        .collect()
}

#[test]
fn racked_gantry_sides_start_every_leg_together_and_latch_their_own_events() {
    let log = gantry(None);
    let [a, b] = *log.st.last().unwrap();
    assert!(a.pc && b.pc, "{a:?}\n{b:?}");

    // Each side's event is its own marker beyond its own switch edge.
    assert!((a.event_raw.unwrap() - -7.5).abs() < 1e-12);
    assert!((b.event_raw.unwrap() - -7.2).abs() < 1e-12);
    assert!(a.switch_edge_raw.unwrap().abs() <= 0.001 + 1e-9);
    assert!((b.switch_edge_raw.unwrap() - 0.3).abs() <= 0.001 + 1e-9);
    // The command in the detecting cycle is within two cycles of travel at
    // R of the latched marker (the plant follows the command in a cycle).
    for s in [a, b] {
        assert!(
            (s.event_command.unwrap() - s.event_raw.unwrap()).abs() <= 2.0 * 2.0 * 0.001 + 1e-9
        );
    }

    // Every leg that starts from rest starts in the same cycle on both
    // sides: the seek (leg 0), the return (2) and the move home (4).
    let (ra, rb) = (releases(&log, 0), releases(&log, 1));
    assert_eq!(ra, rb);
    let legs: Vec<u8> = ra.iter().map(|r| r.1).collect();
    assert_eq!(legs, [0, 2, 4]);
    // A reached its switch 15 ms before B and waited for it at the return.
    let waited = |i: usize, leg: u8| {
        log.st
            .iter()
            .filter(|s| s[i].waiting && s[i].leg == leg)
            .count()
    };
    assert!(waited(0, 2) >= 14, "{}", waited(0, 2));
    assert_eq!(waited(1, 2), 1, "B arrives last and is released next cycle");

    // Final moves: different lengths, same start, same end.
    let (start, _) = ra[2];
    let min = |i: usize| log.st[start - 1][i].min_move_ns;
    // Distance d with 4 ms ramps (0.004 each) at R = 2: d / 2 + 4 ms; the
    // rest lies 0.004..0.008 past the marker, so d is 1.004..1.008 (A) and
    // 1.504..1.508 (B): 506..508 ms and 756..758 ms (+1 for rounding up).
    assert!((506 * T..=508 * T + 1).contains(&min(0)), "{}", min(0));
    assert!((756 * T..=758 * T + 1).contains(&min(1)), "{}", min(1));
    let duration = min(1).div_ceil(T) * T;
    let done = |i: usize| log.st.iter().position(|s| s[i].pc).unwrap();
    assert_eq!(done(0), done(1));
    assert_eq!((done(0) - start) as u64 * T, duration);
    // Each side at event + its own offset, both at Home Position.
    assert!((log.plants[0].position() - -6.5).abs() < 1e-9);
    assert!((log.plants[1].position() - -5.7).abs() < 1e-9);
    let last = log.cmd.last().unwrap();
    assert!((last[0].position - -6.5).abs() < 1e-9 && (last[1].position - -5.7).abs() < 1e-9);
}

#[test]
fn search_travel_is_reported_against_the_search_limit() {
    let log = gantry(None);
    // During the seek, the command's distance from where the leg began (-50).
    let mut seen = 0;
    for (s, c) in log.st.iter().zip(&log.cmd) {
        if s[0].phase == Phase::Seek && !s[0].waiting {
            assert!((s[0].search_travel - (c[0].position - -50.0).abs()).abs() < 1e-9);
            seen += 1;
        }
    }
    assert!(seen > 2000, "the seek takes about 2.5 s: {seen}");
}

#[test]
fn a_coordinator_stop_reports_its_own_code() {
    // Gantry skew, sent by the coordinator as a stop code during the seek.
    let log = gantry(Some((1000, Some((ERR_GANTRY_SKEW, 0)))));
    for s in log.st.last().unwrap() {
        assert!(s.er && !s.homed && !s.ip, "{s:?}");
        assert_eq!((s.err, s.exerr), (ERR_GANTRY_SKEW, 0));
    }
    assert!(log.cmd.last().unwrap().iter().all(|c| c.velocity == 0.0));
    // Without a code, a stop is the instruction's own 12 / 1.
    let log = gantry(Some((1000, None)));
    let s = log.st.last().unwrap()[1];
    assert_eq!(
        (s.err, s.exerr),
        (ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST)
    );
}

#[test]
fn hold_never_holds_a_leg_that_begins_in_motion() {
    // Unidirectional marker under a one-axis coordinator: it waits once, at
    // rest before the seek; the continue after the marker starts at speed.
    let cfg = AxisConfig {
        home_direction: HomeDirection::UnidirectionalForward,
        home_sequence: HomeSequence::Marker,
        home_offset: 3.0,
        ..side(0.0)
    };
    let mut axis = Axis::new(cfg);
    let mut p = Plant::new(plant(0.0));
    let mut fb = p.feedback();
    let mut hold = true;
    let mut waits = Vec::new();
    for k in 0..10_000u64 {
        let req = Request {
            home: true,
            hold,
            ..Request::default()
        };
        let cmd = axis.step(k * T, Some(&fb), &req);
        fb = p.step(&cmd, 1e-3);
        let s = axis.status();
        if s.waiting {
            waits.push(s.leg);
        }
        hold = !s.waiting;
        if k > 10 && !s.ip {
            break;
        }
    }
    assert_eq!(waits, [0], "one barrier, before the seek");
    let s = axis.status();
    assert!(s.pc && s.event_raw == Some(-47.5), "{s:?}");
    assert!((p.position() - -44.5).abs() < 1e-9);
}

#[test]
fn held_forever_an_axis_never_moves() {
    let mut axis = Axis::new(side(0.0));
    let mut p = Plant::new(plant(0.0));
    let mut fb = p.feedback();
    let req = Request {
        home: true,
        hold: true,
        ..Request::default()
    };
    for k in 0..2000u64 {
        let cmd = axis.step(k * T, Some(&fb), &req);
        fb = p.step(&cmd, 1e-3);
        assert_eq!(cmd.position, -50.0);
    }
    let s = axis.status();
    assert!(
        s.ip && s.waiting && s.leg == 0 && s.phase == Phase::Seek,
        "{s:?}"
    );
    assert_eq!(s.min_move_ns, 0, "the seek is no move home");
}
