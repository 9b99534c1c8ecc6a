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
        let mut v = vec![Variant::Bare, Variant::Clients];
        if o.homing {
            v.push(Variant::Homing);
        }
        v
    }

    /// `a`, `b`, `c`: in service prefixes and file names.
    pub fn letter(self) -> char {
        match self {
            Variant::Bare => 'a',
            Variant::Clients => 'b',
            Variant::Homing => 'c',
        }
    }

    /// The row label of the table.
    pub fn label(self) -> &'static str {
        match self {
            Variant::Bare => "(a) no control plane",
            Variant::Clients => "(b) control plane",
            Variant::Homing => "(c) (b) + homing X",
        }
    }

    /// The key of its object in cpcost.json.
    pub fn key(self) -> &'static str {
        match self {
            Variant::Bare => "a_no_control_plane",
            Variant::Clients => "b_control_plane_with_clients",
            Variant::Homing => "c_control_plane_homing",
        }
    }

    /// What it runs, in words (the table's legend and the JSON).
    pub fn describe(self, o: &Opts) -> String {
        let clients = format!(
            "control + status services, clients attached: 1 x `motionctl status --watch` (HMI), \
             `motionctl status --json` every {} ms (PLC), `motionctl stats --json` every {} ms",
            o.status_every_ms, o.stats_every_ms
        );
        match self {
            Variant::Bare => {
                "`motion-supervisor run --no-control-plane`: no control or status service, \
                 no client"
                    .into()
            }
            Variant::Clients => clients,
            Variant::Homing => {
                format!("{clients}, and `motionctl home X --json` back to back")
            }
        }
    }

    /// The control plane runs (and clients attach).
    pub fn serves(self) -> bool {
        self != Variant::Bare
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn letters_and_keys_differ() {
        let v = [Variant::Bare, Variant::Clients, Variant::Homing];
        for (i, a) in v.iter().enumerate() {
            for b in &v[i + 1..] {
                assert_ne!(a.letter(), b.letter());
                assert_ne!(a.key(), b.key());
                assert_ne!(a.label(), b.label());
            }
        }
        assert!(!Variant::Bare.serves() && Variant::Clients.serves() && Variant::Homing.serves());
    }
}
