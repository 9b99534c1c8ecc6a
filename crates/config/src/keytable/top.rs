//! The tables of the file.

use super::{keys, Key, Kind, Section::Top};

keys! {
    GROUP {
        section: Top,
        title: "The file",
        intro: "A machine is one TOML file: `motion-supervisor check --config FILE` reads it \
                and names every problem at once, each by axis and key. Without `--config` \
                the binaries use the built-in demo machine. Every table is optional but \
                `[[axis]]`; a key nobody reads (a typo) is a problem too.",
    }
    SUPERVISOR: Key::new(Top, "supervisor", Kind::Table)
        .unset("every key at its default")
        .fixed()
        .meaning("The real-time cycle, its CPU and priority, and where the daemon keeps its files.")
        .example("{ cycle_us = 1000 }");
    IO: Key::new(Top, "io", Kind::Tables)
        .unset("one I/O process named `io`, started as `[supervisor] io` says, with the `sim` backend")
        .fixed()
        .meaning("The drive-I/O processes (`motion-io`), at most 16.")
        .example("[{ name = \"bus0\" }]");
    AXIS: Key::new(Top, "axis", Kind::Tables)
        .fixed()
        .meaning("The axes, 1 to 64, in the order their frames carry them.")
        .example("[{ name = \"X\" }]");
    GANTRY: Key::new(Top, "gantry", Kind::Tables)
        .unset("no gantry")
        .fixed()
        .meaning("Axes homed as one machine axis.")
        .example("[{ name = \"Y\", axes = [\"Y1\", \"Y2\"] }]");
    OPCUA: Key::new(Top, "opcua", Kind::Table)
        .unset("every key at its default (`motion-opcua` serves this host only)")
        .meaning("What `motion-opcua` serves on the plant network.")
        .example("{ anonymous = \"off\" }");
}
