//! `[[io]]`: the drive-I/O processes.

use super::{keys, Key, Kind, Section::Io};
use crate::{IoBackend, SPAWN_NAMES};

keys! {
    GROUP {
        section: Io,
        title: "[[io]]",
        intro: "One table per drive-I/O process (`motion-io --io NAME`), at most 16. Without \
                any, one process named `io` with the `sim` backend, started as `[supervisor] io` \
                says. With several, every axis names its process (`[[axis]] io`).",
    }
    NAME: Key::new(Io, "name", Kind::Text)
        .bounded("1..=32 characters of A-Z a-z 0-9 _ -, unique")
        .fixed()
        .meaning("The I/O process's name: axes name it, `motion-io --io NAME` serves it, and it is \
                  part of its service names.")
        .example("\"bus0\"");
    SPAWN: Key::new(Io, "spawn", Kind::Choice(|| super::names_of(SPAWN_NAMES)))
        .text("sim")
        .fixed()
        .meaning("`\"sim\"` (or its synonym `\"supervisor\"`): the supervisor starts \
                  `motion-io --backend BACKEND --io NAME` and restarts it if it ends; \
                  `\"external\"`: it waits for one started by someone else (`motion-io@NAME.service`).")
        .example("\"external\"");
    BACKEND: Key::new(Io, "backend", Kind::Choice(|| super::names_of(IoBackend::NAMES)))
        .text("sim")
        .meaning("What drives the axes: `\"sim\"` one simulated plant per axis (`[axis.sim]`), \
                  `\"ethercat\"` CiA 402 drives on an EtherCAT bus (the keys below).")
        .example("\"ethercat\"");
    CPU: Key::new(Io, "cpu", Kind::Integer)
        .unset("`[supervisor] io_cpu`")
        .bounded("a CPU this machine has online")
        .fixed()
        .meaning("CPU of a spawned process (EtherCAT: also of its bus thread).")
        .example("0");
    PRIORITY: Key::new(Io, "priority", Kind::Integer)
        .derived("`[supervisor] io_priority`")
        .range(0.0, 99.0)
        .fixed()
        .meaning("`SCHED_FIFO` priority of a spawned process (EtherCAT: of its bus thread); 0: \
                  normal scheduling.")
        .example("70");
}
