//! Every sequence × direction × mode against hand-worked values.
//!
//! The machine of every row unless the row says otherwise (raw units):
//!
//! ```text
//!   hard stop -100 ......... switch [0, 5] ......... hard stop +100
//!   markers every 10 at 2.5: ... -97.5 ... -7.5, 2.5, 12.5 ... 92.5 ...
//!   home speed V = 20, return speed R = 2, acceleration = deceleration = 500
//!   cycle T = 1 ms; the plant reaches its command in one cycle
//!   stopping distance from V: V²/2D = 400/1000 = 0.4
//! ```
//!
//! Precision (spec §6): a switch sampled once per cycle is placed at the
//! midpoint of the samples around its edge, so its error is at most
//! speed × T / 2 (V: 0.01, R: 0.001, passive at 5 u/s: 0.0025). Markers and
//! registration are latched by the drive: exact.
//!
//! Detection lag on unidirectional stops: the sample that shows the event
//! lies at most one cycle of travel past it (0.02 at V) and the command is one
//! cycle ahead of the sample (0.02), so the axis comes to rest between
//! event + 0.4 and event + 0.44 (the extra 0.02 of the command lead is always
//! there, the other 0.02 depends on where in the cycle the edge falls).

mod common;

use common::run;
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::{PlantConfig, TorqueSpike};

const V: f64 = 20.0;
const R: f64 = 2.0;
const T: f64 = 0.001;
const EXACT: f64 = 1e-9;
const SW_V: f64 = V * T / 2.0 + 1e-9; // switch uncertainty at home speed
const SW_R: f64 = R * T / 2.0 + 1e-9; // ... at return speed
const SW_P: f64 = 5.0 * T / 2.0 + 1e-9; // ... passive at 5 u/s

use HomeDirection::*;
use HomeSequence::*;

/// The common test axis (it homes at V and R), with the torque settings.
fn axis(seq: HomeSequence, dir: HomeDirection) -> AxisConfig {
    AxisConfig {
        home_torque_level: 30.0,
        home_torque_threshold: 20.0,
        home_torque_time: 0.01,
        position_error_tolerance: 1.0,
        ..common::axis(seq, dir)
    }
}

fn plant(start: f64) -> PlantConfig {
    common::machine_at(start)
}

/// Where a forward (reverse) search starts.
fn start_for(dir: HomeDirection) -> f64 {
    if dir.sign() > 0.0 {
        -50.0
    } else {
        50.0
    }
}

#[derive(Clone, Copy, Debug)]
enum Final {
    /// Raw position within tolerance.
    Raw(f64, f64),
    /// Raw position in [lo, hi].
    Between(f64, f64),
    /// Not checked (passive axes keep moving).
    Any,
}

#[derive(Clone, Copy, Debug)]
struct Expect {
    pc: bool,
    homed: bool,
    err: u16,
    exerr: u16,
    /// Event raw position and tolerance.
    event: Option<(f64, f64)>,
    final_raw: Final,
    /// Axis position at the end, if the sequence ends at Home Position.
    at_home: bool,
}

const fn ok(event: f64, tol: f64, final_raw: Final) -> Expect {
    Expect {
        pc: true,
        homed: true,
        err: 0,
        exerr: 0,
        event: Some((event, tol)),
        final_raw,
        at_home: true,
    }
}

/// Unidirectional stop short of Home Position: homed, IP cleared without PC.
const fn short(event: f64, tol: f64, final_raw: Final) -> Expect {
    Expect {
        pc: false,
        at_home: false,
        ..ok(event, tol, final_raw)
    }
}

const fn refused(exerr: u16) -> Expect {
    Expect {
        pc: false,
        homed: false,
        err: ERR_ILLEGAL_HOMING_CONFIG,
        exerr,
        event: None,
        final_raw: Final::Any,
        at_home: false,
    }
}

struct Case {
    name: String,
    cfg: AxisConfig,
    plant: PlantConfig,
    expect: Expect,
}

fn case(name: &str, cfg: AxisConfig, plant: PlantConfig, expect: Expect) -> Case {
    Case {
        name: name.into(),
        cfg,
        plant,
        expect,
    }
}

