//! The limit-switch sequences (`limit_switch`, `limit_switch_then_marker`)
//! against hand-worked values, from every start position.
//!
//! The machine of every row unless the row says otherwise (raw units):
//!
//! ```text
//!   hard stop -100 | negative limit ≤ -90 | switch [0, 5] | positive limit ≥ 90 | hard stop +100
//!   markers every 10 at 2.5: ... -97.5, -87.5, ..., -7.5, 2.5, 12.5, ..., 82.5, 92.5 ...
//!   home speed V = 20, return speed R = 2, acceleration = deceleration = 500
//!   cycle T = 1 ms; the plant reaches its command in one cycle
//!   the seek stops V²/2D = 0.4 (plus up to two cycles, 0.04) past the limit's end:
//!   inside the 10 units of limit before the hard stop
//! ```
//!
//! The reference is the limit in Home Direction (forward: the positive limit
//! at 90, reverse: the negative one at -90); the home switch plays no part.
//! The event is where the limit clears on the return leg at R — a sampled
//! edge, placed at the midpoint of the samples around it: error ≤ R·T/2 =
//! 0.001 — or the first marker beyond it (latched: exact): forward 82.5,
//! reverse -87.5. Home Offset points into the travel (−1 forward, +1
//! reverse), so the axis rests 1 off the switch at Home Position.

mod common;

use common::{limit_machine_at as plant, run, run_with};
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::PlantConfig;

const T: f64 = 0.001;
const R: f64 = 2.0;
const EXACT: f64 = 1e-9;
/// A sampled edge at return speed: R·T/2.
const SAMPLED: f64 = R * T / 2.0 + 1e-9;

use HomeDirection::*;
use HomeSequence::*;

/// The test axis homing on its limit, offset 1 into the travel.
fn axis(seq: HomeSequence, dir: HomeDirection) -> AxisConfig {
    AxisConfig {
        home_offset: -dir.sign(),
        ..common::axis(seq, dir)
    }
}

/// What a row expects.
#[derive(Clone, Copy, Debug)]
enum Want {
    /// Homed with PC: the event within `tol`, at rest `offset` beyond it.
    Homed { event: f64, tol: f64 },
    /// Ends with ER and these codes, not homed.
    Fails { err: u16, exerr: u16 },
}

struct Row {
    name: String,
    cfg: AxisConfig,
    plant: PlantConfig,
    want: Want,
}

fn row(name: impl Into<String>, cfg: AxisConfig, plant: PlantConfig, want: Want) -> Row {
    Row {
        name: name.into(),
        cfg,
        plant,
        want,
    }
}

/// Runs one row; `Err` says what differs.
fn verify(r: &Row) -> Result<(), String> {
    verify_outcome(r, run(r.cfg, r.plant, T, 300.0))
}

fn verify_outcome(r: &Row, o: common::Outcome) -> Result<(), String> {
    let s = o.status;
    eprintln!(
        "{:<78} er {:<5} {:>4}/{:<2} event {:>14} rest {:>10.4}",
        r.name,
        s.er,
        s.err,
        s.exerr,
        format!("{:?}", s.event_raw.map(|x| (x * 1e4).round() / 1e4)),
        o.final_raw
    );
    let mut bad = Vec::new();
    match r.want {
        Want::Homed { event, tol } => {
            let homed_with_pc = s.pc && s.homed && !s.er && !s.ip;
            if !homed_with_pc {
                bad.push(format!("not homed with PC: {s:?}"));
            }
            match s.event_raw {
                Some(e) if (e - event).abs() <= tol => {
                    // At rest at event + offset, which reads Home Position.
                    let rest = e + r.cfg.home_offset;
                    if (o.final_raw - rest).abs() > 1e-9 {
                        bad.push(format!("rest {} want {rest}", o.final_raw));
                    }
                    if (o.final_axis - r.cfg.home_position).abs() > 1e-9 {
                        bad.push(format!("reads {} at rest", o.final_axis));
                    }
                }
                got => bad.push(format!("event {got:?} want {event} ± {tol}")),
            }
            let (neg, pos) = r.plant.overtravel.unwrap_or((f64::MIN, f64::MAX));
            if !(neg < o.final_raw && o.final_raw < pos) {
                bad.push(format!("rests on a limit switch at {}", o.final_raw));
            }
        }
        Want::Fails { err, exerr } => {
            if !s.er || s.homed || s.pc || (s.err, s.exerr) != (err, exerr) {
                bad.push(format!("want ER {err}/{exerr}, got {s:?}"));
            }
        }
    }
    if bad.is_empty() {
        Ok(())
    } else {
        Err(format!("{}: {}", r.name, bad.join("; ")))
    }
}

