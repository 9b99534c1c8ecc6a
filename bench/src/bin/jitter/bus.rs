//! motion-io's bus round trip in a jitter run with `--ethercat`: read from
//! the summary motion-io logs at exit (the supervisor spawned it: its
//! stderr is the supervisor's), one row over the slices.

/// motion-io's bus round trip of one run, from the summary it logs at exit
/// (`… bus round trip (frame out → inputs back): N cycles: min a / p50 b /
/// p99 c / p99.9 d / max e us`), and its lost frames.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BusRun {
    pub cycles: u64,
    pub min: f64,
    pub p50: f64,
    pub p99: f64,
    pub p999: f64,
    pub max: f64,
    pub lost: u64,
}

impl BusRun {
    /// Two runs as one row: cycles and lost frames summed, min and max over
    /// both, the percentiles the higher of the two (motion-io reports
    /// percentiles per run, not its histogram).
    pub fn merge(&self, o: &BusRun) -> BusRun {
        BusRun {
            cycles: self.cycles + o.cycles,
            min: self.min.min(o.min),
            p50: self.p50.max(o.p50),
            p99: self.p99.max(o.p99),
            p999: self.p999.max(o.p999),
            max: self.max.max(o.max),
            lost: self.lost + o.lost,
        }
    }
}

/// Finds the bus summary in `stderr`.
pub fn bus_run(stderr: &str) -> Option<BusRun> {
    let line = stderr
        .lines()
        .rev()
        .find(|l| l.contains("bus round trip (frame out"))?;
    let rt = &line[line.find("inputs back):")?..];
    let after = |key: &str| -> Option<f64> {
        let at = rt.find(key)? + key.len();
        rt[at..].trim_start().split([' ', ',']).next()?.parse().ok()
    };
    let cycles = rt
        .trim_start_matches("inputs back):")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let lost = line
        .split(", ")
        .find(|p| p.ends_with("lost frame(s)"))
        .and_then(|p| p.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    Some(BusRun {
        cycles,
        min: after("min ")?,
        p50: after("p50 ")?,
        p99: after("p99 ")?,
        p999: after("p99.9 ")?,
        max: after("max ")?,
        lost,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_bus_summary() {
        let s = "motion-supervisor: x\nmotion-io: EtherCAT on ecm1: 5000 bus cycles, 3 lost \
                 frame(s), 3 late, 0 working-counter error(s), 1 overrun(s), 0 recovery(ies), \
                 0 SubDevice(s) needing a restart; bus round trip (frame out → inputs back): \
                 4997 cycles: min 40.1 / p50 55.5 / p99 90.5 / p99.9 150.5 / max 900.2 us\n";
        let b = bus_run(s).unwrap();
        assert_eq!(
            b,
            BusRun {
                cycles: 4997,
                min: 40.1,
                p50: 55.5,
                p99: 90.5,
                p999: 150.5,
                max: 900.2,
                lost: 3
            }
        );
        assert_eq!(bus_run("nothing"), None);
        let other = BusRun {
            cycles: 3,
            min: 30.0,
            p99: 100.0,
            lost: 1,
            ..b
        };
        let m = b.merge(&other);
        assert_eq!((m.cycles, m.lost, m.min, m.p50), (5000, 4, 30.0, 55.5));
        assert_eq!((m.p99, m.p999, m.max), (100.0, 150.5, 900.2));
    }
}
