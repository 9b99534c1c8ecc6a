//! What one drive must have, from what its axis does ([`AxisNeeds`], worked
//! out by `motion-config`) and what its dictionary holds: the objects its
//! process data must carry — the required ones each with the configuration
//! that needs it, then the useful optional ones — and every missing object
//! at once, each named `0xNNNN` with what it is for and which axis
//! configuration needs it. Pure: unit-tested here, run at start-up by
//! [`crate::drive_setup`].

use motion_config::ethercat::{AxisNeeds, DriveHomingPlan};

use crate::dictionary::Dictionary;
use crate::objects::*;
use crate::pdo::PdoLayout;

/// An object the process data should carry; `why`: the configuration that
/// requires it (`None`: optional, mapped where the drive allows).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Want {
    pub entry: PdoEntry,
    pub why: Option<String>,
}

/// What the drive of axis `axis` must and may carry.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Wants {
    pub rx: Vec<Want>,
    pub tx: Vec<Want>,
    /// One line per missing object (or unsupported mode / method); empty:
    /// the drive has everything.
    pub missing: Vec<String>,
    /// The drive's own homing, if the axis's drive homes (checked).
    pub drive_homing: Option<DriveHomingPlan>,
}

const POSITION_CONTROL: &str = "cyclic synchronous position control (every axis)";

fn missing_line(e: &PdoEntry, why: &str, dict: &Dictionary) -> String {
    let abort = dict
        .abort(e.index)
        .map_or(String::new(), |c| format!(" (SDO abort {c:#010X})"));
    format!(
        "missing {} — {} — needed by {why}{abort}",
        e.label(),
        purpose(e.index)
    )
}

impl Wants {
    /// The wants of a drive whose dictionary is `dict`, for an axis named
    /// `axis` that needs `needs`; `mode_in_pdo`: the `[[io]]` key.
    pub fn of(axis: &str, needs: &AxisNeeds, dict: &Dictionary, mode_in_pdo: bool) -> Wants {
        let mut w = Wants {
            rx: Vec::new(),
            tx: Vec::new(),
            missing: Vec::new(),
            drive_homing: None,
        };
        let who = |why: &str| format!("axis {axis}: {why}");
        let req = |w: &mut Wants, rx: bool, e: PdoEntry, why: String| {
            if !dict.has(e.index) {
                w.missing.push(missing_line(&e, &why, dict));
            }
            let list = if rx { &mut w.rx } else { &mut w.tx };
            if !list.iter().any(|x| x.entry.index == e.index) {
                list.push(Want {
                    entry: e,
                    why: Some(why),
                });
            }
        };
        let opt = |w: &mut Wants, rx: bool, e: PdoEntry| {
            let list = if rx { &mut w.rx } else { &mut w.tx };
            if dict.has(e.index) && !list.iter().any(|x| x.entry.index == e.index) {
                list.push(Want {
                    entry: e,
                    why: None,
                });
            }
        };
        let base = who(POSITION_CONTROL);
        req(&mut w, true, CONTROLWORD, base.clone());
        req(&mut w, true, TARGET_POSITION, base.clone());
        // touch probes
        let probe_why = needs
            .marker_probe
            .as_ref()
            .or(needs.switch_probe.as_ref())
            .map(|s| who(s));
        match &probe_why {
            Some(why) => req(&mut w, true, TOUCH_PROBE_FUNCTION, why.clone()),
            None if dict.has(0x60B9) => opt(&mut w, true, TOUCH_PROBE_FUNCTION),
            None => {}
        }
        w.torque_limit(axis, needs, dict);
        let mode = needs.drive_homing.is_some() || mode_in_pdo;
        if mode {
            let why = match &needs.drive_homing {
                Some((_, why)) => who(why),
                None => format!("[[io]] mode_in_pdo = true (axis {axis})"),
            };
            req(&mut w, true, MODES_OF_OPERATION, why);
        }
        req(&mut w, false, STATUSWORD, base.clone());
        req(&mut w, false, POSITION_ACTUAL, base.clone());
        opt(&mut w, false, VELOCITY_ACTUAL);
        match &needs.torque_actual {
            Some(why) => req(&mut w, false, TORQUE_ACTUAL, who(why)),
            None => opt(&mut w, false, TORQUE_ACTUAL),
        }
        let inputs = needs
            .home_switch
            .as_ref()
            .map(|(_, why)| why)
            .or(needs.index_bit.as_ref().map(|(_, why)| why))
            .or(needs.limit_switches.as_ref());
        match inputs {
            Some(why) => req(&mut w, false, DIGITAL_INPUTS, who(why)),
            None => opt(&mut w, false, DIGITAL_INPUTS),
        }
        let probes: [(PdoEntry, Option<&String>); 5] = [
            (TOUCH_PROBE_STATUS, probe_why.as_ref()),
            (TOUCH_PROBE_1_POSITIVE, needs.marker_probe.as_ref()),
            (TOUCH_PROBE_1_NEGATIVE, None),
            (TOUCH_PROBE_2_POSITIVE, needs.switch_probe.as_ref()),
            (TOUCH_PROBE_2_NEGATIVE, needs.switch_probe.as_ref()),
        ];
        for (e, why) in probes {
            match why {
                Some(why) if e.index == 0x60B9 => req(&mut w, false, e, why.clone()),
                Some(why) => req(&mut w, false, e, who(why)),
                None if w.rx.iter().any(|x| x.entry.index == 0x60B8) => opt(&mut w, false, e),
                None => {}
            }
        }
        opt(&mut w, false, ERROR_CODE);
        if mode {
            let why = w.rx.last().and_then(|x| x.why.clone()).unwrap_or_default();
            req(&mut w, false, MODES_OF_OPERATION_DISPLAY, why);
        } else if !dict.has(0x6061) {
            // the mode is set and checked over SDO
            w.missing
                .push(missing_line(&MODES_OF_OPERATION_DISPLAY, &base, dict));
        }
        if !mode && !dict.has(0x6060) {
            w.missing
                .push(missing_line(&MODES_OF_OPERATION, &base, dict));
        }
        if dict.supports_mode(MODE_CSP) == Some(false) {
            w.missing.push(format!(
                "0x6502 supported drive modes lacks cyclic synchronous position (bit 7) — \
                 needed by {base}"
            ));
        }
        if let Some((plan, why)) = &needs.drive_homing {
            w.homing(axis, *plan, why, dict);
        }
        w
    }

