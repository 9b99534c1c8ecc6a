//! `gear SLAVE --master MASTER --ratio R [--actual] [--clutch A] [--json]`
//! (MAG; the flags are the engine's `GearSpec`, `spec_args.rs`): returns
//! once the gear is accepted — the gearing runs until `stop` or `disable`
//! of either axis, or a fault of either, ends it (`status` shows
//! `gearing`); exit 1 with the reason when refused.

use super::moves::op_error;
use super::EXIT_OK;
use crate::cli::GearArgs;
use motion_control::*;
use motion_report::{print_json, AcceptedReport};

pub fn gear(client: &mut Client, a: &GearArgs) -> i32 {
    let op = Operation::Gear(a.spec.spec);
    let resp = match client.operate(std::slice::from_ref(&a.slave), op) {
        Ok(r) => r,
        Err(e) => return op_error(a.json, "gear", &e),
    };
    let names: Vec<String> = resp.answers().iter().map(|x| get_str(&x.name)).collect();
    if a.json {
        print_json(&AcceptedReport { accepted: names });
    } else {
        let master = a.spec.spec.master.name().unwrap_or("?").to_string();
        println!("gear: {} follows {master}", names.join(" "));
    }
    EXIT_OK
}
