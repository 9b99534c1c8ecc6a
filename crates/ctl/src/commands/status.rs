use super::{client_error, signal_code, EXIT_OK};
use crate::cli::StatusArgs;
use motion_control::Client;
use motion_report::{print_json, table};
use std::io::{IsTerminal, Write};
use std::time::Duration;

/// `status [--json] [--watch]`: the status service's newest frame.
pub fn status(client: &mut Client, a: &StatusArgs) -> i32 {
    let tty = std::io::stdout().is_terminal();
    let mut last = String::new();
    loop {
        let st = match client.status(Duration::from_secs(2)) {
            Ok(s) => s,
            Err(e) => return client_error(a.json, &e),
        };
        let report = st.to_report();
        if a.json {
            print_json(&report);
        } else {
            let text = table::status(&report);
            if !a.watch {
                print!("{text}");
            } else if tty {
                // Redraw in place: home the cursor, clear the screen.
                print!("\x1b[H\x1b[2J{text}");
            } else if text != last {
                // A log: only what changed (cycle counters aside).
                println!("uptime {:.1} s", report.uptime_ms as f64 / 1000.0);
                print!("{text}");
            }
            last = text;
        }
        let _ = std::io::stdout().flush();
        if !a.watch {
            return EXIT_OK;
        }
        if let Some(code) = signal_code() {
            return code;
        }
        std::thread::sleep(Duration::from_millis(100));
        if let Some(code) = signal_code() {
            return code;
        }
    }
}
