//! `exchange` (motion-io's side) and the bus thread's cycle make no
//! system-allocator call after warm-up (root; skipped otherwise). The
//! binary installs motion-rt's counting allocator, as motion-io would.

use std::time::{Duration, Instant};

use ecat_emu::{DriveConfig, Emulator, EmulatorConfig, VethPair};
use motion_config::ethercat::BusAxis;
use motion_config::EthercatBus;
use motion_ethercat::EthercatBackend;
use motion_frames::backend::Backend;
use motion_frames::{CommandFrame, FeedbackFrame, CW_ENABLE, SW_ENABLED};

#[global_allocator]
static A: motion_rt::RtAllocator = motion_rt::RtAllocator;

#[test]
fn exchange_and_bus_cycle_do_not_allocate() {
    let Some(pair) = VethPair::or_skip() else {
        return;
    };
    let _emu = Emulator::start(EmulatorConfig {
        interface: pair.subdevice.clone(),
        netns: Some(pair.netns.clone()),
        drives: vec![DriveConfig::new("EMU-0"), DriveConfig::new("EMU-1")],
        priority: Some(60),
    })
    .unwrap();
    let axes = (0..2).map(|i| BusAxis::at(&format!("A{i}"), i)).collect();
    let mut b = EthercatBackend::new(EthercatBus::new(&pair.master, 1000, axes)).expect("start-up");
    let mut cmd = CommandFrame::ZERO;
    cmd.header.axis_count = 2;
    let mut fb = FeedbackFrame::ZERO;
    for a in &mut cmd.axes[..2] {
        a.control_word = CW_ENABLE;
        a.torque_limit_positive = 100.0;
        a.torque_limit_negative = 100.0;
    }
    let mut total = 0;
    let mut next = Instant::now();
    for k in 0..2000i64 {
        next += Duration::from_millis(1);
        if let Some(d) = next.checked_duration_since(Instant::now()) {
            std::thread::sleep(d);
        }
        if fb.axes[0].status_word & SW_ENABLED != 0 {
            cmd.axes[0].target_position = k * 5;
            cmd.axes[0].marker_arm_id = 1 + (k / 500) as u8;
        }
        let ((), n) = motion_rt::counting::system_calls_during(|| {
            b.exchange(&cmd, &mut fb).unwrap();
        });
        if k >= 100 {
            total += n;
        }
    }
    // the counter counts in this binary
    let (_v, n) = motion_rt::counting::system_calls_during(|| vec![1u8; 64]);
    assert!(n > 0, "counting allocator not active");
    let st = b.bus_status();
    eprintln!(
        "exchange: {total} system-allocator calls in 1900 cycles; bus thread: {} after warm-up; \
         round trip {}",
        st.bus_thread_allocations, st.roundtrip
    );
    assert_eq!(total, 0, "exchange allocated");
    assert_eq!(st.bus_thread_allocations, 0, "the bus cycle allocated");
}
