//! The panic hook in a real process (its own main thread, real stdout):
//! this binary runs itself once per case and reads what the case printed.
//! No test harness: libtest runs tests on threads of its own, not on `main`.

use std::process::Command;

use motion_report::{print_json, ErrorReport};

const CASE: &str = "MOTION_REPORT_PANIC_CASE";

fn case(name: &str) {
    match name {
        // A panic of the main thread with --json: one error object.
        "main" => {
            motion_report::panic::install_hook(true);
            panic!("boom \"quoted\"\nsecond line");
        }
        // Without --json: nothing on stdout.
        "text" => {
            motion_report::panic::install_hook(false);
            panic!("boom");
        }
        // A report is out already: no second object.
        "after_report" => {
            motion_report::panic::install_hook(true);
            print_json(&ErrorReport::message("the report"));
            panic!("boom");
        }
        // Another thread's panic is the main thread's to report.
        "thread" => {
            motion_report::panic::install_hook(true);
            let r = std::thread::Builder::new()
                .name("motion-rt".into())
                .spawn(|| panic!("in the cycle"))
                .unwrap()
                .join();
            assert!(r.is_err());
            print_json(&ErrorReport::message("the real-time thread panicked"));
            std::process::exit(1);
        }
        _ => unreachable!("{name}"),
    }
}

fn run(name: &str) -> (Option<i32>, String, String) {
    let out = Command::new(std::env::current_exe().unwrap())
        .env(CASE, name)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

fn one_report(stdout: &str) -> ErrorReport {
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 1, "exactly one JSON object: {stdout:?}");
    serde_json::from_str(lines[0]).unwrap_or_else(|e| panic!("{e}: {stdout:?}"))
}

fn main() {
    if let Ok(name) = std::env::var(CASE) {
        case(&name);
        return;
    }
    let (code, stdout, stderr) = run("main");
    assert_eq!(code, Some(101), "{stderr}");
    let r = one_report(&stdout);
    let m = &r.errors[0].message;
    assert!(
        m.starts_with("internal error: boom \"quoted\" second line (at ")
            && m.contains("panic_hook.rs:"),
        "{m}"
    );
    let e = &r.errors[0];
    assert!(e.axis.is_none() && e.key.is_none() && e.err.is_none() && e.exerr.is_none());
    // The previous (default) hook still writes to stderr.
    assert!(
        stderr.contains("panicked at") && stderr.contains("boom"),
        "{stderr}"
    );

    let (code, stdout, stderr) = run("text");
    assert_eq!(code, Some(101));
    assert_eq!(stdout, "");
    assert!(stderr.contains("boom"), "{stderr}");

    let (code, stdout, _) = run("after_report");
    assert_eq!(code, Some(101));
    assert_eq!(one_report(&stdout).errors[0].message, "the report");

    let (code, stdout, stderr) = run("thread");
    assert_eq!(code, Some(1), "{stderr}");
    assert_eq!(
        one_report(&stdout).errors[0].message,
        "the real-time thread panicked"
    );
    assert!(stderr.contains("in the cycle"), "{stderr}");

    println!("panic_hook: 4 passed, 0 failed");
}