/// The rows for one active sequence in one direction with offset 0 and HP 0.
fn active_row(seq: HomeSequence, dir: HomeDirection) -> Case {
    let name = format!("active {seq:?} {dir:?}");
    let cfg = axis(seq, dir);
    let p = plant(start_for(dir));
    let fwd = dir.sign() > 0.0;
    let e = match (seq, dir) {
        (Immediate, _) => {
            // No motion: the start position becomes Home Position 0.
            let s = start_for(dir);
            return case(
                &name,
                cfg,
                p,
                Expect {
                    event: None,
                    ..ok(0.0, 0.0, Final::Raw(s, EXACT))
                },
            );
        }
        // Bidirectional switch: seek hits the near edge (0 going forward, 5
        // going reverse), the return leg at R clears the same edge.
        (Switch, BidirectionalForward) => ok(0.0, SW_R, Final::Raw(0.0, SW_R)),
        (Switch, BidirectionalReverse) => ok(5.0, SW_R, Final::Raw(5.0, SW_R)),
        // Bidirectional marker: the first marker ahead of the start.
        // -50 forward: -47.5; +50 reverse: 42.5. Return to it at R.
        (Marker, BidirectionalForward) => ok(-47.5, EXACT, Final::Raw(-47.5, EXACT)),
        (Marker, BidirectionalReverse) => ok(42.5, EXACT, Final::Raw(42.5, EXACT)),
        // Switch then marker: clear the near edge on the way back, then the
        // first marker beyond it: forward: clear 0 going reverse → -7.5;
        // reverse: clear 5 going forward → 12.5.
        (SwitchThenMarker, BidirectionalForward) => ok(-7.5, EXACT, Final::Raw(-7.5, EXACT)),
        (SwitchThenMarker, BidirectionalReverse) => ok(12.5, EXACT, Final::Raw(12.5, EXACT)),
        // Torque: the hard stop clamps at ±100 while torque builds, so the
        // event is the stop itself; offset 0 → stay there.
        (Torque, BidirectionalForward) => ok(100.0, EXACT, Final::Raw(100.0, EXACT)),
        (Torque, BidirectionalReverse) => ok(-100.0, EXACT, Final::Raw(-100.0, EXACT)),
        // Torque then marker: away from the stop to the first marker:
        // 100 → 92.5; -100 → -97.5.
        (TorqueThenMarker, BidirectionalForward) => ok(92.5, EXACT, Final::Raw(92.5, EXACT)),
        (TorqueThenMarker, BidirectionalReverse) => ok(-97.5, EXACT, Final::Raw(-97.5, EXACT)),
        // Torque sequences are bidirectional only.
        (Torque | TorqueThenMarker, _) => refused(EX_UNIDIRECTIONAL_TORQUE),
        // Unidirectional, offset 0: the event is where the search finds it,
        // then the axis decelerates past it (0.40..0.44, module docs). PC.
        (Switch, _) => {
            let ev = if fwd { 0.0 } else { 5.0 };
            let s = dir.sign();
            ok(ev, SW_V, past(ev, s, SW_V))
        }
        (Marker, _) => {
            let ev = if fwd { -47.5 } else { 42.5 };
            ok(ev, EXACT, past(ev, dir.sign(), 0.0))
        }
        // The first marker after the switch is detected: forward detects 0,
        // reverse detects 5; the marker at 2.5 lies beyond both.
        (SwitchThenMarker, _) => ok(2.5, EXACT, past(2.5, dir.sign(), 0.0)),
        (LimitSwitch | LimitSwitchThenMarker, _) => unreachable!("see limit_sequences.rs"),
    };
    let unidirectional_at_rest_past_event =
        dir.is_unidirectional() && !matches!(seq, Torque | TorqueThenMarker);
    let expect = Expect {
        at_home: e.at_home && !unidirectional_at_rest_past_event,
        ..e
    };
    case(&name, cfg, p, expect)
}

