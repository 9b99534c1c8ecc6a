//! Engine + plant in a loop, one cycle at a time.
#![allow(dead_code)]

use motion_homing::*;
use motion_plant::{Plant, PlantConfig};

/// Result of one homing run.
pub struct Outcome {
    pub status: Status,
    pub final_raw: f64,
    pub final_axis: f64,
    /// Every command, in order (one per cycle).
    pub commands: Vec<Command>,
    /// Axis position the engine assigns to the event point.
    pub axis_at_event: Option<f64>,
    pub cycles: usize,
    pub axis: Axis,
}

/// Runs homing from the plant's power-up state until the instruction is done
/// and the axis is at rest, then lets the plant settle for a few cycles.
pub fn run(cfg: AxisConfig, plant: PlantConfig, cycle_s: f64, max_s: f64) -> Outcome {
    run_with(cfg, plant, cycle_s, max_s, |_, _, fb, _| Some(fb))
}

/// As [`run`], with a hook called before every engine step that may alter or
/// drop (None) the feedback frame, poke the plant, or change the request:
/// `hook(cycle, plant, feedback, request) -> feedback seen by the engine`.
pub fn run_with(
    cfg: AxisConfig,
    plant_cfg: PlantConfig,
    cycle_s: f64,
    max_s: f64,
    mut hook: impl FnMut(usize, &mut Plant, Feedback, &mut Request) -> Option<Feedback>,
) -> Outcome {
    let cycle_ns = (cycle_s * 1e9).round() as u64;
    let mut axis = Axis::new(cfg);
    let mut plant = Plant::new(plant_cfg);
    let mut fb = plant.feedback();
    let mut req = Request {
        home: true,
        ..Request::default()
    };
    let mut commands = Vec::new();
    let max = (max_s / cycle_s) as usize;
    let mut settle = None;
    let mut k = 0;
    loop {
        let now = k as u64 * cycle_ns;
        let seen = hook(k, &mut plant, fb, &mut req);
        let cmd = axis.step(now, seen.as_ref(), &req);
        commands.push(cmd);
        fb = plant.step(&cmd, cycle_s);
        let st = axis.status();
        let at_rest = cmd.velocity == 0.0;
        if settle.is_none() && !st.ip && st.phase == Phase::Idle && at_rest && k > 0 {
            settle = Some(k + 5);
        }
        if settle == Some(k) {
            break;
        }
        k += 1;
        assert!(
            k < max,
            "homing did not finish in {max_s} s: {:?}",
            axis.status()
        );
    }
    let status = *axis.status();
    let final_raw = plant.position();
    Outcome {
        status,
        final_raw,
        final_axis: axis.to_axis(final_raw),
        commands,
        axis_at_event: status.event_raw.map(|e| axis.to_axis(e)),
        cycles: k,
        axis,
    }
}
