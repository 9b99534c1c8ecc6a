//! A recorded homing as CSV (`motionctl trace --out FILE.csv`): one row per
//! cycle, the columns the plot and a spreadsheet need.

use crate::shared::TraceRecord;
use motion_homing::Phase;

pub const HEADER: &str = "t_s,phase,cmd_position,cmd_velocity,position,velocity,torque,switch,marker,fresh,event,event_raw,err,exerr\n";

fn phase_name(n: u8) -> &'static str {
    const ALL: [Phase; 11] = [
        Phase::Idle,
        Phase::Enabling,
        Phase::Seek,
        Phase::SeekStop,
        Phase::Release,
        Phase::Return,
        Phase::ReturnStop,
        Phase::MoveHome,
        Phase::Passive,
        Phase::Stopping,
        Phase::Creep,
    ];
    ALL.iter()
        .find(|p| **p as u8 == n)
        .map_or("?", |p| p.name())
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.6}")
    } else {
        String::new()
    }
}

/// The records as CSV text (header included).
pub fn csv(records: &[TraceRecord]) -> String {
    let mut s = String::with_capacity(HEADER.len() + records.len() * 96);
    s += HEADER;
    for r in records {
        s += &format!(
            "{:.6},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.t_ns as f64 * 1e-9,
            phase_name(r.phase),
            num(r.cmd_position),
            num(r.cmd_velocity),
            num(r.position),
            num(r.velocity),
            num(r.torque),
            u8::from(r.switch),
            u8::from(r.marker),
            u8::from(r.fresh),
            u8::from(r.event),
            if r.event {
                num(r.event_raw)
            } else {
                String::new()
            },
            r.err,
            r.exerr
        );
    }
    s
}