/// Rest position of a unidirectional stop after an event at `ev` (± `tol`)
/// going in direction `s`: `ev + s * [0.40, 0.44]`.
fn past(ev: f64, s: f64, tol: f64) -> Final {
    let a = ev + s * (0.40 - tol);
    let b = ev + s * (0.44 + tol);
    Final::Between(a.min(b) - 1e-9, a.max(b) + 1e-9)
}

fn passive_row(seq: HomeSequence, speed: f64) -> Case {
    let name = format!("passive {seq:?} external {speed:+}");
    let cfg = AxisConfig {
        configuration: AxisConfiguration::FeedbackOnly,
        home_mode: HomeMode::Passive,
        ..axis(seq, BidirectionalForward)
    };
    let start = if speed > 0.0 { -3.0 } else { 8.0 };
    let p = PlantConfig {
        start,
        external_speed: speed,
        ..plant(start)
    };
    let expect = match (seq, speed > 0.0) {
        // Immediate: the current position is Home Position at once.
        (Immediate, _) => Expect {
            event: None,
            final_raw: Final::Any,
            at_home: false,
            ..ok(0.0, 0.0, Final::Any)
        },
        // Switch detected: 0 coming from below, 5 coming from above.
        (Switch, true) => ok(0.0, SW_P, Final::Any),
        (Switch, false) => ok(5.0, SW_P, Final::Any),
        // Marker: the first one passed: 2.5 both ways from -3 / 8.
        (Marker, _) => ok(2.5, EXACT, Final::Any),
        // Switch then marker: detect 0 (or 5), then 2.5.
        (SwitchThenMarker, _) => ok(2.5, EXACT, Final::Any),
        _ => unreachable!(),
    };
    case(
        &name,
        cfg,
        p,
        Expect {
            at_home: false,
            ..expect
        },
    )
}

