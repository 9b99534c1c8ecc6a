//! The campaign's machine: the `Core` of the daemon as the real-time thread
//! steps it, one simulated I/O process answering it with the plant of its
//! drive, and the clients (a jog's HMI renewing its lease, a streaming
//! program publishing at the cycle rate). The I/O side can be made to do
//! everything a real one does wrong: its drive faults, drops its power
//! stage, is lost and comes back power-cycled; it answers with corrupt,
//! stale, missing or implausible feedback, a limit switch tripped; it dies
//! (its watchdog disables the drive after 50 cycles) and restarts.

use super::super::testbench::{Bench, MS};
use crate::shared::{Ack, Ask, Control};
use motion_frames::{
    axis_to_command, feedback_to_axis, FeedbackFrame, SetpointFrame, SETPOINT_LAYOUT,
    SW_DRIVE_LOST, SW_NO_DATA,
};
use motion_homing::{Command, Feedback};

/// The session key the campaign's Core checks setpoint frames against.
pub const KEY: [u64; 2] = [0x0123_4567_89ab_cdef, 0x0fed_cba9_8765_4321];
/// A dead I/O process's watchdog disables its drives after this many
/// cycles without a command (`motion-io`'s default).
pub const WATCHDOG_CYCLES: u32 = 50;

/// What the simulated I/O process and its drive do wrong now.
#[derive(Clone, Debug, Default)]
pub struct Io {
    /// The drive's power stage is held off (STO) while set.
    pub sto: bool,
    /// Cycles still answered with a velocity that is not a number.
    pub nan_for: u32,
    /// Cycles still answered with the same old frame.
    pub stale_for: u32,
    stale: Option<FeedbackFrame>,
    /// Cycles still answered without data for the axis.
    pub no_data_for: u32,
    /// Cycles the drive is still lost (off the bus: no data, reported
    /// lost, its own watchdog has it off).
    pub lost_for: u32,
    /// Cycles the process is still gone (no answer at all).
    pub gone_for: u32,
    silent: u32,
    /// One answer with the position 20 units off.
    pub jump: bool,
    /// A limit switch reads tripped from now on: the positive one?
    pub overtravel: Option<bool>,
    /// The cycle the drive or the process came back.
    pub back_at: Option<u64>,
}

/// A client of the operations.
#[derive(Clone, Debug)]
pub enum Client {
    None,
    /// An HMI holding a jog: renews every `every` cycles while `alive`.
    Jog {
        token: u64,
        every: u64,
        alive: bool,
    },
    /// A program streaming at the cycle rate while `alive`.
    Stream(Program),
}

/// A program's trajectory: at the cycle rate, accelerations within
/// `accel`, speed within `vmax`, braking in time for ±`room`; one setpoint
/// per cycle on its own timeline `t_ns`.
#[derive(Clone, Debug)]
pub struct Program {
    pub token: u64,
    pub seq: u64,
    pub t_ns: u64,
    pub p: f64,
    pub v: f64,
    pub accel: f64,
    pub vmax: f64,
    pub room: f64,
    /// Accelerating this way (±1) for `hold` more cycles.
    pub push: f64,
    pub hold: u32,
    pub alive: bool,
    /// When the last setpoint was published (the cycle).
    pub last_k: u64,
}

impl Program {
    /// The next setpoint: on at the current push, braking for the room.
    fn next(&mut self, rng_bits: u64) -> f64 {
        let dt = 1e-3;
        if self.hold == 0 {
            self.push = [-1.0, -0.5, 0.0, 0.5, 1.0][(rng_bits % 5) as usize];
            self.hold = 20 + (rng_bits >> 8) as u32 % 200;
        }
        self.hold -= 1;
        let stop = self.v * self.v / (2.0 * self.accel) + 3.0 * self.v.abs() * dt;
        let dv = if (self.p + self.v.signum() * stop).abs() > self.room {
            -self.v.signum() * (self.accel * dt).min(self.v.abs())
        } else {
            self.push * self.accel * dt
        };
        self.v = (self.v + dv).clamp(-self.vmax, self.vmax);
        self.p += self.v * dt;
        self.t_ns += MS;
        self.p
    }
}

/// The machine of one run.
#[derive(Clone)]
pub struct Rig {
    pub b: Bench,
    pub io: Io,
    pub client: Client,
    /// The answers of the requests the test made.
    pub answers: Vec<Ack>,
    /// Setpoint frames the next cycle takes besides the program's.
    pub inject: Vec<SetpointFrame>,
    /// The plant's last three positions and whether it followed commands
    /// (its power stage on, its I/O process there) — newest first: its
    /// truth, for the oracle.
    pub trail: [Option<(f64, bool)>; 3],
    /// Per-cycle bits the clients draw from.
    noise: u64,
}

impl Rig {
    pub fn new(b: Bench) -> Self {
        Self {
            b,
            io: Io::default(),
            client: Client::None,
            answers: Vec::new(),
            inject: Vec::new(),
            trail: [None; 3],
            noise: 0x1234_5678,
        }
    }

    /// The cycle's number (its time is this × 1 ms).
    pub fn k(&self) -> u64 {
        self.b.k
    }

    /// A request to the cycle, answered now or after the next step.
    pub fn control(&mut self, c: Control) {
        if let Some(a) = self.b.core.control(c, self.b.k * MS) {
            self.answers.push(a);
        }
    }

    pub fn run(&mut self, n: u64) {
        for _ in 0..n {
            self.cycle();
        }
    }

    /// The axis's drive, as the plant has it.
    pub fn plant(&self) -> &motion_plant::Plant {
        &self.b.plants[0]
    }

