//! Temporary machine configs: the demo machine's axes with another
//! `[supervisor]` section (period, CPU, priority, service prefix).

use motion_config::{MachineConfig, DEMO_TOML};

/// What goes into `[supervisor]`.
#[derive(Clone, Debug)]
pub struct Supervisor {
    pub cycle_us: u32,
    pub cpu: usize,
    pub priority: i32,
    pub service_prefix: String,
}

/// The demo machine (`deploy/demo.toml`) with `s` as its `[supervisor]`
/// section, checked by `motion_config::parse`.
pub fn demo_with(s: &Supervisor) -> Result<(String, MachineConfig), String> {
    let start = DEMO_TOML
        .find("[supervisor]")
        .ok_or("deploy/demo.toml has no [supervisor] section")?;
    let end = DEMO_TOML[start..]
        .find("[[axis]]")
        .map(|i| start + i)
        .ok_or("deploy/demo.toml has no [[axis]]")?;
    let section = format!(
        "[supervisor]\n\
         cycle_us = {}\n\
         cpu = {}\n\
         priority = {}\n\
         io = \"sim\"\n\
         service_prefix = \"{}\"\n\
         feedback_timeout_ms = 10\n\
         io_watchdog_cycles = 50\n\
         cpu_dma_latency_us = 0\n\n",
        s.cycle_us, s.cpu, s.priority, s.service_prefix
    );
    let text = format!(
        "# Written by motion-bench: deploy/demo.toml's axes, [supervisor] changed.\n{}{}{}",
        &DEMO_TOML[..start],
        section,
        &DEMO_TOML[end..]
    );
    match motion_config::parse(&text) {
        Ok(m) => Ok((text, m)),
        Err(problems) => Err(problems
            .iter()
            .map(|p| p.to_string())
            .collect::<Vec<_>>()
            .join("; ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn changes_only_the_supervisor() {
        let (_, m) = demo_with(&Supervisor {
            cycle_us: 125,
            cpu: 0,
            priority: 70,
            service_prefix: "mb_test".into(),
        })
        .unwrap();
        let demo = motion_config::parse(DEMO_TOML).unwrap();
        // The axes are the demo's; only what is stated per cycle differs:
        // the ambiguous-marker distance is two cycles of return travel,
        // and the engine is told the cycle it runs at.
        let same = |a: &[motion_config::AxisEntry]| {
            let mut a = a.to_vec();
            for x in &mut a {
                x.engine.marker_min_distance = 0.0;
                x.engine.cycle_ns = 0;
            }
            a
        };
        assert_eq!(same(&m.axes), same(&demo.axes));
        assert_eq!(
            m.axes[1].engine.feedback_timeout_ns, 10_000_000,
            "the same time at 8 kHz"
        );
        assert_eq!(m.supervisor.cycle_us, 125);
        assert_eq!(m.supervisor.cpu, 0);
        assert_eq!(m.supervisor.priority, 70);
        assert_eq!(m.supervisor.io_priority, 60);
        assert_eq!(m.supervisor.service_prefix, "mb_test");
        assert!(demo_with(&Supervisor {
            cycle_us: 5,
            cpu: 0,
            priority: 70,
            service_prefix: "x".into(),
        })
        .is_err());
    }
}