/// Rows beyond the plain grid: offsets, wiring, starting on the switch,
/// registration, cyclic axes, configuration errors.
fn variant_rows() -> Vec<Case> {
    let mut rows = Vec::new();
    let with = |seq, dir, f: &dyn Fn(&mut AxisConfig, &mut PlantConfig)| {
        let mut c = axis(seq, dir);
        let mut p = plant(start_for(dir));
        f(&mut c, &mut p);
        (c, p)
    };

    // Offsets on bidirectional sequences: final raw = event + offset, axis = HP.
    let (c, p) = with(Marker, BidirectionalForward, &|c, _| {
        c.home_offset = 3.0;
        c.home_position = 10.0;
    });
    rows.push(case(
        "bidir marker offset +3, HP 10: rest at -47.5 + 3 = -44.5",
        c,
        p,
        ok(-47.5, EXACT, Final::Raw(-44.5, EXACT)),
    ));
    let (c, p) = with(SwitchThenMarker, BidirectionalReverse, &|c, _| {
        c.home_offset = -2.0;
    });
    rows.push(case(
        "bidir STM reverse offset -2: 12.5 - 2 = 10.5",
        c,
        p,
        ok(12.5, EXACT, Final::Raw(10.5, EXACT)),
    ));
    let (c, p) = with(Switch, BidirectionalForward, &|c, _| c.home_offset = 1.5);
    rows.push(case(
        "bidir switch offset +1.5: 0 + 1.5",
        c,
        p,
        ok(0.0, SW_R, Final::Raw(1.5, SW_R)),
    ));

    // Normally-closed switch: same events as normally open.
    let (c, p) = with(Switch, BidirectionalForward, &|c, p| {
        c.home_switch_normally_closed = true;
        p.switch_normally_closed = true;
    });
    rows.push(case(
        "bidir switch NC",
        c,
        p,
        ok(0.0, SW_R, Final::Raw(0.0, SW_R)),
    ));
    let (c, p) = with(SwitchThenMarker, UnidirectionalReverse, &|c, p| {
        c.home_switch_normally_closed = true;
        p.switch_normally_closed = true;
    });
    rows.push(case(
        "unidir STM reverse NC",
        c,
        p,
        Expect {
            at_home: false,
            ..ok(2.5, EXACT, past(2.5, -1.0, 0.0))
        },
    ));

    // Registration: the drive latches the switch edge: exact.
    let (c, p) = with(Switch, BidirectionalForward, &|c, _| c.registration = true);
    rows.push(case(
        "bidir switch with registration: exact 0",
        c,
        p,
        ok(0.0, EXACT, Final::Raw(0.0, EXACT)),
    ));
    let (c, p) = with(Switch, UnidirectionalReverse, &|c, p| {
        c.registration = true;
        c.home_switch_normally_closed = true;
        p.switch_normally_closed = true;
    });
    rows.push(case(
        "unidir switch reverse NC with registration: exact 5",
        c,
        p,
        Expect {
            at_home: false,
            ..ok(5.0, EXACT, past(5.0, -1.0, 0.0))
        },
    ));

    // Drives without a marker latch: the index pulse is only known to one
    // cycle of travel (midpoint, error <= speed x T / 2); the creep leg of
    // the seek / back-off / creep scheme stops past it and creeps back over
    // it at the creep speed, shrinking the error to creep x T / 2.
    const CREEP: f64 = 0.5;
    let sw_c = CREEP * T / 2.0 + 1e-9;
    let (c, p) = with(Marker, BidirectionalForward, &|c, _| c.marker_latch = false);
    rows.push(case(
        "bidir marker, no latch, no creep: -47.5 +- 20 x 0.001 / 2",
        c,
        p,
        ok(-47.5, SW_V, Final::Raw(-47.5, SW_V)),
    ));
    let (c, p) = with(Marker, BidirectionalForward, &|c, _| {
        c.marker_latch = false;
        c.home_creep_speed = CREEP;
    });
    rows.push(case(
        "bidir marker, no latch, creep 0.5: -47.5 +- 0.5 x 0.001 / 2",
        c,
        p,
        ok(-47.5, sw_c, Final::Raw(-47.5, sw_c)),
    ));
    let (c, p) = with(SwitchThenMarker, BidirectionalReverse, &|c, _| {
        c.marker_latch = false;
        c.home_creep_speed = CREEP;
        c.home_offset = 1.0;
    });
    rows.push(case(
        "bidir STM reverse, no latch, creep: marker 12.5 +- creep error, rest at +1",
        c,
        p,
        ok(12.5, sw_c, Final::Raw(13.5, sw_c)),
    ));
    let (c, p) = with(TorqueThenMarker, BidirectionalForward, &|c, _| {
        c.marker_latch = false;
        c.home_creep_speed = CREEP;
    });
    rows.push(case(
        "torque then marker, no latch, creep: 92.5 +- creep error",
        c,
        p,
        ok(92.5, sw_c, Final::Raw(92.5, sw_c)),
    ));
    let (c, p) = with(Marker, UnidirectionalForward, &|c, _| {
        c.marker_latch = false;
        c.home_creep_speed = CREEP; // creeping back would reverse: not used
        c.home_offset = 3.0;
    });
    rows.push(case(
        "unidir marker, no latch: no creep (it would reverse), -47.5 +- 0.01, on to +3",
        c,
        p,
        ok(-47.5, SW_V, Final::Raw(-44.5, SW_V)),
    ));

    // Switch active at start.
    let (c, p) = with(Switch, BidirectionalForward, &|_, p| p.start = 2.0);
    rows.push(case(
        "bidir switch, on the switch at start: return leg clears 0",
        c,
        p,
        ok(0.0, SW_R, Final::Raw(0.0, SW_R)),
    ));
    let (c, p) = with(SwitchThenMarker, BidirectionalReverse, &|_, p| {
        p.start = 2.0
    });
    rows.push(case(
        "bidir STM reverse, on the switch at start: clear 5 forward, marker 12.5",
        c,
        p,
        ok(12.5, EXACT, Final::Raw(12.5, EXACT)),
    ));
    let (c, p) = with(SwitchThenMarker, UnidirectionalForward, &|_, p| {
        p.start = 2.0
    });
    rows.push(case(
        "unidir STM, on the switch at start, offset 0: event here (2), done, no motion",
        c,
        p,
        ok(2.0, EXACT, Final::Raw(2.0, EXACT)),
    ));
    let (c, p) = with(SwitchThenMarker, UnidirectionalForward, &|c, p| {
        p.start = 2.0;
        c.home_offset = 3.0;
    });
    rows.push(case(
        "unidir STM, on the switch at start, offset +3: move forward to 5",
        c,
        p,
        ok(2.0, EXACT, Final::Raw(5.0, EXACT)),
    ));
    let (c, p) = with(SwitchThenMarker, UnidirectionalForward, &|c, p| {
        p.start = 2.0;
        c.home_offset = -1.0;
    });
    rows.push(case(
        "unidir STM, on the switch at start, offset -1 (behind): no move, no PC",
        c,
        p,
        short(2.0, EXACT, Final::Raw(2.0, EXACT)),
    ));

    // Unidirectional offsets: longer than the stopping distance → keep going
    // to event + offset at home speed; shorter or behind → stop, no PC.
    let (c, p) = with(Marker, UnidirectionalForward, &|c, _| c.home_offset = 3.0);
    rows.push(case(
        "unidir marker offset +3 > 0.44: continue to -47.5 + 3 = -44.5",
        c,
        p,
        ok(-47.5, EXACT, Final::Raw(-44.5, EXACT)),
    ));
    let (c, p) = with(Switch, UnidirectionalReverse, &|c, _| c.home_offset = -3.0);
    rows.push(case(
        "unidir switch reverse offset -3: continue to 5 - 3 = 2 (± switch error)",
        c,
        p,
        ok(5.0, SW_V, Final::Raw(2.0, SW_V)),
    ));
    let (c, p) = with(Marker, UnidirectionalForward, &|c, _| c.home_offset = 0.2);
    rows.push(case(
        "unidir marker offset 0.2 < stopping distance: stop, IP clears without PC",
        c,
        p,
        short(-47.5, EXACT, past(-47.5, 1.0, 0.0)),
    ));
    let (c, p) = with(Marker, UnidirectionalReverse, &|c, _| c.home_offset = 1.0);
    rows.push(case(
        "unidir marker reverse offset +1 (against travel): stop, no PC",
        c,
        p,
        short(42.5, EXACT, past(42.5, -1.0, 0.0)),
    ));

    // Torque offsets.
    let (c, p) = with(Torque, BidirectionalForward, &|c, _| c.home_offset = -5.0);
    rows.push(case(
        "torque offset -5 (away from the stop): move to 95",
        c,
        p,
        ok(100.0, EXACT, Final::Raw(95.0, EXACT)),
    ));
    let (c, p) = with(Torque, BidirectionalForward, &|c, _| c.home_offset = 5.0);
    rows.push(case(
        "torque offset +5 (into the stop): stay at the stop, homed, no PC",
        c,
        p,
        short(100.0, EXACT, Final::Raw(100.0, EXACT)),
    ));
    let (c, p) = with(TorqueThenMarker, BidirectionalReverse, &|c, _| {
        c.home_offset = -4.0;
    });
    rows.push(case(
        "torque then marker reverse offset -4: -97.5 - 4 lies beyond -100: stay where the \
         return leg stopped (R²/2D = 0.004 plus up to 2 cycles of 0.002 past -97.5), no PC",
        c,
        p,
        short(-97.5, EXACT, Final::Between(-97.494 - 1e-9, -97.492 + 1e-9)),
    ));
    let (c, p) = with(Torque, BidirectionalReverse, &|_, p| {
        // A 25 % spike over 0.1 units of travel = 5 ms at 20 u/s: shorter
        // than the 10 ms torque time, so it must not count as the stop.
        p.torque_spike = Some(TorqueSpike {
            at: -20.0,
            width: 0.1,
            level: 25.0,
        });
    });
    rows.push(case(
        "torque reverse with a 5 ms nuisance spike: filtered, event at -100",
        c,
        p,
        ok(-100.0, EXACT, Final::Raw(-100.0, EXACT)),
    ));

    // Cyclic axis, unwind 360, one marker per revolution at 2.5 (…, 362.5 …).
    let cyc = |seq, dir, start: f64, hp: f64, off: f64| {
        let mut c = axis(seq, dir);
        c.travel = TravelMode::Cyclic;
        c.unwind = 360.0;
        c.travel_limits = None;
        c.home_position = hp;
        c.home_offset = off;
        let p = PlantConfig {
            start,
            marker_every: 360.0,
            marker_at: 2.5,
            ..PlantConfig::default()
        };
        (c, p)
    };
    let (c, p) = cyc(Marker, BidirectionalForward, 100.0, 10.0, 0.0);
    rows.push(case(
        "cyclic bidir marker from 100: 362.5, back 0.4 to it",
        c,
        p,
        ok(362.5, EXACT, Final::Raw(362.5, EXACT)),
    ));
    let (c, p) = cyc(Marker, BidirectionalForward, 100.0, 10.0, 200.0);
    rows.push(case(
        "cyclic bidir marker offset 200: 562.5 is 200 ahead, 202.5 is 160 back: shortest way",
        c,
        p,
        ok(362.5, EXACT, Final::Raw(202.5, EXACT)),
    ));
    let (c, p) = cyc(Marker, UnidirectionalForward, 100.0, 10.0, 0.0);
    rows.push(case(
        "cyclic unidir marker offset 0: one more revolution to 722.5",
        c,
        p,
        ok(362.5, EXACT, Final::Raw(722.5, EXACT)),
    ));
    let (c, p) = cyc(Marker, UnidirectionalForward, 100.0, 10.0, 0.2);
    rows.push(case(
        "cyclic unidir marker offset 0.2 < stopping distance: 362.7 + 360 = 722.7",
        c,
        p,
        ok(362.5, EXACT, Final::Raw(722.7, EXACT)),
    ));
    let (c, p) = cyc(Marker, UnidirectionalReverse, 100.0, 0.0, -1.0);
    rows.push(case(
        "cyclic unidir reverse marker offset -1: 2.5 - 1 = 1.5, ahead by more than 0.44",
        c,
        p,
        ok(2.5, EXACT, Final::Raw(1.5, EXACT)),
    ));

    // Configuration errors, reported by the instruction at start.
    let (c, p) = with(Switch, BidirectionalForward, &|c, _| c.home_speed = 0.0);
    rows.push(case("home speed zero", c, p, refused(EX_HOME_SPEED_ZERO)));
    let (c, p) = with(Switch, BidirectionalForward, &|c, _| {
        c.home_return_speed = 0.0
    });
    rows.push(case(
        "return speed zero",
        c,
        p,
        refused(EX_RETURN_SPEED_ZERO),
    ));
    let (c, p) = with(Marker, BidirectionalForward, &|c, _| c.marker = false);
    rows.push(case(
        "marker sequence, no marker",
        c,
        p,
        refused(EX_NO_MARKER),
    ));
    let (c, p) = with(Switch, BidirectionalForward, &|c, _| {
        c.configuration = AxisConfiguration::FeedbackOnly;
    });
    rows.push(case(
        "active on feedback-only",
        c,
        p,
        refused(EX_ACTIVE_ON_FEEDBACK_ONLY),
    ));
    let (c, p) = with(Torque, BidirectionalForward, &|c, _| {
        c.home_mode = HomeMode::Passive;
    });
    rows.push(case(
        "passive torque",
        c,
        p,
        refused(EX_SEQUENCE_INCOMPATIBLE),
    ));
    let (c, p) = with(Switch, BidirectionalForward, &|c, _| {
        c.control_mode = ControlMode::Torque;
    });
    rows.push(case(
        "torque control mode",
        c,
        p,
        refused(EX_TORQUE_CONTROL_MODE),
    ));
    rows
}

