use super::load;
use crate::cli::CheckArgs;
use motion_config::MachineConfig;
use motion_homing::{AxisConfiguration, OpLimits, TravelMode};
use motion_report::{print_json, AxisOperationLimits, CheckReport};
use motion_rt::{check_environment, RtConfig};

pub fn check(a: &CheckArgs) -> i32 {
    let (m, source) = match load(&a.common, a.json) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let cycle_s = f64::from(m.supervisor.cycle_us) * 1e-6;
    let mut notes = Vec::new();
    for ax in &m.axes {
        for note in motion_homing::advisories(&ax.engine, cycle_s) {
            notes.push(format!("axis {}: {note}", ax.name));
        }
        for note in motion_homing::op_limits::advisories(&ax.engine) {
            notes.push(format!("axis {}: {note}", ax.name));
        }
    }
    let rt = RtConfig {
        cpu: Some(m.supervisor.cpu),
        priority: m.supervisor.priority,
        lock_memory: m.supervisor.lock_memory,
        ..RtConfig::default()
    };
    let environment = check_environment(&rt);
    if a.json {
        print_json(&CheckReport {
            source,
            cycle_us: m.supervisor.cycle_us,
            axes: m.axes.iter().map(|x| x.name.clone()).collect(),
            io: m.ios.iter().map(|x| x.name.clone()).collect(),
            notes,
            warnings: m.warnings.clone(),
            environment,
            errors: Vec::new(),
            operations: operation_limits(&m),
        });
        return 0;
    }
    println!(
        "config {source}: {} axes, {} I/O process(es) ({}), cycle {} µs, cpu {}, SCHED_FIFO {}, \
         service prefix '{}'",
        m.axes.len(),
        m.ios.len(),
        m.ios
            .iter()
            .map(|i| format!("{} {:?}", i.name, i.spawn).to_lowercase())
            .collect::<Vec<_>>()
            .join(", "),
        m.supervisor.cycle_us,
        m.supervisor.cpu,
        m.supervisor.priority,
        m.supervisor.service_prefix
    );
    for a in operation_limits(&m) {
        println!("{}", operations_line(&a));
    }
    for w in &m.warnings {
        println!("warning: {w}");
    }
    for n in &notes {
        println!("note: {n}");
    }
    println!("real-time environment:");
    for line in environment {
        println!("  {line}");
    }
    0
}

/// Every axis's bounds of the operations around homing, defaults resolved
/// as the engine resolves them.
fn operation_limits(m: &MachineConfig) -> Vec<AxisOperationLimits> {
    m.axes
        .iter()
        .map(|a| {
            let e = &a.engine;
            let l = OpLimits::new(e);
            AxisOperationLimits {
                axis: a.name.clone(),
                movable: e.configuration != AxisConfiguration::FeedbackOnly,
                soft_limits: e
                    .travel_limits
                    .filter(|_| e.travel == TravelMode::Linear)
                    .map(|(lo, hi)| [lo, hi]),
                max_speed: l.max_speed,
                unhomed_speed: l.unhomed_speed,
                max_deceleration: l.max_deceleration,
                limit_switches: e.limit_switches,
                stream_acceleration: l.stream_acceleration,
                stream_timeout_ms: l.stream_timeout_ns as f64 / 1e6,
                stream_unhomed: e.stream_unhomed,
            }
        })
        .collect()
}

/// `axis X: operations: soft limits [-100, 100] while homed, max_speed 40,
/// unhomed 20, max_deceleration 500, limit switches, stream: 5000 units/s²,
/// timeout 50 ms, homed only`.
fn operations_line(a: &AxisOperationLimits) -> String {
    if !a.movable {
        return format!("axis {}: operations: none (feedback-only axis)", a.axis);
    }
    let soft = match a.soft_limits {
        Some([lo, hi]) => format!("soft limits [{lo}, {hi}] while homed"),
        None => "no soft limits".to_string(),
    };
    let speed = match a.max_speed {
        Some(v) => format!("max_speed {v}"),
        None => "no max_speed (stream refused)".to_string(),
    };
    format!(
        "axis {}: operations: {soft}, {speed}, unhomed_speed {}, max_deceleration {}, {}, \
         stream: acceleration {} units/s², timeout {} ms, {}",
        a.axis,
        a.unhomed_speed,
        a.max_deceleration,
        if a.limit_switches {
            "limit switches"
        } else {
            "no limit switches"
        },
        a.stream_acceleration,
        a.stream_timeout_ms,
        if a.stream_unhomed {
            "also unhomed"
        } else {
            "homed only"
        },
    )
}