    /// A torque limit: needed (0x60E0 and 0x60E1, or 0x6072) or optional.
    fn torque_limit(&mut self, axis: &str, needs: &AxisNeeds, dict: &Dictionary) {
        let per_direction = dict.has(0x60E0) && dict.has(0x60E1);
        let entries: &[PdoEntry] = if per_direction {
            &[POSITIVE_TORQUE_LIMIT, NEGATIVE_TORQUE_LIMIT]
        } else if dict.has(0x6072) {
            &[MAX_TORQUE]
        } else {
            &[]
        };
        let why = needs
            .torque_limit
            .as_ref()
            .map(|w| format!("axis {axis}: {w}"));
        if entries.is_empty() {
            if let Some(why) = why {
                let aborts: Vec<String> = [0x60E0, 0x60E1, 0x6072]
                    .iter()
                    .filter_map(|&i| dict.abort(i).map(|c| format!("{i:#06X}: {c:#010X}")))
                    .collect();
                self.missing.push(format!(
                    "missing a torque limit: 0x60E0 positive and 0x60E1 negative torque limit \
                     value, or 0x6072 max torque — limits the torque — needed by {why} (SDO \
                     aborts {})",
                    aborts.join(", ")
                ));
            }
            return;
        }
        for e in entries {
            self.rx.push(Want {
                entry: *e,
                why: why.clone(),
            });
        }
    }

    /// The drive's own homing: its objects, its method in 0x60E3, homing
    /// mode in 0x6502.
    fn homing(&mut self, axis: &str, plan: DriveHomingPlan, why: &str, dict: &Dictionary) {
        let why = format!("axis {axis}: {why}");
        for e in [
            HOMING_METHOD,
            HOMING_SPEED_SWITCH,
            HOMING_SPEED_ZERO,
            HOMING_ACCELERATION,
            HOME_OFFSET,
        ] {
            if !dict
                .present
                .iter()
                .any(|(p, _)| p.index == e.index && p.sub == e.sub)
            {
                self.missing.push(missing_line(&e, &why, dict));
            }
        }
        if dict.supports_mode(MODE_HOMING) == Some(false) {
            self.missing.push(format!(
                "0x6502 supported drive modes lacks homing mode (bit 5) — needed by {why}"
            ));
        }
        match &dict.homing_methods {
            Some(list) if !list.contains(&plan.method) => self.missing.push(format!(
                "homing method {} ({}) is not among the drive's 0x60E3 supported homing methods \
                 {list:?} — needed by {why}: set drive_homing_method to one of them, or home \
                 controller-side (drive_homing = false)",
                plan.method,
                motion_config::ethercat::homing::method_name(plan.method)
            )),
            _ => {}
        }
        self.drive_homing = Some(plan);
    }