fn check(c: &Case) -> Result<(), String> {
    let o = run(c.cfg, c.plant, T, 300.0);
    let s = o.status;
    let e = c.expect;
    eprintln!(
        "{:<70} pc {:<5} er {:<5} err {:>2}/{:<2} event {:>12} final raw {:>10.4} axis {:>9.4} cycles {}",
        c.name,
        s.pc,
        s.er,
        s.err,
        s.exerr,
        format!("{:?}", s.event_raw.map(|x| (x * 1e4).round() / 1e4)),
        o.final_raw,
        o.final_axis,
        o.cycles
    );
    let mut problems = Vec::new();
    let refused = e.err == ERR_ILLEGAL_HOMING_CONFIG;
    let (pc, er) = (e.pc, e.err != 0);
    if s.pc != pc || s.er != er || s.ip || s.dn == refused || s.homed != e.homed {
        problems.push(format!(
            "bits pc {} er {} ip {} dn {} homed {} (want pc {pc} er {er} dn {} homed {})",
            s.pc, s.er, s.ip, s.dn, s.homed, !refused, e.homed
        ));
    }
    if (s.err, s.exerr) != (e.err, e.exerr) {
        problems.push(format!(
            "ERR {} EXERR {} want {} {}",
            s.err, s.exerr, e.err, e.exerr
        ));
    }
    match (e.event, s.event_raw) {
        (Some((want, tol)), Some(got)) if (got - want).abs() <= tol => {}
        (None, None) => {}
        (want, got) => problems.push(format!("event {got:?} want {want:?}")),
    }
    match e.final_raw {
        Final::Raw(want, tol) if (o.final_raw - want).abs() > tol => {
            problems.push(format!("final raw {} want {want} ± {tol}", o.final_raw))
        }
        Final::Between(lo, hi) if !(lo..=hi).contains(&o.final_raw) => {
            problems.push(format!("final raw {} want in [{lo}, {hi}]", o.final_raw))
        }
        _ => {}
    }
    // The event point reads Home Position − Home Offset (spec §3).
    if let Some(a) = o.axis_at_event {
        let want = c.cfg.home_position - c.cfg.home_offset;
        let d = if c.cfg.travel == TravelMode::Cyclic {
            let x = (a - want).rem_euclid(c.cfg.unwind);
            x.min(c.cfg.unwind - x)
        } else {
            (a - want).abs()
        };
        if d > 1e-9 {
            problems.push(format!("event reads {a}, want HP - offset = {want}"));
        }
    }
    if e.at_home && (o.final_axis - c.cfg.home_position).abs() > 1e-9 {
        problems.push(format!(
            "final axis position {} want Home Position {}",
            o.final_axis, c.cfg.home_position
        ));
    }
    // A healthy machine's feedback is never refused as implausible.
    if s.implausible != Implausible::default() {
        problems.push(format!(
            "feedback refused as implausible: {:?}",
            s.implausible
        ));
    }
    // Overridden drive values are always restored at the end.
    let last = o.commands.last().unwrap();
    if last.torque_limit_positive != c.cfg.torque_limit
        || last.position_error_tolerance != c.cfg.position_error_tolerance
    {
        problems.push(format!("overrides not restored: {last:?}"));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!("{}: {}", c.name, problems.join("; ")))
    }
}

