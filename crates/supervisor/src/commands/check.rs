use super::load;
use crate::cli::Common;
use motion_rt::{check_environment, RtConfig};

pub fn check(common: &Common) -> i32 {
    let Some((m, source)) = load(common) else {
        return 2;
    };
    println!(
        "config {source}: {} axes, cycle {} µs, cpu {}, SCHED_FIFO {}, io {:?}, service prefix '{}'",
        m.axes.len(),
        m.supervisor.cycle_us,
        m.supervisor.cpu,
        m.supervisor.priority,
        m.supervisor.io,
        m.supervisor.service_prefix
    );
    let cycle_s = m.supervisor.cycle_us as f64 * 1e-6;
    for a in &m.axes {
        for note in motion_homing::advisories(&a.engine, cycle_s) {
            println!("axis {}: note: {note}", a.name);
        }
    }
    let rt = RtConfig {
        cpu: Some(m.supervisor.cpu),
        priority: m.supervisor.priority,
        lock_memory: m.supervisor.lock_memory,
        ..RtConfig::default()
    };
    println!("real-time environment:");
    for line in check_environment(&rt) {
        println!("  {line}");
    }
    0
}
