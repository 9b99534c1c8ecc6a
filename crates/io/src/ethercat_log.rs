//! What motion-io says about its EtherCAT bus: the start-up report (per
//! drive: the mapping in force, sync mode and cycle, SM watchdog, stop,
//! brake, homing, what is unavailable), every change of a drive's health
//! while it runs (a thread of its own, off the loop: it formats and logs),
//! and the bus summary at exit.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use motion_ethercat::{BusStatus, Health, HealthWatch, StartupReport, SubDeviceHealth, SyncMode};

use crate::say::Say;

/// The start-up report in lines for the log: one summary, per SubDevice a
/// line (name, position, the axis it drives, DC or free run) and the lines
/// of its set-up, then the warnings.
pub fn report_lines(interface: &str, r: &StartupReport) -> Vec<String> {
    let dc = r.axes.iter().filter(|(_, s)| *s == SyncMode::Dc).count();
    let mut out = vec![format!(
        "EtherCAT on {interface}: {} SubDevice(s) in OP after {} ms; {} of {} axes on \
         distributed clocks (SYNC0), {} free run; bus thread: {}",
        r.subdevices.len(),
        r.duration.as_millis(),
        dc,
        r.axes.len(),
        r.axes.len() - dc,
        r.rt.lines().next().unwrap_or_default()
    )];
    for s in &r.subdevices {
        let sync = match (&s.axis, s.sync) {
            (Some(axis), Some(sync)) => format!("axis {axis}, {sync}"),
            _ => "no axis".to_string(),
        };
        out.push(format!(
            "  SubDevice {} {:?}: {sync} (DC {}capable), vendor {:#010x} product {:#010x} rev {}, \
             {} B out / {} B in",
            s.position,
            s.name,
            if s.dc_capable { "" } else { "not " },
            s.vendor_id,
            s.product_id,
            s.revision,
            s.output_bytes,
            s.input_bytes
        ));
        for l in &s.lines {
            out.push(format!("    {l}"));
        }
    }
    for w in &r.warnings {
        out.push(format!("  warning: {w}"));
    }
    out
}

/// The bus counters and round trip, for the log at exit.
pub fn summary(interface: &str, st: &BusStatus) -> String {
    format!(
        "EtherCAT on {interface}: {} bus cycles, {} lost frame(s), {} late, {} working-counter \
         error(s), {} overrun(s), {} recovery(ies), {} drive loss(es), {} back in OP, {} \
         re-configured after a power cycle, {} SubDevice(s) needing a restart, {} stop(s) by \
         the bus thread's own watchdog, {} drive(s) stopped after a loss over which their \
         command ran away, {} frame(s) moved off the supervisor's sequence (the clocks a cycle \
         apart, or a stall); bus round trip (frame out → inputs back): {}",
        st.cycles,
        st.lost_frames,
        st.late_frames,
        st.wkc_errors,
        st.overruns,
        st.recoveries,
        st.losses,
        st.returns,
        st.reconfigured,
        st.needs_restart,
        st.bus_watchdog_trips,
        st.axes.iter().map(|a| a.gap_stops).sum::<u64>(),
        st.handoff_corrections,
        st.roundtrip
    )
}

/// An AL status code in words (ETG.1000.6 Table 11, the ones drives raise).
fn al_code(code: u16) -> &'static str {
    match code {
        0x0000 => "no error",
        0x0011 => "invalid requested state change",
        0x0016 => "invalid mailbox configuration",
        0x001A => "synchronisation error",
        0x001B => "sync manager watchdog",
        0x001D => "invalid output configuration",
        0x001E => "invalid input configuration",
        0x002C => "fatal sync error",
        0x0030 => "invalid DC SYNC configuration",
        _ => "see the drive's manual",
    }
}

fn state(al: u8) -> &'static str {
    match al & 0x0F {
        0x01 => "INIT",
        0x02 => "PRE-OP",
        0x03 => "BOOT",
        0x04 => "SAFE-OP",
        0x08 => "OP",
        _ => "no answer",
    }
}

/// What one change of health means, for the operator.
pub fn health_line(h: &SubDeviceHealth, io: &str) -> String {
    let who = format!(
        "EtherCAT: SubDevice {} {:?} (axis {})",
        h.position,
        h.name,
        h.axes.join(", ")
    );
    match h.health {
        Health::NotAnswering => format!(
            "{who} lost: it does not answer (power, cable, or the SubDevice before it); its \
             axis reports its drive lost (a homing ends ERR 12 / EXERR 45), its SM watchdog \
             stops it; it is brought back to OP when it answers again"
        ),
        Health::NotOp => format!(
            "{who} lost: it left OP ({}, AL status code {:#06x} {}); acknowledging and \
             requesting OP again",
            state(h.al_status),
            h.al_code,
            al_code(h.al_code)
        ),
        Health::PowerCycled => format!(
            "{who} was power-cycled (found at its bus position without its station \
             address): re-configuring it (station address, mailbox, PDO mapping, mode, SM \
             watchdog; free run)"
        ),
        Health::Ok => format!(
            "{who} back in OP (lost {} time(s), re-configured {} time(s)); its axis stays \
             disabled until the supervisor asks again (reset, then enable or home)",
            h.losses, h.reconfigured
        ),
        Health::Failed => format!(
            "{who} cannot be brought back: {}; restart motion-io (`systemctl restart \
             motion-io@{io}`, or the supervisor when it spawned it) to bring it up again",
            h.failure.as_deref().unwrap_or("re-configuring it failed")
        ),
    }
}

/// The thread that logs every change of a drive's health.
pub struct HealthLog {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl HealthLog {
    /// Starts watching `watch` (every 20 ms), logging through `say`.
    pub fn start(watch: HealthWatch, say: Say, io: String) -> HealthLog {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::Builder::new()
            .name("ecat-health".into())
            .spawn(move || {
                let mut seen = watch.events();
                let mut last: Vec<Health> = watch.health().iter().map(|h| h.health).collect();
                while !flag.load(Ordering::Relaxed) {
                    std::thread::sleep(Duration::from_millis(20));
                    let now = watch.events();
                    if now == seen {
                        continue;
                    }
                    seen = now;
                    for (k, h) in watch.health().iter().enumerate() {
                        if last.get(k) != Some(&h.health) {
                            say.always(format_args!("{}", health_line(h, &io)));
                            if let Some(l) = last.get_mut(k) {
                                *l = h.health;
                            }
                        }
                    }
                }
            })
            .ok();
        HealthLog { stop, thread }
    }
}

impl Drop for HealthLog {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