fn grid() -> Vec<Case> {
    let mut rows = Vec::new();
    for seq in [
        Immediate,
        Switch,
        Marker,
        SwitchThenMarker,
        Torque,
        TorqueThenMarker,
    ] {
        for dir in [
            UnidirectionalForward,
            BidirectionalForward,
            UnidirectionalReverse,
            BidirectionalReverse,
        ] {
            rows.push(active_row(seq, dir));
        }
    }
    for seq in [Immediate, Switch, Marker, SwitchThenMarker] {
        for speed in [5.0, -5.0] {
            rows.push(passive_row(seq, speed));
        }
    }
    rows
}

#[test]
fn every_sequence_direction_and_mode() {
    let rows = grid();
    assert_eq!(
        rows.len(),
        32,
        "6 active sequences x 4 directions + 4 passive x 2"
    );
    let failures: Vec<String> = rows.iter().filter_map(|c| check(c).err()).collect();
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn variants_offsets_wiring_cyclic_and_errors() {
    let rows = variant_rows();
    let failures: Vec<String> = rows.iter().filter_map(|c| check(c).err()).collect();
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn table_can_fail() {
    // A wrong expectation must be reported: the checker is not vacuous.
    let mut c = active_row(Marker, BidirectionalForward);
    c.expect.event = Some((-37.5, EXACT));
    assert!(check(&c).is_err());
    let mut c = active_row(Switch, UnidirectionalForward);
    c.expect.pc = false;
    assert!(check(&c).is_err());
}
