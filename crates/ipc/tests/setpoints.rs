//! The setpoint service in one process: created exclusively, at most eight
//! publishers, frames stamped with layout, session, key and an increasing
//! sequence, the drain bounded by the buffer, nothing left behind.

mod common;

use common::TestEnv;
use motion_frames::*;
use motion_ipc::setpoints::{MAX_SETPOINT_PUBLISHERS, SETPOINT_BUFFER};
use motion_ipc::*;

#[test]
fn frames_arrive_stamped_and_the_drain_is_bounded() {
    let env = TestEnv::new("sp");
    {
        let node = env.domain.create_node("motion-supervisor").unwrap();
        let mut sub = SetpointSubscriber::create(&node, &env.domain).unwrap();
        // exclusively: a second supervisor-side creation is refused
        let err = SetpointSubscriber::create(&node, &env.domain)
            .err()
            .expect("refused");
        assert!(matches!(err, IpcError::CreateTopic { .. }), "{err:?}");

        let prog = env.domain.create_node("program").unwrap();
        let mut publisher = SetpointPublisher::open(&prog, &env.domain).unwrap();
        sub.update_connections().unwrap();
        for k in 0..3u64 {
            let seq = publisher
                .publish(42, 1_000 * k, |axes| {
                    axes[0] = SetpointAxis {
                        axis: 1,
                        flags: SP_VELOCITY,
                        position: k as f64,
                        velocity: 0.5,
                    };
                    1
                })
                .unwrap();
            assert_eq!(seq, k + 1);
        }
        let mut got = Vec::new();
        assert_eq!(sub.drain(|f| got.push(*f)).unwrap(), 3);
        for (k, f) in got.iter().enumerate() {
            assert_eq!(f.check(env.domain.key), Ok(()));
            assert_eq!(
                (f.token, f.seq, f.t_ns, f.count),
                (42, k as u64 + 1, 1_000 * k as u64, 1)
            );
            assert_eq!(f.entries()[0].position, k as f64);
            assert_eq!(f.entries()[0].feed_forward(), Some(0.5));
        }
        // a flood: the buffer keeps the newest SETPOINT_BUFFER frames, one
        // drain takes at most that many
        for _ in 0..3 * SETPOINT_BUFFER {
            publisher.publish(42, 0, |_| 0).unwrap();
        }
        assert_eq!(sub.drain(|_| {}).unwrap(), SETPOINT_BUFFER);
        assert_eq!(sub.drain(|_| {}).unwrap(), 0);

        // eight programs at most
        let mut more = Vec::new();
        for _ in 1..MAX_SETPOINT_PUBLISHERS {
            more.push(SetpointPublisher::open(&prog, &env.domain).unwrap());
        }
        let err = SetpointPublisher::open(&prog, &env.domain)
            .err()
            .expect("a ninth publisher is refused");
        assert!(matches!(err, IpcError::CreatePublisher { .. }), "{err:?}");
    }
    env.assert_clean_and_remove();
}

#[test]
fn a_program_cannot_open_what_no_supervisor_created() {
    let env = TestEnv::new("spn");
    let node = env.domain.create_node("program").unwrap();
    let err = SetpointPublisher::open(&node, &env.domain)
        .err()
        .expect("no service");
    assert!(matches!(err, IpcError::OpenTopic { .. }), "{err:?}");
}