fn verify_all(rows: &[Row]) {
    let failures: Vec<String> = rows.iter().filter_map(|r| verify(r).err()).collect();
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// The reference of each sequence and direction on the test machine.
fn reference(seq: HomeSequence, dir: HomeDirection) -> Want {
    match (seq, dir) {
        // The limit's end, sampled on the way back at R.
        (LimitSwitch, BidirectionalForward) => Want::Homed {
            event: 90.0,
            tol: SAMPLED,
        },
        (LimitSwitch, _) => Want::Homed {
            event: -90.0,
            tol: SAMPLED,
        },
        // The first marker beyond the clear point, into the travel: below
        // 90 the marker 82.5, above -90 the marker -87.5.
        (_, BidirectionalForward) => Want::Homed {
            event: 82.5,
            tol: EXACT,
        },
        _ => Want::Homed {
            event: -87.5,
            tol: EXACT,
        },
    }
}

/// Every start: below the home switch (-50), on it (2), above it (50), on
/// the limit the axis homes on (±95: the return leg starts at once), on
/// the other limit (∓95: the seek leaves it). The event is the same from
/// each.
#[test]
fn every_start_position_finds_the_same_event() {
    let mut rows = Vec::new();
    for seq in [LimitSwitch, LimitSwitchThenMarker] {
        for dir in [BidirectionalForward, BidirectionalReverse] {
            let s = dir.sign();
            for (start, where_) in [
                (-50.0, "below the home switch"),
                (2.0, "on the home switch"),
                (50.0, "above the home switch"),
                (95.0 * s, "on the limit it homes on"),
                (-95.0 * s, "on the other limit"),
            ] {
                rows.push(row(
                    format!("{seq} {dir} from {start} ({where_})"),
                    axis(seq, dir),
                    plant(start),
                    reference(seq, dir),
                ));
            }
        }
    }
    assert_eq!(rows.len(), 20);
    verify_all(&rows);
}

#[test]
fn wiring_registration_offsets_and_creep() {
    let with = |seq, dir, start: f64, f: &dyn Fn(&mut AxisConfig, &mut PlantConfig)| {
        let (mut c, mut p) = (axis(seq, dir), plant(start));
        f(&mut c, &mut p);
        (c, p)
    };
    let mut rows = Vec::new();
    // NC limit switches: the drive reports states, the events are the same.
    for dir in [BidirectionalForward, BidirectionalReverse] {
        for seq in [LimitSwitch, LimitSwitchThenMarker] {
            let (c, p) = with(seq, dir, 0.0, &|_, p| {
                p.limit_switches_normally_closed = true
            });
            rows.push(row(
                format!("{seq} {dir}, NC limits"),
                c,
                p,
                reference(seq, dir),
            ));
        }
    }
    // Registration: the probe input is wired to the limit: the clear point
    // is latched, exactly -90 / 90 (NC or not).
    for (dir, edge) in [(BidirectionalReverse, -90.0), (BidirectionalForward, 90.0)] {
        let (c, p) = with(LimitSwitch, dir, 0.0, &|c, p| {
            c.registration = true;
            p.limit_switches_normally_closed = true;
            p.registration_input = if edge > 0.0 {
                motion_plant::RegistrationInput::PositiveLimit
            } else {
                motion_plant::RegistrationInput::NegativeLimit
            };
        });
        rows.push(row(
            format!("limit_switch {dir}, NC, registration: exactly {edge}"),
            c,
            p,
            Want::Homed {
                event: edge,
                tol: EXACT,
            },
        ));
    }
    // Home Position 10, offset +3: rests at -90 + 3 = -87 reading 10; the
    // clear point reads 10 - 3 = 7.
    let (c, p) = with(LimitSwitch, BidirectionalReverse, 30.0, &|c, _| {
        c.home_position = 10.0;
        c.home_offset = 3.0;
    });
    rows.push(row(
        "limit_switch reverse, HP 10, offset +3: rest -87",
        c,
        p,
        Want::Homed {
            event: -90.0,
            tol: SAMPLED,
        },
    ));
    // No marker latch: the return leg finds 82.5 at R, stops past it and
    // creeps back over it at 0.5: error ≤ 0.5·T/2.
    let (c, p) = with(LimitSwitchThenMarker, BidirectionalForward, 0.0, &|c, _| {
        c.marker_latch = false;
        c.home_creep_speed = 0.5;
    });
    rows.push(row(
        "limit_switch_then_marker forward, no latch, creep 0.5: 82.5 ± 0.00025",
        c,
        p,
        Want::Homed {
            event: 82.5,
            tol: 0.5 * T / 2.0 + 1e-9,
        },
    ));
    verify_all(&rows);
}

/// A limit is a fault in every leg but the seek and the stop on the limit
/// the sequence homes on (`axis::at_limit`).
#[test]
fn a_limit_in_any_other_leg_is_still_an_overtravel() {
    let overtravel = Want::Fails {
        err: ERR_SERVO_MESSAGE,
        exerr: EX_OVERTRAVEL,
    };
    let rows = [
        // The other limit on the return leg: limits at ±5, markers every 50
        // at 30 (…, -20, 30, …): after clearing 5 going negative the first
        // marker is -20, beyond the negative limit at -5.
        row(
            "limit_switch_then_marker forward: the negative limit before the marker",
            axis(LimitSwitchThenMarker, BidirectionalForward),
            PlantConfig {
                overtravel: Some((-5.0, 5.0)),
                marker_every: 50.0,
                marker_at: 30.0,
                hard_stop: Some((-30.0, 30.0)),
                ..plant(0.0)
            },
            overtravel,
        ),
        // A home switch sequence whose Home Position (0 + 92) lies on the
        // positive limit: the move home trips it.
        row(
            "switch forward, offset +92: the move home meets the positive limit",
            AxisConfig {
                home_offset: 92.0,
                ..common::axis(Switch, BidirectionalForward)
            },
            plant(-50.0),
            overtravel,
        ),
        // Without home_reverse_at_limit a limit ends a search that misses
        // its switch; a unidirectional one cannot reverse at all.
        row(
            "switch forward from 50, no reversal: the seek meets the positive limit",
            common::axis(Switch, BidirectionalForward),
            plant(50.0),
            overtravel,
        ),
        row(
            "unidirectional switch forward from 50: the seek meets the positive limit",
            common::axis(Switch, UnidirectionalForward),
            plant(50.0),
            overtravel,
        ),
    ];
    verify_all(&rows);
}

/// A broken common wire: NC switches both read actuated, the drive faults
/// (ERR 12 / EXERR 16). NO switches read released: the limit is silently
/// gone, the seek runs into the hard stop and the search limit (1.1 × 200
/// = 220) ends it (1016 / 2).
#[test]
fn a_broken_limit_wire() {
    for (nc, want) in [
        (
            true,
            Want::Fails {
                err: ERR_SERVO_MESSAGE,
                exerr: EX_DRIVE_FAULT,
            },
        ),
        (
            false,
            Want::Fails {
                err: ERR_SEARCH_LIMIT,
                exerr: EX_SEARCH_SEEK,
            },
        ),
    ] {
        let r = row(
            format!("limit_switch reverse, wire cut at 0.5 s, NC {nc}"),
            axis(LimitSwitch, BidirectionalReverse),
            PlantConfig {
                limit_switches_normally_closed: nc,
                ..plant(0.0)
            },
            want,
        );
        let o = run_with(r.cfg, r.plant, T, 300.0, |k, p, fb, _| {
            if k == 500 {
                p.break_limit_wire();
            }
            Some(fb)
        });
        verify_outcome(&r, o).unwrap();
    }
}

#[test]
fn refused_configurations() {
    let refused = |exerr| Want::Fails {
        err: ERR_ILLEGAL_HOMING_CONFIG,
        exerr,
    };
    let cfg = |f: &dyn Fn(&mut AxisConfig)| {
        let mut c = axis(LimitSwitch, BidirectionalReverse);
        c.cycle_ns = 1_000_000;
        f(&mut c);
        c
    };
    let rows = [
        row(
            "unidirectional",
            cfg(&|c| c.home_direction = UnidirectionalReverse),
            plant(0.0),
            refused(EX_LIMIT_UNIDIRECTIONAL),
        ),
        row(
            "offset 0: rests on the limit's end",
            cfg(&|c| c.home_offset = 0.0),
            plant(0.0),
            refused(EX_LIMIT_OFFSET),
        ),
        row(
            "offset -1: into the negative limit",
            cfg(&|c| c.home_offset = -1.0),
            plant(0.0),
            refused(EX_LIMIT_OFFSET),
        ),
        row(
            "offset +0.002: not more than R·T = 0.002 off",
            cfg(&|c| c.home_offset = 0.002),
            plant(0.0),
            refused(EX_LIMIT_OFFSET),
        ),
        row(
            "passive",
            cfg(&|c| {
                c.home_mode = HomeMode::Passive;
                c.configuration = AxisConfiguration::FeedbackOnly;
            }),
            plant(0.0),
            refused(EX_SEQUENCE_INCOMPATIBLE),
        ),
        row(
            "no limit switches",
            cfg(&|c| c.limit_switches = false),
            plant(0.0),
            refused(EX_NO_LIMIT_SWITCHES),
        ),
        row(
            "cyclic axis",
            cfg(&|c| {
                c.travel = TravelMode::Cyclic;
                c.unwind = 360.0;
                c.travel_limits = None;
            }),
            plant(0.0),
            refused(EX_NO_LIMIT_SWITCHES),
        ),
        row(
            "then marker without a marker",
            cfg(&|c| {
                c.home_sequence = LimitSwitchThenMarker;
                c.marker = false;
            }),
            plant(0.0),
            refused(EX_NO_MARKER),
        ),
    ];
    verify_all(&rows);
    // Just beyond the margin is accepted.
    assert!(validate(&cfg(&|c| c.home_offset = 0.0021)).is_empty());
}

/// `limit_switch_then_marker` with no offset — CiA 402 methods 1 and 2 as
/// they are commonly used: accepted, and the axis rests on the marker it
/// found once the switch had cleared, off the switch, from every start;
/// also with the marker 0.1 from the switch's edge (markers at ±89.9). An
/// offset towards the limit is still refused, and so is a plain
/// `limit_switch` home with no offset (`refused_configurations`): that one
/// would rest on the switch's edge.
#[test]
fn then_marker_with_no_offset_rests_on_the_marker_off_the_switch() {
    let mut rows = Vec::new();
    for dir in [BidirectionalForward, BidirectionalReverse] {
        let s = dir.sign();
        let cfg = AxisConfig {
            home_offset: 0.0,
            ..axis(LimitSwitchThenMarker, dir)
        };
        assert!(validate(&cfg).is_empty(), "{:?}", validate(&cfg));
        for start in [-50.0, 2.0, 50.0, 95.0 * s] {
            rows.push(row(
                format!("then marker {dir} offset 0 from {start}"),
                cfg,
                plant(start),
                reference(LimitSwitchThenMarker, dir),
            ));
            let close = 89.9 * s;
            rows.push(row(
                format!("then marker {dir} offset 0 from {start}, marker 0.1 off the edge"),
                cfg,
                PlantConfig {
                    marker_at: close,
                    ..plant(start)
                },
                Want::Homed {
                    event: close,
                    tol: EXACT,
                },
            ));
        }
        let toward = AxisConfig {
            home_offset: 0.001 * s,
            ..cfg
        };
        rows.push(row(
            format!("then marker {dir} offset 0.001 towards the limit"),
            toward,
            plant(0.0),
            Want::Fails {
                err: ERR_ILLEGAL_HOMING_CONFIG,
                exerr: EX_LIMIT_OFFSET,
            },
        ));
    }
    verify_all(&rows);
}

#[test]
fn the_checker_can_fail() {
    let mut r = row(
        "wrong event",
        axis(LimitSwitch, BidirectionalForward),
        plant(0.0),
        Want::Homed {
            event: 89.99,
            tol: SAMPLED,
        },
    );
    assert!(verify(&r).is_err());
    r.want = Want::Fails {
        err: ERR_SERVO_MESSAGE,
        exerr: EX_OVERTRAVEL,
    };
    assert!(verify(&r).is_err());
}
