//! `[[gantry]]`: axes homed as one machine axis.

use super::{keys, Key, Kind, Section::Gantry};
use crate::limits::POSITION;

keys! {
    GROUP {
        section: Gantry,
        title: "[[gantry]]",
        intro: "The sides of a gantry run the same sequence in lockstep: every leg starts on all \
                sides in the same cycle; each side latches its own event and applies its own \
                `home_offset`, which squares the gantry. What decides the legs (mode, sequence, \
                direction, speeds, accelerations, torque settings, travel, home order) must be \
                the same on every side. A gantry jogs, moves and streams as one axis too.",
    }
    NAME: Key::new(Gantry, "name", Kind::Text)
        .bounded("1..=32 characters of A-Z a-z 0-9 _ . -, not an axis's name")
        .fixed()
        .meaning("The gantry's name: commands given it act on every side; a side named alone is \
                  refused.")
        .example("\"Y\"");
    AXES: Key::new(Gantry, "axes", Kind::NameList)
        .bounded("2..=4 axis names, each a side of one gantry only")
        .fixed()
        .meaning("The sides.")
        .example("[\"Y1\", \"Y2\"]");
    MAX_SKEW: Key::new(Gantry, "max_skew", Kind::Number)
        .num(1.0)
        .range(1e-6, POSITION)
        .unit("units")
        .fixed()
        .meaning("Sides whose events lie further apart than this fail together with ERR 1017, \
                  before anything is squared.")
        .example("1.0");
}
