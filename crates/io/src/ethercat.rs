//! Backend `ethercat`: CiA 402 drives on an EtherCAT bus, through
//! [`motion_ethercat::EthercatBackend`] (ethercrab on its own real-time bus
//! thread, cycling at the supervisor's cycle; see `crates/ethercat/README.md`).
//!
//! [`EthercatIo`] is the thin adapter between motion-io and the bus's
//! [`Backend`]: the methods are forwarded. The one thing it adds is the virtual axes of
//! the I/O process: they have no drive, so they are left out of the bus and
//! answered here (the engine never reads a virtual axis' feedback; the
//! command is echoed). With no virtual axis the frames go through as they
//! are; otherwise they are repacked into preallocated frames (no allocation
//! per cycle).

use std::cell::RefCell;

use motion_ethercat::{EthercatBackend, EthercatBus};
use motion_frames::backend::{Backend, ExchangeError};
use motion_frames::{
    AxisCommand, AxisFeedback, CommandFrame, FeedbackFrame, CW_ENABLE, SW_ENABLED,
};

use crate::ethercat_log::{self, HealthLog};
use crate::say::Say;

/// Why the backend could not start, and the exit code it calls for.
#[derive(Debug)]
pub struct StartError {
    /// 2: a configuration / command-line mistake; 1: the bus refused.
    pub code: i32,
    pub message: String,
}

/// Copies the bus feedback `bus` into `fb` in frame order (`map`: frame →
/// bus index); virtual axes echo their last command.
fn unpack(
    map: &[Option<usize>],
    last: &[AxisCommand],
    bus: &FeedbackFrame,
    fb: &mut FeedbackFrame,
) {
    for (i, m) in map.iter().enumerate() {
        fb.axes[i] = match m {
            Some(k) => bus.axes[*k],
            None => {
                let c = &last[i];
                AxisFeedback {
                    position: c.target_position,
                    velocity: c.target_velocity,
                    status_word: if c.control_word & CW_ENABLE != 0 {
                        SW_ENABLED
                    } else {
                        0
                    },
                    ..AxisFeedback::ZERO
                }
            }
        };
    }
    fb.header.axis_count = map.len() as u32;
}

/// motion-io's [`Backend`] over [`EthercatBackend`].
pub struct EthercatIo {
    inner: EthercatBackend,
    names: Vec<String>,
    /// Frame index → bus index; `None`: a virtual axis.
    map: Vec<Option<usize>>,
    /// Every axis on the bus, in frame order: frames pass through.
    direct: bool,
    bus_cmd: Box<CommandFrame>,
    bus_fb: RefCell<Box<FeedbackFrame>>,
    /// Last command of each frame axis (the virtual ones are echoed).
    last: Vec<AxisCommand>,
    interface: String,
    /// Logs every change of a drive's health.
    _health: HealthLog,
}

impl EthercatIo {
    /// Starts the bus (blocking until every SubDevice is in OP or start-up
    /// failed; errors name the SubDevice and the object or state).
    pub fn start(
        cfg: EthercatBus,
        map: Vec<Option<usize>>,
        names: Vec<String>,
        say: Say,
        io: &str,
    ) -> Result<EthercatIo, StartError> {
        let interface = cfg.keys.interface.clone();
        let inner = EthercatBackend::new(cfg).map_err(|e| StartError {
            code: 1,
            message: format!("EtherCAT start-up on {interface} failed: {e}"),
        })?;
        let direct = map.iter().enumerate().all(|(i, m)| *m == Some(i));
        let health = HealthLog::start(inner.health_watch(), say, io.to_string());
        Ok(EthercatIo {
            _health: health,
            inner,
            last: vec![AxisCommand::ZERO; names.len()],
            names,
            map,
            direct,
            bus_cmd: Box::new(CommandFrame::ZERO),
            bus_fb: RefCell::new(Box::new(FeedbackFrame::ZERO)),
            interface,
        })
    }

