//! `arm AXIS [--input switch|marker] [--edge rising|falling] [--window LO
//! HI] [--no-wait] [--json]` (MAR; the flags are the engine's `ArmSpec`,
//! `spec_args.rs`) and `disarm AXIS` (MDR): `arm` waits until the edge is
//! latched and prints its axis position; exit 0 only then. Ctrl-C (or
//! SIGTERM) disarms it.

use super::moves::op_error;
use super::{client_error, fail, signal_code, EXIT_FAILED, EXIT_OK};
use crate::cli::ArmArgs;
use motion_control::*;
use motion_report::{print_json, AcceptedReport, ErrorEntry, RegistrationReport, RegistrationRow};
use std::time::Duration;

pub fn arm(client: &mut Client, a: &ArmArgs) -> i32 {
    let axes = std::slice::from_ref(&a.axis);
    let resp = match client.operate(axes, Operation::Arm(a.spec.spec)) {
        Ok(r) => r,
        Err(e) => return op_error(a.json, "arm", &e),
    };
    let Some(index) = resp.answers().first().map(|x| x.index as usize) else {
        return EXIT_FAILED;
    };
    if a.no_wait {
        if a.json {
            print_json(&AcceptedReport {
                accepted: vec![a.axis.clone()],
            });
        } else {
            println!("armed: {}", a.axis);
        }
        return EXIT_OK;
    }
    let position = match wait_latched(client, index, resp.cycle) {
        Ok(p) => p,
        Err(e) => return client_error(a.json, &e),
    };
    if let Some(code) = signal_code() {
        // Interrupted: nothing is left armed behind us.
        let _ = client.operate(axes, Operation::Disarm);
        return code;
    }
    let Some(position) = position else {
        let e = ErrorEntry::message(format!(
            "{}: the registration was disarmed before an edge was latched",
            a.axis
        ));
        return fail(a.json, vec![e], EXIT_FAILED);
    };
    if a.json {
        print_json(&RegistrationReport {
            axes: vec![RegistrationRow {
                name: a.axis.clone(),
                position: Some(position),
            }],
        });
    } else {
        println!("{}: latched at {position}", a.axis);
    }
    EXIT_OK
}

/// Follows axis `index` from the status frame after `after_cycle` until its
/// registration is no longer armed (or a signal came): its latched
/// position (`None`: disarmed without one, or interrupted).
fn wait_latched(
    client: &mut Client,
    index: usize,
    after_cycle: u64,
) -> Result<Option<f64>, ClientError> {
    loop {
        let st = client.status(Duration::from_secs(2))?;
        if st.cycle > after_cycle {
            if let Some(e) = st.axes().get(index) {
                if !e.registration_armed() {
                    return Ok(e.registration_position());
                }
            }
        }
        if signal_code().is_some() {
            return Ok(None);
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}