    /// The enable request the last command frame carried to the drive.
    pub fn enable_sent(&self) -> bool {
        let c = axis_to_command(&self.b.cmd[0].axes[0], self.counts());
        c.enable
    }

    fn counts(&self) -> f64 {
        self.b.m.axes[0].engine.counts_per_unit
    }

    /// The monitor's trip in force, in words.
    pub fn trip(&self) -> Option<String> {
        let a = &self.b.core.axes()[0];
        a.trip().map(|t| format!("{t:?} with {:?}", a.status()))
    }

    /// One cycle: the clients act, the core steps on the I/O process's
    /// newest answer, publishes, and the I/O process answers (or not).
    pub fn cycle(&mut self) {
        self.noise = self.noise.wrapping_mul(6364136223846793005).wrapping_add(1);
        self.clients();
        let now = self.b.k * MS;
        let answering = self.io.gone_for == 0 && self.b.seq[0] > 0;
        let frame = match (&self.io.stale, answering) {
            (_, false) => None,
            (Some(f), true) if self.io.stale_for > 0 => Some(f),
            _ => Some(&self.b.fb[0]),
        };
        self.b.core.step(now, false, &[frame]);
        let answers = &mut self.answers;
        self.b.core.answers(|a| answers.push(a));
        self.b.core.fill(0, &mut self.b.cmd[0]);
        self.b.seq[0] += 1;
        self.b.core.sent(0, self.b.seq[0], now);
        self.answer(now);
        let p = &self.b.plants[0];
        let commanded = self.io.gone_for == 0 && self.io.back_at != Some(self.b.k + 1);
        self.trail = [
            Some((p.position(), p.feedback().drive.enabled && commanded)),
            self.trail[0],
            self.trail[1],
        ];
        self.b.k += 1;
    }

    /// The I/O process: its drive takes the command (or its watchdog's
    /// stop), and it answers with what it reads (or what it gets wrong).
    fn answer(&mut self, now: u64) {
        let io = &mut self.io;
        if io.gone_for > 0 {
            io.gone_for -= 1;
            io.silent += 1;
            if io.silent == WATCHDOG_CYCLES {
                // motion-io's watchdog: every drive stopped and disabled
                self.b.plants[0].step(&Command::default(), 1e-3);
            }
            if io.gone_for == 0 {
                // restarted: a new process, the same drive, which the new
                // process starts disabled
                self.b.origin[0] += 1000;
                io.back_at = Some(self.b.k + 1);
                if io.silent < WATCHDOG_CYCLES {
                    self.b.plants[0].step(&Command::default(), 1e-3);
                }
            }
            return;
        }
        let mut c = axis_to_command(
            &self.b.cmd[0].axes[0],
            self.b.m.axes[0].engine.counts_per_unit,
        );
        if io.sto || io.lost_for > 0 {
            c.enable = false;
        }
        let mut fb: Feedback = self.b.plants[0].step(&c, 1e-3);
        if let Some(positive) = io.overtravel {
            fb.overtravel_positive = positive;
            fb.overtravel_negative = !positive;
        }
        if io.nan_for > 0 {
            io.nan_for -= 1;
            fb.velocity = f64::NAN;
        }
        if io.jump {
            io.jump = false;
            fb.position += 20.0;
        }
        let cpu = self.b.m.axes[0].engine.counts_per_unit;
        let mut entry = feedback_to_axis(&fb, cpu);
        if io.no_data_for > 0 {
            io.no_data_for -= 1;
            entry.status_word |= SW_NO_DATA;
        }
        if io.lost_for > 0 {
            io.lost_for -= 1;
            entry.status_word |= SW_NO_DATA | SW_DRIVE_LOST;
            if io.lost_for == 0 {
                io.back_at = Some(self.b.k + 1);
            }
        }
        let f = &mut self.b.fb[0];
        f.header.axis_count = 1;
        f.header.origin = self.b.origin[0];
        f.header.timestamp_ns = now + 20_000;
        f.answers_sequence = self.b.seq[0];
        f.axes[0] = entry;
        if io.stale_for > 0 {
            io.stale_for -= 1;
            if io.stale.is_none() {
                io.stale = Some(*f);
            }
        } else {
            io.stale = None;
        }
    }

    /// The clients act before the cycle: a jog renewed, a setpoint
    /// published.
    fn clients(&mut self) {
        let k = self.b.k;
        let bits = self.noise >> 16;
        self.b.core.setpoints_begin();
        for f in self.inject.drain(..) {
            self.b.core.setpoints_take(&f);
        }
        match &mut self.client {
            Client::None => {}
            &mut Client::Jog {
                token,
                every,
                alive,
            } => {
                if alive && k % every == 0 {
                    self.control(Control::undated(
                        0,
                        Ask::JogRenew {
                            token,
                            mask: 0,
                            end: false,
                        },
                    ));
                }
            }
            Client::Stream(p) => {
                if !p.alive {
                    return;
                }
                let position = p.next(bits);
                p.seq += 1;
                p.last_k = k;
                let f = setpoint_frame(p.token, p.seq, p.t_ns, position);
                self.b.core.setpoints_take(&f);
            }
        }
    }
}

/// A setpoint frame of `token` for axis 0.
pub fn setpoint_frame(token: u64, seq: u64, t_ns: u64, position: f64) -> SetpointFrame {
    let mut f = SetpointFrame {
        layout_version: SETPOINT_LAYOUT,
        key: KEY,
        token,
        seq,
        t_ns,
        count: 1,
        ..SetpointFrame::ZERO
    };
    f.axes[0].position = position;
    f
}
