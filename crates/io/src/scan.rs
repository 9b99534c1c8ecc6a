//! `motion-io scan --interface IF [--json]`: the bus as it is, and a config
//! skeleton of it (`motion_ethercat::scan`). Exit 0 with the report; 1 when
//! the bus cannot be scanned (the message says why).

use std::time::Duration;

/// How long a scan may take.
const SCAN_TIMEOUT: Duration = Duration::from_secs(60);

pub fn run(interface: &str, json: bool) -> i32 {
    match motion_ethercat::scan::scan(interface, SCAN_TIMEOUT) {
        Ok(r) if json => {
            println!("{}", serde_json::to_string(&r).unwrap_or_default());
            0
        }
        Ok(r) => {
            print!("{}", r.text());
            0
        }
        Err(e) if json => {
            let v = serde_json::json!({"errors": [{
                "axis": null, "key": null, "err": null, "exerr": null,
                "message": format!("scan of {interface} failed: {e}"),
            }]});
            println!("{v}");
            1
        }
        Err(e) => {
            log::error!("scan of {interface} failed: {e}");
            1
        }
    }
}
