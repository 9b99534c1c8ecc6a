//! The emulated drive, unit by unit: mapping rules, state machine, CSP,
//! latches, quick stop, faults, watchdog loss.

use super::*;
use crate::od::abort;
use motion_plant::Plant;

fn drive() -> Drive {
    let mut cfg = DriveConfig::new("EMU");
    cfg.plant.marker_every = 10.0;
    cfg.plant.marker_at = 2.5;
    cfg.plant.switch = Some((5.0, 8.0));
    let mut d = Drive::new(cfg);
    // map like the backend does
    let rx = [
        0x6040_0010u32,
        0x607A_0020,
        0x60B8_0010,
        0x60E0_0010,
        0x60E1_0010,
    ];
    let tx = [
        0x6041_0010u32,
        0x6064_0020,
        0x606C_0020,
        0x6077_0010,
        0x60FD_0020,
        0x60B9_0010,
        0x60BA_0020,
        0x60BB_0020,
        0x60BC_0020,
        0x60BD_0020,
        0x603F_0010,
    ];
    for (idx, list) in [(0x1600u16, &rx[..]), (0x1A00, &tx[..])] {
        d.sdo_download(idx, 0, &[0], true).unwrap();
        for (i, m) in list.iter().enumerate() {
            d.sdo_download(idx, i as u8 + 1, &m.to_le_bytes(), true)
                .unwrap();
        }
        d.sdo_download(idx, 0, &[list.len() as u8], true).unwrap();
    }
    d.sdo_download(0x6060, 0, &[8], true).unwrap();
    d
}

fn out(cw: u16, target: i32, tp: u16) -> Vec<u8> {
    let mut v = Vec::new();
    v.extend_from_slice(&cw.to_le_bytes());
    v.extend_from_slice(&target.to_le_bytes());
    v.extend_from_slice(&tp.to_le_bytes());
    v.extend_from_slice(&1000u16.to_le_bytes());
    v.extend_from_slice(&1000u16.to_le_bytes());
    v
}

fn run(d: &mut Drive, cw: u16, target: i32, tp: u16) -> DriveView {
    d.apply_outputs(&out(cw, target, tp));
    d.cycle(true);
    d.view()
}

fn enable(d: &mut Drive) {
    for cw in [0x0000, 0x0006, 0x0007, 0x000F, 0x000F] {
        run(d, cw, 0, 0);
    }
    assert_eq!(d.view().state, State::OperationEnabled);
}

#[test]
fn mapping_rules() {
    let mut d = drive();
    assert_eq!(d.rx_bytes(), 12);
    assert_eq!(d.tx_bytes(), 36);
    // sub 0 must be 0 before entries change
    assert_eq!(
        d.sdo_download(0x1600, 1, &0x6040_0010u32.to_le_bytes(), true),
        Err(abort::SUBINDEX0_MUST_BE_ZERO)
    );
    // mapping changes only in PRE-OP
    assert_eq!(d.sdo_download(0x1600, 0, &[0], false), Err(abort::STATE));
    d.sdo_download(0x1600, 0, &[0], true).unwrap();
    // an input object in the RxPDO cannot be mapped
    assert_eq!(
        d.sdo_download(0x1600, 1, &0x6041_0010u32.to_le_bytes(), true),
        Err(abort::CANNOT_MAP)
    );
    // a missing object is named as such
    let mut cfg = DriveConfig::new("NOTP");
    cfg.touch_probe = false;
    let mut n = Drive::new(cfg);
    n.sdo_download(0x1600, 0, &[0], true).unwrap();
    assert_eq!(
        n.sdo_download(0x1600, 3, &0x60B8_0010u32.to_le_bytes(), true),
        Err(abort::OBJECT_NOT_FOUND)
    );
    assert_eq!(n.od.upload(0x60B8, 0), Err(abort::OBJECT_NOT_FOUND));
    // modes and sync types
    assert_eq!(
        d.sdo_download(0x6060, 0, &[1], true),
        Err(abort::VALUE_RANGE)
    );
    assert_eq!(d.od.get(0x6061, 0), 8);
    d.sdo_download(0x1C32, 1, &2u16.to_le_bytes(), true)
        .unwrap();
    let mut cfg = DriveConfig::new("NODC");
    cfg.dc = false;
    let mut n = Drive::new(cfg);
    assert_eq!(
        n.sdo_download(0x1C32, 1, &2u16.to_le_bytes(), true),
        Err(abort::VALUE_RANGE)
    );
    assert_eq!(n.od.get(0x1C32, 4), 0x0003);
}

#[test]
fn state_machine_follow_and_latch() {
    let mut d = drive();
    assert_eq!(d.view().state, State::NotReadyToSwitchOn);
    enable(&mut d);
    assert_eq!(d.view().statusword, 0x1237);
    // CSP: the plant follows the target at once (1000 counts/unit)
    let v = run(&mut d, 0x000F, 1500, 0);
    assert_eq!(v.position, 1.5);
    let mut buf = vec![0u8; d.tx_bytes()];
    d.fill_inputs(&mut buf);
    assert_eq!(i32::from_le_bytes(buf[2..6].try_into().unwrap()), 1500);
    // arm probe 1 (index, rising) and probe 2 (input, rising)
    run(&mut d, 0x000F, 1500, 0x1115);
    let v = run(&mut d, 0x000F, 3000, 0x1115);
    assert_eq!(
        v.touch_probe_status & 0x0303,
        0x0103,
        "{:#06x}",
        v.touch_probe_status
    );
    assert_eq!(d.od.get_signed(0x60BA, 0), 2500);
    let v = run(&mut d, 0x000F, 6000, 0x1115);
    assert_eq!(v.touch_probe_status & 0x0303, 0x0303);
    assert_eq!(d.od.get_signed(0x60BC, 0), 5000);
    // re-arm by toggling: stored bits clear, nothing new until an edge
    run(&mut d, 0x000F, 6000, 0x0000);
    let v = run(&mut d, 0x000F, 6000, 0x0015);
    assert_eq!(v.touch_probe_status, 0x0001);
    // torque limits per mille → %
    assert_eq!(v.torque_limit_positive, 100.0);
}

