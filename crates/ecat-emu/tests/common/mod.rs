//! The veth rig the wire tests share: a veth pair (the emulator's end in a
//! network namespace of its own), the emulator, the backend, one command
//! frame ticked at 1 kHz. Needs root (CI is root); without it a test prints
//! why it is skipped and passes.
#![allow(dead_code)]

use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use ecat_emu::{DriveConfig, DriveView, Emulator, EmulatorConfig, VethPair};
use motion_config::ethercat::BusAxis;
use motion_config::EthercatBus;
use motion_ethercat::EthercatBackend;
use motion_frames::backend::Backend;
use motion_frames::{
    AxisCommand, AxisFeedback, CommandFrame, FeedbackFrame, CW_ENABLE, CW_FAULT_RESET, SW_ENABLED,
    SW_FAULT, SW_NO_DATA,
};

pub const CYCLE: Duration = Duration::from_millis(1);
pub const CYCLE_US: u32 = 1000;

pub static TURN: Mutex<()> = Mutex::new(());

pub fn turn() -> MutexGuard<'static, ()> {
    TURN.lock().unwrap_or_else(|e| e.into_inner())
}

/// A drive with markers every 10 units at 2.5, a switch on [5, 8] and hard
/// stops at ±50.
pub fn drive(name: &str) -> DriveConfig {
    let mut d = DriveConfig::new(name);
    d.plant.marker_every = 10.0;
    d.plant.marker_at = 2.5;
    d.plant.switch = Some((5.0, 8.0));
    d.plant.hard_stop = Some((-50.0, 50.0));
    d.plant.overtravel = Some((-45.0, 45.0));
    d
}

pub struct Rig {
    pub backend: EthercatBackend,
    pub emu: Option<Emulator>,
    pub _pair: Option<VethPair>,
    pub cmd: CommandFrame,
    pub fb: FeedbackFrame,
    pub next: Instant,
}

/// Axes A0.. on the drives at positions 0.., the index pulse on bit 16.
pub fn mapping(n: usize) -> Vec<BusAxis> {
    (0..n)
        .map(|i| {
            let mut a = BusAxis::at(&format!("A{i}"), i as u16);
            a.ethercat.index_pulse_bit = Some(16);
            a
        })
        .collect()
}

pub fn emulator(pair: &VethPair, drives: Vec<DriveConfig>) -> Emulator {
    Emulator::start(EmulatorConfig {
        interface: pair.subdevice.clone(),
        netns: Some(pair.netns.clone()),
        drives,
        priority: Some(60),
    })
    .expect("emulator")
}

/// Pair + emulator + backend, or `None` (skipped, reason printed).
pub fn rig_with(drives: Vec<DriveConfig>, tweak: impl FnOnce(&mut EthercatBus)) -> Option<Rig> {
    let n = drives.len();
    let r = start(drives, mapping(n), tweak)?;
    Some(r.unwrap_or_else(|e| panic!("start-up: {e}")))
}

pub fn rig(n: usize) -> Option<Rig> {
    rig_with((0..n).map(|i| drive(&format!("EMU-{i}"))).collect(), |_| {})
}

impl Rig {
    pub fn emu(&self) -> &Emulator {
        self.emu.as_ref().expect("emulator")
    }

    /// One supervisor cycle: wait for the next 1 ms tick, exchange.
    pub fn tick(&mut self) {
        let now = Instant::now();
        if self.next > now {
            std::thread::sleep(self.next - now);
        }
        self.next += CYCLE;
        if self.next + CYCLE * 20 < Instant::now() {
            self.next = Instant::now(); // a long stall: do not catch up
        }
        self.backend
            .exchange(&self.cmd, &mut self.fb)
            .expect("exchange");
    }

    pub fn axis(&mut self, i: usize) -> &mut AxisCommand {
        &mut self.cmd.axes[i]
    }

    /// What emulated drive `i` does.
    pub fn drive(&self, i: usize) -> DriveView {
        self.emu().view(i).expect("drive").drive
    }

    /// Ticks until axis `i`'s feedback satisfies `pred`, at most 2 s.
    pub fn until_axis(
        &mut self,
        i: usize,
        what: &str,
        pred: impl Fn(&AxisFeedback) -> bool,
    ) -> usize {
        self.until(what, Duration::from_secs(2), |r| pred(&r.fb.axes[i]))
    }

    /// Ticks until `pred` holds (returns the ticks taken) or panics after
    /// `max`.
    pub fn until(
        &mut self,
        what: &str,
        max: Duration,
        mut pred: impl FnMut(&Rig) -> bool,
    ) -> usize {
        let t0 = Instant::now();
        let mut n = 0;
        loop {
            self.tick();
            n += 1;
            if pred(self) {
                return n;
            }
            assert!(
                t0.elapsed() < max,
                "{what}: not within {max:?}; feedback {:?}; drive {:?}; bus {:?}",
                &self.fb.axes[..self.fb.header.axis_count as usize],
                self.emu.as_ref().and_then(|e| e.view(0)).map(|v| v.drive),
                self.backend.bus_status()
            );
        }
    }

    pub fn ticks(&mut self, n: usize) {
        for _ in 0..n {
            self.tick();
        }
    }

