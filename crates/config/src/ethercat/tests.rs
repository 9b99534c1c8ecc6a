//! The EtherCAT keys: the stop's bound, the home switch bit,
//! the brake, the drive's own homing, and what each axis needs of its drive.

use super::*;
use crate::{parse, Problem};

const BUS: &str = "[[io]]\nname = \"bus0\"\nbackend = \"ethercat\"\ninterface = \"eth1\"\n";

const AXIS: &str = "[[axis]]\nname = \"X\"\nethercat_position = 0\ncounts_per_unit = 1000.0\n\
                    home_speed = 2.0\nhome_return_speed = 0.5\nhome_acceleration = 100.0\n\
                    home_deceleration = 100.0\n";

fn axis(extra: &str) -> Result<crate::MachineConfig, Vec<Problem>> {
    parse(&format!("{BUS}{AXIS}{extra}"))
}

fn needs(extra: &str) -> AxisNeeds {
    let m = axis(extra).unwrap_or_else(|p| panic!("{p:#?}"));
    let (bus, _) = EthercatBus::for_io(&m, 0, None, None, None).unwrap();
    bus.axes[0].needs.clone()
}

fn problem(extra: &str, key: &str) -> String {
    let p = axis(extra).expect_err("a problem");
    p.iter()
        .find(|p| p.key == key)
        .unwrap_or_else(|| panic!("no problem with {key}: {p:#?}"))
        .message
        .clone()
}

#[test]
fn the_drive_homes_with_the_standard_method_of_its_sequence_or_the_given_one() {
    let m = axis("home_sequence = \"switch\"\ndrive_homing = true\n").unwrap();
    let a = &m.axes[0];
    assert!(a.engine.drive_homing);
    assert_eq!(a.ethercat.as_ref().unwrap().drive_homing_method, Some(19));
    let n = needs("home_sequence = \"switch_then_marker\"\nhome_direction = \"bidirectional_reverse\"\nmarker = true\ndrive_homing = true\n");
    let (plan, why) = n.drive_homing.unwrap();
    assert_eq!(
        plan,
        DriveHomingPlan {
            method: 5,
            speed_switch: 2000,
            speed_zero: 500,
            acceleration: 100_000
        }
    );
    assert!(why.contains("method 5"), "{why}");
    // the drive reads its switch and index itself: no probe, no input of ours
    assert_eq!(
        (n.home_switch, n.marker_probe, n.switch_probe),
        (None, None, None)
    );
    // a method given means drive homing
    let m = axis("home_sequence = \"switch\"\nhome_direction = \"unidirectional_forward\"\ndrive_homing_method = 20\n").unwrap();
    assert!(m.axes[0].engine.drive_homing);
    // torque: a torque limit caps the drive's own search
    let n = needs("home_sequence = \"torque\"\nhome_torque_level = 30.0\nhome_torque_threshold = 20.0\nhome_torque_time = 0.1\ndrive_homing_method = -1\n");
    assert!(n.torque_limit.is_some() && n.torque_actual.is_none());
}

#[test]
fn drive_homing_mistakes_are_named() {
    let e = problem(
        "home_sequence = \"torque\"\nhome_torque_level = 30.0\nhome_torque_threshold = 20.0\nhome_torque_time = 0.1\ndrive_homing = true\n",
        "drive_homing_method",
    );
    assert!(
        e.contains("no standard CiA 402 homing method") && e.contains("hard-stop"),
        "{e}"
    );
    let e = problem(
        "home_sequence = \"switch\"\nhome_direction = \"unidirectional_forward\"\ndrive_homing = true\n",
        "drive_homing_method",
    );
    assert!(e.contains("unidirectional_forward"), "{e}");
    let e = problem("drive_homing = true\n", "drive_homing");
    assert!(e.contains("immediate"), "{e}");
    let e = problem(
        "home_sequence = \"switch\"\ndrive_homing_method = 0\n",
        "drive_homing_method",
    );
    assert!(e.contains("not 0"), "{e}");
    let e = problem(
        "home_sequence = \"switch\"\ndrive_homing = false\ndrive_homing_method = 19\n",
        "drive_homing_method",
    );
    assert!(e.contains("unused"), "{e}");
    // only on an EtherCAT axis
    let p = parse("[[axis]]\nname = \"X\"\ndrive_homing = true\n").unwrap_err();
    assert!(
        p.iter()
            .any(|p| p.key == "drive_homing" && p.message.contains("EtherCAT")),
        "{p:#?}"
    );
}

#[test]
fn what_each_sequence_needs_of_its_drive() {
    // immediate: only the limit switches (a servo axis has them unless it
    // says otherwise)
    let n = needs("");
    assert!(n.limit_switches.is_some());
    assert_eq!(needs("limit_switches = false\n"), AxisNeeds::default());
    assert_eq!(
        AxisNeeds {
            limit_switches: None,
            ..n
        },
        AxisNeeds::default()
    );
    // a switch: the sampled input, bit 2 or the configured bit
    let n = needs("home_sequence = \"switch\"\n");
    assert_eq!(n.home_switch.as_ref().unwrap().0, 2);
    assert!(n.marker_probe.is_none() && n.switch_probe.is_none() && n.torque_actual.is_none());
    let n =
        needs("home_sequence = \"switch\"\nethercat_home_switch_bit = 20\nregistration = true\n");
    assert_eq!(n.home_switch.as_ref().unwrap().0, 20);
    assert_eq!(n.switch_probe.as_deref(), Some("registration = true"));
    // a marker: the touch probe, or the index bit without a latch
    let n = needs("home_sequence = \"marker\"\nmarker = true\n");
    assert!(n.marker_probe.unwrap().contains("marker_latch = true"));
    let n = needs("home_sequence = \"marker\"\nmarker = true\nmarker_latch = false\nethercat_index_pulse_bit = 17\n");
    assert_eq!((n.marker_probe, n.index_bit.map(|b| b.0)), (None, Some(17)));
    let e = problem(
        "home_sequence = \"marker\"\nmarker = true\nmarker_latch = false\n",
        "ethercat_index_pulse_bit",
    );
    assert!(e.starts_with("missing"), "{e}");
    // torque: torque actual and a limit
    let n = needs("home_sequence = \"torque\"\nhome_torque_level = 30.0\nhome_torque_threshold = 20.0\nhome_torque_time = 0.1\n");
    assert!(n.torque_actual.is_some() && n.torque_limit.is_some());
}

#[test]
fn the_stop_bound_and_the_brake() {
    let m = axis("ethercat_brake_delay_ms = 150\n").unwrap();
    assert_eq!(
        m.ios[0].ethercat.as_ref().unwrap().quick_stop_timeout_ms,
        500
    );
    assert_eq!(m.axes[0].ethercat.as_ref().unwrap().brake_delay_ms, 150);
    let m = parse(&format!("{BUS}quick_stop_timeout_ms = 200\n{AXIS}")).unwrap();
    assert_eq!(
        m.ios[0].ethercat.as_ref().unwrap().quick_stop_timeout_ms,
        200
    );
    let p = parse(&format!("{BUS}quick_stop_timeout_ms = 5\n{AXIS}")).unwrap_err();
    assert!(
        p.iter().any(|p| p.key == "io.quick_stop_timeout_ms"),
        "{p:#?}"
    );
    let e = problem(
        "ethercat_brake_delay_ms = 5000\n",
        "ethercat_brake_delay_ms",
    );
    assert!(e.contains("0..=2000"), "{e}");
}
