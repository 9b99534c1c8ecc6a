//! What an axis's configuration needs of its drive ([`AxisNeeds`]), each
//! need with the configuration that makes it (for the start-up check's
//! messages: "0x60B8 touch probe function: latches the marker — axis X:
//! home_sequence = \"marker\" with marker_latch = true").
//!
//! | the axis | needs |
//! |---|---|
//! | immediate or absolute homing | nothing beyond the cyclic position objects |
//! | a switch sequence | the home switch input: 0x60FD bit 2, or `ethercat_home_switch_bit` |
//! | `registration = true` | touch probe 2 (0x60B8, 0x60B9, 0x60BC, 0x60BD) |
//! | a marker sequence, `marker_latch = true` | touch probe 1 (0x60B8, 0x60B9, 0x60BA) |
//! | a marker sequence, `marker_latch = false` | the index bit of 0x60FD (`ethercat_index_pulse_bit`) |
//! | a torque sequence | 0x6077 torque actual and a torque limit (0x60E0/0x60E1, or 0x6072) |
//! | limit switches | 0x60FD bits 0/1 |
//! | `drive_homing` | homing mode: 0x6098, 0x6099, 0x609A, 0x607C, 0x6060/0x6061 in the PDOs; its method listed in 0x60E3 |
//!
//! The drive's own homing replaces the controller-side needs of the
//! sequence (the drive reads its switch and index itself); a torque
//! sequence still needs a torque limit, which caps the drive's hard-stop
//! search at `home_torque_level`.

use motion_homing::{AxisConfig, AxisConfiguration, HomeMode, HomeSequence};

use super::AxisEthercat;

/// The parameters of the drive's own homing (CiA 402 mode 6), in the
/// drive's units (counts, counts/s, counts/s²).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DriveHomingPlan {
    /// 0x6098.
    pub method: i8,
    /// 0x6099:01 speed during the search for the switch (`home_speed`).
    pub speed_switch: u32,
    /// 0x6099:02 speed during the search for zero (`home_return_speed`,
    /// else `home_speed`).
    pub speed_zero: u32,
    /// 0x609A (`home_acceleration`).
    pub acceleration: u32,
}

/// What an axis needs of its drive; each `Some` holds why (the axis's
/// configuration, in its keys' words).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AxisNeeds {
    /// Touch probe 1 on the encoder index: the marker latch.
    pub marker_probe: Option<String>,
    /// Touch probe 2 on its input: the home switch edge latched
    /// (registration).
    pub switch_probe: Option<String>,
    /// The home switch input, sampled: bit of 0x60FD (2, or a manufacturer
    /// bit).
    pub home_switch: Option<(u8, String)>,
    /// The index pulse, sampled: manufacturer bit of 0x60FD.
    pub index_bit: Option<(u8, String)>,
    /// The limit switches, 0x60FD bits 0/1.
    pub limit_switches: Option<String>,
    /// The torque actual value (0x6077).
    pub torque_actual: Option<String>,
    /// A torque limit (0x60E0/0x60E1 or 0x6072).
    pub torque_limit: Option<String>,
    /// The drive homes by itself.
    pub drive_homing: Option<(DriveHomingPlan, String)>,
    /// At the end of a stop the drive closes its holding brake: disable
    /// operation, this long with the power stage on, then disable voltage
    /// (`ethercat_brake_delay_ms`; 0 = no brake).
    pub brake_delay_ms: u32,
}

/// The axis has overtravel limit switches: a servo axis unless it says
/// `limit_switches = false` (then its drive need not report 0x60FD bits
/// 0/1, and the engine ignores them).
fn has_limit_switches(engine: &AxisConfig) -> bool {
    engine.configuration == AxisConfiguration::Servo && engine.limit_switches
}

fn counts(x: f64, counts_per_unit: f64) -> u32 {
    (x * counts_per_unit)
        .round()
        .clamp(0.0, f64::from(u32::MAX)) as u32
}

impl AxisNeeds {
    /// The needs of an axis configured as `engine` with the EtherCAT keys
    /// `keys`.
    pub fn of(engine: &AxisConfig, keys: &AxisEthercat) -> AxisNeeds {
        let seq = engine.home_sequence;
        let sequence = format!("home_sequence = {:?}", seq.name());
        let homes = seq != HomeSequence::Immediate && engine.home_mode != HomeMode::Absolute;
        let mut n = AxisNeeds {
            limit_switches: has_limit_switches(engine)
                .then(|| "limit switches (an axis has them unless it says otherwise)".into()),
            brake_delay_ms: keys.brake_delay_ms,
            ..AxisNeeds::default()
        };
        // `registration` says the drive latches the home switch: `arm`
        // takes that latch whatever the axis homes with.
        if engine.registration && !seq.uses_limit_switch() {
            n.switch_probe = Some("registration = true".into());
        }
        if !homes {
            return n;
        }
        if let Some(method) = keys.drive_homing_method {
            let cpu = engine.counts_per_unit;
            let zero = if engine.home_return_speed > 0.0 {
                engine.home_return_speed
            } else {
                engine.home_speed
            };
            let plan = DriveHomingPlan {
                method,
                speed_switch: counts(engine.home_speed, cpu),
                speed_zero: counts(zero, cpu),
                acceleration: counts(engine.home_acceleration, cpu),
            };
            n.drive_homing = Some((plan, format!("drive_homing (method {method}, {sequence})")));
            if seq.uses_torque() {
                n.torque_limit = Some(format!(
                    "{sequence} homed by the drive: home_torque_level caps its search"
                ));
            }
            return n;
        }
        if seq.uses_switch() {
            let (bit, how) = match keys.home_switch_bit {
                Some(b) => (b, format!(" (ethercat_home_switch_bit = {b})")),
                None => (2, String::new()),
            };
            n.home_switch = Some((bit, format!("{sequence}{how}")));
            if engine.registration {
                n.switch_probe = Some("registration = true".into());
            }
        }
        if seq.uses_marker() {
            if engine.marker_latch {
                n.marker_probe = Some(format!("{sequence} with marker_latch = true"));
            } else if let Some(b) = keys.index_pulse_bit {
                n.index_bit = Some((
                    b,
                    format!(
                        "{sequence} with marker_latch = false (ethercat_index_pulse_bit = {b})"
                    ),
                ));
            }
        }
        if seq.uses_torque() && engine.home_mode == HomeMode::Active {
            n.torque_actual = Some(sequence.clone());
            n.torque_limit = Some(sequence);
        }
        n
    }
}