    /// The required entries of one direction, with why.
    pub fn required(&self, rx: bool) -> impl Iterator<Item = &Want> {
        (if rx { &self.rx } else { &self.tx })
            .iter()
            .filter(|w| w.why.is_some())
    }

    /// What a candidate mapping (`entries` of one direction) lacks of the
    /// required ones: lines "0x60B8 touch probe function (… needed by …)".
    pub fn lacks(&self, rx: bool, entries: &[PdoEntry]) -> Vec<String> {
        self.required(rx)
            .filter(|w| !entries.iter().any(|e| e.index == w.entry.index))
            .map(|w| {
                format!(
                    "{} (needed by {})",
                    w.entry.label(),
                    w.why.as_deref().unwrap_or_default()
                )
            })
            .collect()
    }

    /// Entries of one direction the backend writes into a writable mapping:
    /// everything wanted (`all`) or only the required ones.
    pub fn entries(&self, rx: bool, all: bool) -> Vec<PdoEntry> {
        (if rx { &self.rx } else { &self.tx })
            .iter()
            .filter(|w| all || w.why.is_some())
            .map(|w| w.entry)
            .collect()
    }
}

/// What the layout in force leaves out that the backend could use: lines
/// for the start-up log ("unavailable: …"), none of them needed by the
/// axis (those were checked).
pub fn unavailable(layout: &PdoLayout, dict: &Dictionary) -> Vec<String> {
    let p = &layout.present;
    let mut out = Vec::new();
    let mut say = |absent: bool, what: &str| {
        if absent {
            out.push(format!("unavailable: {what}"));
        }
    };
    say(
        !p.velocity,
        "0x606C velocity actual value not in the process data: the velocity is derived from \
         the position each cycle",
    );
    say(
        !p.torque,
        "0x6077 torque actual value not in the process data: torque reads 0 (no torque homing)",
    );
    say(
        !p.digital_inputs,
        "0x60FD digital inputs not in the process data: no home switch, limit switch or index \
         input",
    );
    say(
        !p.touch_probes,
        "no touch probes (0x60B8/0x60B9..0x60BD) in the process data: no marker or switch latch",
    );
    say(
        p.torque_limit.is_none(),
        "no torque limit (0x60E0/0x60E1 or 0x6072) in the process data: the command's torque \
         limit is not applied",
    );
    say(
        !p.error_code,
        "0x603F error code not in the process data: a drive fault is reported without its code",
    );
    say(
        !dict.has(0x6065),
        "no 0x6065 following error window: the position error tolerance is not applied",
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dictionary::PROBED;

    /// A dictionary with every probed object but `without`.
    fn dict(without: &[u16]) -> Dictionary {
        let mut d = Dictionary::default();
        for e in PROBED {
            if without.contains(&e.index) {
                d.absent.push((e, 0x0602_0000));
            } else {
                // 0x6502: CSP (bit 7) and homing (bit 5)
                d.present
                    .push((e, if e.index == 0x6502 { 0xA0 } else { 0 }));
            }
        }
        d
    }

    fn needs_marker() -> AxisNeeds {
        AxisNeeds {
            marker_probe: Some("home_sequence = \"marker\" with marker_latch = true".into()),
            limit_switches: Some("limit switches".into()),
            ..AxisNeeds::default()
        }
    }

    #[test]
    fn a_drive_with_everything_maps_everything_useful() {
        let w = Wants::of("X", &needs_marker(), &dict(&[]), false);
        assert!(w.missing.is_empty(), "{:#?}", w.missing);
        let rx: Vec<u16> = w.entries(true, true).iter().map(|e| e.index).collect();
        assert_eq!(rx, [0x6040, 0x607A, 0x60B8, 0x60E0, 0x60E1]);
        let tx: Vec<u16> = w.entries(false, true).iter().map(|e| e.index).collect();
        assert_eq!(
            tx,
            [
                0x6041, 0x6064, 0x606C, 0x6077, 0x60FD, 0x60B9, 0x60BA, 0x60BB, 0x60BC, 0x60BD,
                0x603F
            ]
        );
        let req: Vec<u16> = w.entries(false, false).iter().map(|e| e.index).collect();
        assert_eq!(req, [0x6041, 0x6064, 0x60FD, 0x60B9, 0x60BA]);
    }

    #[test]
    fn every_missing_object_is_named_at_once_with_its_purpose_and_its_axis() {
        let n = AxisNeeds {
            torque_actual: Some("home_sequence = \"torque\"".into()),
            torque_limit: Some("home_sequence = \"torque\"".into()),
            ..needs_marker()
        };
        let d = dict(&[
            0x60B8, 0x60B9, 0x60BA, 0x60E0, 0x60E1, 0x6072, 0x6077, 0x60FD,
        ]);
        let w = Wants::of("X", &n, &d, false);
        let all = w.missing.join("\n");
        for want in [
            "missing 0x60B8 touch probe function — arms the touch probes — needed by axis X: \
             home_sequence = \"marker\" with marker_latch = true (SDO abort 0x06020000)",
            "missing 0x60B9 touch probe status",
            "missing 0x60BA touch probe 1 positive edge",
            "missing a torque limit: 0x60E0 positive and 0x60E1 negative torque limit value, or \
             0x6072 max torque",
            "missing 0x6077 torque actual value — reports the torque (hard-stop detection) — \
             needed by axis X: home_sequence = \"torque\"",
            "missing 0x60FD digital inputs",
        ] {
            assert!(all.contains(want), "no {want:?} in\n{all}");
        }
        assert_eq!(w.missing.len(), 6, "{all}");
        // 0x6072 alone is a torque limit
        let w = Wants::of("X", &n, &dict(&[0x60E0, 0x60E1]), false);
        assert!(w.missing.is_empty(), "{:#?}", w.missing);
        assert!(w
            .rx
            .iter()
            .any(|x| x.entry.index == 0x6072 && x.why.is_some()));
    }

    #[test]
    fn an_immediate_axis_needs_no_probe_and_no_inputs() {
        let n = AxisNeeds::default();
        let w = Wants::of(
            "X",
            &n,
            &dict(&[
                0x60B8, 0x60B9, 0x60BA, 0x60BB, 0x60BC, 0x60BD, 0x60FD, 0x6077, 0x606C,
            ]),
            false,
        );
        assert!(w.missing.is_empty(), "{:#?}", w.missing);
        let rx: Vec<u16> = w.entries(true, true).iter().map(|e| e.index).collect();
        assert_eq!(rx, [0x6040, 0x607A, 0x60E0, 0x60E1]);
    }

    #[test]
    fn drive_homing_needs_its_objects_the_mode_in_the_pdos_and_a_listed_method() {
        let plan = DriveHomingPlan {
            method: 19,
            speed_switch: 1000,
            speed_zero: 100,
            acceleration: 10_000,
        };
        let n = AxisNeeds {
            drive_homing: Some((
                plan,
                "drive_homing (method 19, home_sequence = \"switch\")".into(),
            )),
            ..AxisNeeds::default()
        };
        let mut d = dict(&[]);
        d.homing_methods = Some(vec![33, 34, 37]);
        let w = Wants::of("X", &n, &d, false);
        assert_eq!(w.missing.len(), 1, "{:#?}", w.missing);
        assert!(
            w.missing[0].starts_with(
                "homing method 19 (positive home switch) is not among the drive's 0x60E3 \
                 supported homing methods [33, 34, 37]"
            ),
            "{}",
            w.missing[0]
        );
        assert!(w
            .rx
            .iter()
            .any(|x| x.entry.index == 0x6060 && x.why.is_some()));
        assert!(w
            .tx
            .iter()
            .any(|x| x.entry.index == 0x6061 && x.why.is_some()));
        let w = Wants::of("X", &n, &dict(&[0x6098, 0x609A]), false);
        let all = w.missing.join("\n");
        assert!(
            all.contains("missing 0x6098 homing method") && all.contains("0x609A"),
            "{all}"
        );
    }

    #[test]
    fn what_a_candidate_mapping_lacks() {
        let w = Wants::of("X", &needs_marker(), &dict(&[]), false);
        let lacks = w.lacks(false, &[STATUSWORD, POSITION_ACTUAL, DIGITAL_INPUTS]);
        assert_eq!(
            lacks,
            [
                "0x60B9 touch probe status (needed by axis X: home_sequence = \"marker\" with \
                 marker_latch = true)",
                "0x60BA touch probe 1 positive edge (needed by axis X: home_sequence = \
                 \"marker\" with marker_latch = true)"
            ]
        );
    }
}
