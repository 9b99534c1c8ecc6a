//! Deterministic plant model of one servo axis: drive + mechanics + sensors.
//!
//! The homing engine's tests run engine and plant in a loop, and the
//! `motion-io` process's `sim` backend puts one plant behind every simulated
//! axis. Both need the same things from it, which shape the design:
//!
//! * **Exactly predictable.** Tests compare with hand-computed values, so the
//!   model is the simplest one that exercises homing: an enabled drive reaches
//!   its command within the cycle (the engine sees it one cycle later), motion
//!   within a cycle is a straight segment, and every sensor event is decided
//!   on that segment analytically (see [`sensors`] for the crossing rules).
//!   Latched positions are the exact marker / switch-boundary values.
//! * **Deterministic and real-time friendly.** No randomness, clocks, threads
//!   or allocation in [`Plant::step`].
//! * **Total.** No input makes it panic or report a non-finite value: a
//!   non-finite command faults the drive, malformed configs are
//!   [sanitized](PlantConfig::sanitized), huge values saturate.
//!
//! ```
//! use motion_homing::{Command, LatchArm};
//! use motion_plant::{Plant, PlantConfig};
//!
//! let mut plant = Plant::new(PlantConfig {
//!     marker_at: 2.5,
//!     marker_every: 10.0,
//!     enable_delay_cycles: 0,
//!     ..PlantConfig::default()
//! });
//! let mut cmd = Command { enable: true, torque_limit_positive: 100.0,
//!                         torque_limit_negative: 100.0, ..Command::default() };
//! cmd.marker_arm = LatchArm { id: 1, ..LatchArm::default() };
//! cmd.position = 3.0;
//! let fb = plant.step(&cmd, 0.001);
//! assert_eq!(fb.position, 3.0);
//! assert!(fb.marker_latch.latched);
//! assert_eq!(fb.marker_latch.position, 2.5);
//! ```

pub mod config;
mod drive;
mod latch;
pub mod limits;
mod num;
mod plant;
pub mod sensors;
mod torque;

pub use config::{PlantConfig, RegistrationInput, TorqueSpike};
pub use num::feedback_numbers;
pub use plant::Plant;
pub use sensors::{Markers, Switch, SwitchEdge};
