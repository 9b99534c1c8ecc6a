use super::load;
use crate::cli::CheckArgs;
use motion_report::{print_json, CheckReport};
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
