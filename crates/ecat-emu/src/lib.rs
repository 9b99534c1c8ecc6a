//! `ecat-emu`: a test fixture emulating a chain of EtherCAT SubDevices —
//! CiA 402 servo drives over [`motion_plant::Plant`] — on a raw socket, so
//! that `motion-ethercat` (ethercrab) can be tested on the wire without
//! hardware. Never a dependency of product crates.
//!
//! * [`chain`] — the wire: frames in chain order, datagram commands,
//!   working counters, unplug / re-plug, the emulator thread
//!   ([`Emulator`]) on the backend's raw socket (`motion_ethercat::socket`,
//!   the only piece of the backend it uses).
//! * [`esc`] — one ESC: registers, SII, FMMUs, sync managers, AL state
//!   machine, DC registers, SM watchdog.
//! * [`sii`] — the generated SII EEPROM image.
//! * [`coe`] — the mailbox CoE SDO server.
//! * [`od`] — the object dictionary.
//! * [`drive`] — the CiA 402 drive over the plant: its config, object
//!   dictionary, PDO image, SDO rules, state machine (independent of the
//!   backend's on purpose), motion, touch probes, inputs — a file each.
//! * [`netns`] — a veth pair with one end in a network namespace (tests).

pub mod chain;
pub mod coe;
pub mod drive;
pub mod esc;
pub mod netns;
pub mod od;
pub mod sii;

pub use chain::{Chain, Emulator, EmulatorConfig, SubDeviceView};
pub use drive::{
    DriveConfig, DriveView, ModeDisplay, PdoProfile, State, TorqueObjects, SUPPORTED_METHODS,
};
pub use esc::{al, Dropped};
pub use netns::{Skip, VethPair};