    pub fn report_lines(&self) -> Vec<String> {
        ethercat_log::report_lines(&self.interface, self.inner.report())
    }

    /// Runs `f` on the bus feedback, then fills `fb` from it.
    fn via_bus<R>(
        &mut self,
        fb: &mut FeedbackFrame,
        f: impl FnOnce(&mut EthercatBackend, &mut FeedbackFrame) -> R,
    ) -> R {
        if self.direct {
            return f(&mut self.inner, fb);
        }
        let bus = self.bus_fb.get_mut();
        let r = f(&mut self.inner, bus);
        unpack(&self.map, &self.last, bus, fb);
        r
    }

    /// A summary of the bus counters and its round trip, for the log at exit.
    pub fn summary(&self) -> String {
        ethercat_log::summary(&self.interface, &self.inner.bus_status())
    }
}

impl Backend for EthercatIo {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn axis_count(&self) -> usize {
        self.names.len()
    }

    fn axis_names(&self) -> Vec<String> {
        self.names.clone()
    }

    fn apply(&mut self, cmd: &CommandFrame, fb: &mut FeedbackFrame) -> Result<(), ExchangeError> {
        if self.direct {
            return self.inner.exchange(cmd, fb);
        }
        let n = self.names.len();
        self.last.copy_from_slice(&cmd.axes[..n]);
        let mut bus_n = 0;
        for (i, m) in self.map.iter().enumerate() {
            if let Some(k) = m {
                self.bus_cmd.axes[*k] = cmd.axes[i];
                bus_n += 1;
            }
        }
        self.bus_cmd.header = cmd.header;
        self.bus_cmd.header.axis_count = bus_n as u32;
        let bus = self.bus_fb.get_mut();
        let r = self.inner.exchange(&self.bus_cmd, bus);
        unpack(&self.map, &self.last, bus, fb);
        r
    }

    fn watchdog_stop(&mut self, dt_s: f64, fb: &mut FeedbackFrame) -> bool {
        // the virtual axes stop with their commands: nothing to do
        self.via_bus(fb, |b, f| b.watchdog_stop(dt_s, f))
    }

    fn status(&self, fb: &mut FeedbackFrame) {
        if self.direct {
            return self.inner.status(fb);
        }
        let mut bus = self.bus_fb.borrow_mut();
        self.inner.status(&mut bus);
        unpack(&self.map, &self.last, &bus, fb);
    }

    fn emergency_stop(&mut self, fb: &mut FeedbackFrame) {
        self.via_bus(fb, |b, f| b.emergency_stop(f));
    }

    fn shutdown(&mut self, dt_s: f64, fb: &mut FeedbackFrame) -> bool {
        // paced by the bus cycle, bounded by the stop's own bound
        // (EthercatBackend::stop_bound)
        self.via_bus(fb, |b, f| b.shutdown(dt_s, f))
    }

    fn summary(&self) -> Option<String> {
        Some(EthercatIo::summary(self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn virtual_axes_echo_their_command_between_the_bus_axes() {
        let mut bus = FeedbackFrame::ZERO;
        bus.axes[0].position = 111;
        bus.axes[1].position = 222;
        let mut last = vec![AxisCommand::ZERO; 3];
        last[1].target_position = 5_000;
        last[1].target_velocity = 20.0;
        last[1].control_word = CW_ENABLE;
        let mut fb = FeedbackFrame::ZERO;
        unpack(&[Some(0), None, Some(1)], &last, &bus, &mut fb);
        assert_eq!(fb.header.axis_count, 3);
        assert_eq!(
            (
                fb.axes[0].position,
                fb.axes[1].position,
                fb.axes[2].position
            ),
            (111, 5_000, 222)
        );
        assert_eq!(
            (fb.axes[1].velocity, fb.axes[1].status_word),
            (20.0, SW_ENABLED)
        );
    }
}