#[test]
fn quick_stop_ramps_then_switch_on_disabled() {
    let mut d = drive();
    enable(&mut d);
    // moving at 10 units/s: 10 counts per 1 ms cycle
    let mut t = 0;
    for _ in 0..100 {
        t += 10;
        run(&mut d, 0x000F, t, 0);
    }
    let v = run(&mut d, 0x0002, t, 0);
    assert_eq!(v.state, State::QuickStopActive);
    let mut n = 0;
    while d.view().state == State::QuickStopActive {
        run(&mut d, 0x0002, t, 0);
        n += 1;
        assert!(n < 1000);
    }
    // 10 units/s at 1000 units/s²: ~10 cycles
    assert!((8..=12).contains(&n), "{n}");
    assert_eq!(d.view().state, State::SwitchOnDisabled);
    assert_eq!(d.view().velocity, 0.0);
}

#[test]
fn faults_and_reset() {
    let mut d = drive();
    enable(&mut d);
    d.inject_fault(0x2310);
    let v = run(&mut d, 0x000F, 0, 0);
    assert_eq!(v.state, State::Fault);
    assert_eq!(v.error_code, 0x2310);
    assert!(!v.enabled);
    // no edge: stays
    let v = run(&mut d, 0x0000, 0, 0);
    assert_eq!(v.state, State::Fault);
    let v = run(&mut d, 0x0080, 0, 0);
    assert_eq!(v.state, State::SwitchOnDisabled);
    assert_eq!(v.error_code, 0);
    enable(&mut d);

    // following error: tolerance window 100 counts, jump 1000 counts
    d.sdo_download(0x6065, 0, &100u32.to_le_bytes(), false)
        .unwrap();
    let mut cfg = d.cfg.clone();
    cfg.plant.hard_stop = Some((-1.0, 0.5));
    let mut d2 = drive();
    d2.cfg = cfg.clone();
    d2.plant = Plant::new(cfg.plant);
    enable(&mut d2);
    d2.sdo_download(0x6065, 0, &100u32.to_le_bytes(), false)
        .unwrap();
    let v = run(&mut d2, 0x000F, 1000, 0);
    assert_eq!(v.state, State::Fault);
    assert_eq!(v.error_code, ERR_FOLLOWING);
    assert_eq!(v.statusword & 0x2000, 0x2000);
}

/// 0x60FD bits 0 / 1 are the plant's limit switches (as states, whatever
/// the wiring); a cut common wire of NC switches reads both actuated and
/// faults the drive with a wiring code, also when it is enabled again.
#[test]
fn limit_switches_in_0x60fd_and_an_nc_wire_break() {
    let mut d = drive();
    let mut cfg = d.cfg.clone();
    cfg.plant.overtravel = Some((-4.0, 4.0));
    cfg.plant.limit_switches_normally_closed = true;
    d.cfg = cfg.clone();
    d.plant = Plant::new(cfg.plant);
    enable(&mut d);
    let di = |d: &Drive| d.od.get(0x60FD, 0) & 0b11;
    run(&mut d, 0x000F, -4000, 0);
    assert_eq!(di(&d), 0b01, "negative limit at -4");
    run(&mut d, 0x000F, 4000, 0);
    assert_eq!(di(&d), 0b10, "positive limit at 4");
    run(&mut d, 0x000F, 0, 0);
    assert_eq!(di(&d), 0);
    d.plant.break_limit_wire();
    let v = run(&mut d, 0x000F, 0, 0);
    assert_eq!(di(&d), 0b11);
    assert_eq!((v.state, v.error_code), (State::Fault, ERR_LIMIT_WIRING));
    run(&mut d, 0x0080, 0, 0);
    for cw in [0x0006, 0x0007, 0x000F, 0x000F] {
        run(&mut d, cw, 0, 0);
    }
    let v = d.view();
    assert_eq!((v.state, v.error_code), (State::Fault, ERR_LIMIT_WIRING));
}

#[test]
fn watchdog_loss_ramps_then_faults() {
    let mut d = drive();
    enable(&mut d);
    let mut t = 0;
    for _ in 0..50 {
        t += 20;
        run(&mut d, 0x000F, t, 0);
    }
    d.outputs_lost(true);
    assert_eq!(d.view().state, State::FaultReactionActive);
    let mut n = 0;
    while d.ramping() {
        d.tick();
        n += 1;
        assert!(n < 1000);
    }
    let v = d.view();
    assert_eq!(v.state, State::Fault);
    assert_eq!(v.error_code, ERR_COMMUNICATION);
    assert_eq!(v.velocity, 0.0);
    assert!(v.position > 1.0);
}
