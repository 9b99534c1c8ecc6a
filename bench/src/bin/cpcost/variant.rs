//! The variants compared: the same demo machine at the same period, without
//! the control plane, with it and its clients, and (with `--homing`) with
//! its clients while an axis homes.

use crate::cli::Opts;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// (a) `run --no-control-plane`: no control or status service, no client.
    Bare,
    /// (b) the control plane with a deployed machine's clients attached.
    Clients,
    /// (c) (b) plus `motionctl home X --json` back to back.
    Homing,
}

impl Variant {
    /// The variants of this run, in the order of the even slices (the odd
    /// ones run them in reverse, so that neither always follows the other).
    pub fn all(o: &Opts) -> Vec<Variant> {
        let v = [Variant::Bare, Variant::Clients, Variant::Homing];
        v[..2 + usize::from(o.homing)].to_vec()
    }

    /// `a`, `b`, `c`: in service prefixes and file names.
    pub fn letter(self) -> char {
        ['a', 'b', 'c'][self as usize]
    }

    /// The row label of the table.
    pub fn label(self) -> &'static str {
        [
            "(a) no control plane",
            "(b) control plane",
            "(c) (b) + homing X",
        ][self as usize]
    }

    /// The key of its object in cpcost.json.
    pub fn key(self) -> &'static str {
        [
            "a_no_control_plane",
            "b_control_plane_with_clients",
            "c_control_plane_homing",
        ][self as usize]
    }

    /// What it runs, in words (the table's legend and the JSON).
    pub fn describe(self, o: &Opts) -> String {
        let clients = format!(
            "control + status services, clients attached: 1 x `motionctl status --watch` (HMI), \
             `motionctl status --json` every {} ms (PLC), `motionctl stats --json` every {} ms",
            o.status_every_ms, o.stats_every_ms
        );
        match self {
            Variant::Bare => "`motion-supervisor run --no-control-plane`: no control or status \
                              service, no client"
                .into(),
            Variant::Clients => clients,
            Variant::Homing => format!("{clients}, and `motionctl home X --json` back to back"),
        }
    }

    /// The control plane runs (and clients attach).
    pub fn serves(self) -> bool {
        self != Variant::Bare
    }
}