    /// Enables axis `i` the way the engine does: target = actual.
    pub fn enable(&mut self, i: usize) {
        self.until_axis(i, "feedback", |a| a.status_word & SW_NO_DATA == 0);
        let at = self.fb.axes[i].position;
        let a = self.axis(i);
        a.target_position = at;
        a.control_word = CW_ENABLE;
        // A drive that a stalled host made "lost" while it enabled comes
        // back faulted (never enabled by itself): reset it, as an operator
        // would, and enable again — as often as the host does it.
        let mut resets = 0;
        let t0 = Instant::now();
        loop {
            self.tick();
            let s = self.fb.axes[i].status_word;
            if s & SW_ENABLED != 0 && s & SW_FAULT == 0 {
                break;
            }
            assert!(
                t0.elapsed() < Duration::from_secs(5),
                "axis {i} not enabled within 5 s: {:?}; drive {:?}; bus {:?}",
                self.fb.axes[i],
                self.emu.as_ref().and_then(|e| e.view(i)).map(|v| v.drive),
                self.backend.bus_status()
            );
            // the reset bit's rising edge while a fault shows, low otherwise
            let reset = self.cmd.axes[i].control_word & CW_FAULT_RESET != 0;
            let again = s & SW_FAULT != 0 && !reset;
            resets += u32::from(again);
            self.axis(i).control_word = if again {
                CW_ENABLE | CW_FAULT_RESET
            } else {
                CW_ENABLE
            };
        }
        if resets > 0 {
            eprintln!("axis {i} reset {resets} time(s) while enabling (lost on a loaded host)");
        }
    }

    /// The calling thread (the test's, playing the supervisor) at SCHED_FIFO
    /// 50 where allowed — below the bus thread (70) and the emulator (60):
    /// on a loaded 2-CPU host a normal thread is off the CPU for several
    /// cycles now and then, and the commands it sends then jump as a
    /// supervisor's after a stall would.
    pub fn pace() {
        let _ = motion_rt::enter_realtime(&motion_rt::RtConfig {
            cpu: None,
            priority: 50,
            lock_memory: false,
            prefault_stack: 0,
        });
    }

    /// Moves axis `i` to `to` counts at `speed` counts per cycle.
    pub fn move_to(&mut self, i: usize, to: i64, speed: i64) {
        loop {
            let t = self.cmd.axes[i].target_position;
            if t == to {
                break;
            }
            let step = (to - t).clamp(-speed, speed);
            self.axis(i).target_position = t + step;
            self.tick();
        }
    }

    pub fn settle(&mut self, i: usize) {
        let to = self.cmd.axes[i].target_position;
        self.until_axis(i, "settled", |a| {
            a.position == to && a.status_word & SW_NO_DATA == 0
        });
    }
}

/// The axes of a machine on an EtherCAT bus, with what their
/// configuration needs of the drives (`axes`: `[[axis]]` tables; each
/// names its `ethercat_position`).
pub fn axes_from_toml(axes: &str) -> Vec<BusAxis> {
    let text =
        format!("[[io]]\nname = \"bus0\"\nbackend = \"ethercat\"\ninterface = \"veth-x\"\n{axes}");
    let m = motion_config::parse(&text).unwrap_or_else(|p| panic!("{p:#?}"));
    EthercatBus::for_io(&m, 0, None, None, None)
        .expect("bus")
        .0
        .axes
}

/// Pair + emulator + the backend for `axes` on `drives`, or why it refused
/// (`None`: skipped, the reason printed).
pub fn start(
    drives: Vec<DriveConfig>,
    axes: Vec<BusAxis>,
    tweak: impl FnOnce(&mut EthercatBus),
) -> Option<Result<Rig, String>> {
    let pair = VethPair::or_skip()?;
    // the test's thread sends the commands: as the supervisor's, never off
    // the CPU long enough for the bus thread's own watchdog (100 ms)
    Rig::pace();
    let n = axes.len();
    let emu = emulator(&pair, drives);
    let mut cfg = EthercatBus::new(&pair.master, CYCLE_US, axes);
    tweak(&mut cfg);
    let backend = match EthercatBackend::new(cfg) {
        Ok(b) => b,
        Err(e) => return Some(Err(e.to_string())),
    };
    let mut cmd = CommandFrame::ZERO;
    cmd.header.axis_count = n as u32;
    for a in &mut cmd.axes[..n] {
        a.torque_limit_positive = 100.0;
        a.torque_limit_negative = 100.0;
    }
    Some(Ok(Rig {
        backend,
        emu: Some(emu),
        _pair: Some(pair),
        cmd,
        fb: FeedbackFrame::ZERO,
        next: Instant::now(),
    }))
}

/// The backend for `axes` on `drives` (panics if it refuses).
pub fn rig_for(drives: Vec<DriveConfig>, axes: Vec<BusAxis>) -> Option<Rig> {
    let r = start(drives, axes, |_| {})?;
    Some(r.unwrap_or_else(|e| panic!("start-up: {e}")))
}

/// Why the backend refuses `axes` on `drives` (panics if it starts).
pub fn refused(drives: Vec<DriveConfig>, axes: Vec<BusAxis>) -> Option<String> {
    match start(drives, axes, |_| {})? {
        Ok(_) => panic!("must be refused"),
        Err(e) => {
            eprintln!("{e}");
            Some(e)
        }
    }
}

impl Rig {
    /// The start-up lines of SubDevice `position`.
    pub fn lines(&self, position: usize) -> Vec<String> {
        self.backend.report().subdevices[position].lines.clone()
    }

    /// Whether some start-up line of SubDevice `position` contains `what`.
    #[track_caller]
    pub fn says(&self, position: usize, what: &str) {
        let lines = self.lines(position);
        assert!(
            lines.iter().any(|l| l.contains(what)),
            "no line with {what:?} in\n{}",
            lines.join("\n")
        );
    }
}
