//! The EtherCAT keys: of an `[[io]]` with `backend = "ethercat"`, and of
//! its axes. Anywhere else each one is a problem (it would be ignored).

use super::{keys, Key, Kind, Section};
use crate::ethercat::DC_MODES;

keys! {
    IO {
        section: Section::Io,
        title: "[[io]] with backend = \"ethercat\"",
        intro: "An EtherCAT I/O process drives CiA 402 drives in cyclic synchronous position \
                mode on a dedicated network interface, cycling at `[supervisor] cycle_us` \
                (at least 100 µs). See the EtherCAT page of the manual.",
    }
    INTERFACE: Key::new(Section::Io, "interface", Kind::Text)
        .bounded("1..=15 printable characters without `/`, `:` or space")
        .ethercat()
        .meaning("The network interface of the bus, used by nothing else; `motion-io --interface` \
                  overrides it.")
        .example("\"enp3s0\"");
    DC: Key::new(Section::Io, "dc", Kind::Choice(|| super::names_of(DC_MODES)))
        .text("auto")
        .ethercat()
        .meaning("Distributed clocks: `\"auto\"` SYNC0 on every drive that supports it, free run \
                  elsewhere; `\"on\"` every drive on SYNC0 (a start-up error otherwise); `\"off\"` \
                  free run.")
        .example("\"on\"");
    SM_WATCHDOG_MS: Key::new(Section::Io, "sm_watchdog_ms", Kind::Integer)
        .int(50)
        .range(1.0, 1000.0)
        .unit("ms")
        .note("and at least 3 cycles")
        .ethercat()
        .meaning("The drives' sync-manager watchdog: a drive stops this long after the last \
                  process data (a dead `motion-io`, a cut cable).")
        .example("50");
    REPLY_TIMEOUT_US: Key::new(Section::Io, "reply_timeout_us", Kind::Integer)
        .unset("90 % of the cycle")
        .range(10.0, 95_000.0)
        .unit("µs")
        .note("and at most 95 % of the cycle")
        .ethercat()
        .meaning("A bus frame answered later than this counts as lost.")
        .example("800");
    STARTUP_TIMEOUT_S: Key::new(Section::Io, "startup_timeout_s", Kind::Integer)
        .int(30)
        .range(1.0, 300.0)
        .unit("s")
        .ethercat()
        .meaning("How long the bus may take from INIT to OP at start-up.")
        .example("30");
    MODE_IN_PDO: Key::new(Section::Io, "mode_in_pdo", Kind::Bool)
        .flag(false)
        .ethercat()
        .meaning("Also map 0x6060 (modes of operation) into the RxPDO, for drives that want it \
                  there rather than written once over SDO.")
        .example("true");
    DC_STATIC_SYNC_ITERATIONS: Key::new(Section::Io, "dc_static_sync_iterations", Kind::Integer)
        .int(1000)
        .range(0.0, 100_000.0)
        .ethercat()
        .meaning("Rounds of the distributed clocks' static drift compensation at start-up.")
        .example("1000");
    QUICK_STOP_TIMEOUT_MS: Key::new(Section::Io, "quick_stop_timeout_ms", Kind::Integer)
        .int(500)
        .range(10.0, 10_000.0)
        .unit("ms")
        .ethercat()
        .meaning("A stop of `motion-io` (watchdog, shutdown, a refused set-point) gives each drive \
                  quick stop for at most this long, then disable voltage: every drive ends in \
                  Switch on disabled, power stage off.")
        .example("500");
}

keys! {
    AXIS {
        section: Section::Axis,
        title: "[[axis]] of an EtherCAT I/O process",
        intro: "Every axis of an EtherCAT I/O process but a virtual one names its drive, by bus \
                position or by name. What else the drive must have follows from the axis's \
                configuration and is checked at start-up.",
    }
    ETHERCAT_POSITION: Key::new(Section::Axis, "ethercat_position", Kind::Integer)
        .unset("the drive is named by `ethercat_name`; one of the two is required")
        .range(0.0, 65_535.0)
        .ethercat()
        .meaning("Bus position of the axis's drive (0: the first after the master).")
        .example("0");
    ETHERCAT_NAME: Key::new(Section::Axis, "ethercat_name", Kind::Text)
        .unset("the drive is named by `ethercat_position`")
        .bounded("1..=64 printable characters, unique on the bus")
        .ethercat()
        .meaning("The drive's SubDevice name (its SII name), instead of its position.")
        .example("\"X5-Servo\"");
    ETHERCAT_INDEX_PULSE_BIT: Key::new(Section::Axis, "ethercat_index_pulse_bit", Kind::Integer)
        .unset("none; required by a marker sequence with `marker_latch = false`")
        .range(16.0, 31.0)
        .ethercat()
        .meaning("The manufacturer bit of 0x60FD (digital inputs) that reports an index pulse in \
                  the last cycle, for a drive that cannot latch the marker.")
        .example("16");
    ETHERCAT_HOME_SWITCH_BIT: Key::new(Section::Axis, "ethercat_home_switch_bit", Kind::Integer)
        .unset("bit 2 of 0x60FD, the standard home switch input")
        .range(16.0, 31.0)
        .ethercat()
        .meaning("The manufacturer bit of 0x60FD wired to the home switch.")
        .example("18");
    ETHERCAT_BRAKE_DELAY_MS: Key::new(Section::Axis, "ethercat_brake_delay_ms", Kind::Integer)
        .int(0)
        .range(0.0, 2_000.0)
        .unit("ms")
        .ethercat()
        .meaning("A vertical axis whose drive closes a holding brake: every stop ends with \
                  disable operation, this long with the power stage on while the brake closes, \
                  then disable voltage. 0: no brake.")
        .example("150");
    DRIVE_HOMING: Key::new(Section::Axis, "drive_homing", Kind::Bool)
        .derived("true when `drive_homing_method` is given, else false")
        .ethercat()
        .meaning("The drive homes the axis itself (CiA 402 homing mode 6) with the standard method \
                  of the sequence and direction, or `drive_homing_method`; active sequences that \
                  move only.")
        .example("true");
    DRIVE_HOMING_METHOD: Key::new(Section::Axis, "drive_homing_method", Kind::Integer)
        .derived("the standard CiA 402 method of `home_sequence` and `home_direction`")
        // 0x6098 is a signed byte; 0 means no method.
        .range(-128.0, 127.0)
        .note("not 0")
        .ethercat()
        .meaning("The drive's homing method (0x6098); given, it implies `drive_homing = true`. \
                  Required for torque and unidirectional switch sequences, which have no \
                  standard method (hard-stop methods are the vendor's, negative on most drives).")
        .example("19");
}
