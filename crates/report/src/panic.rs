//! A panic with `--json` (README: "with --json every failure is one JSON
//! object"): besides the usual message on stderr, the tool prints
//! `{"errors":[{..., "message": "internal error: ..."}]}` on stdout, once,
//! and only if it has not printed a JSON object yet (a report already
//! printed stays the one object; a second would break every reader).
//!
//! Only a panic of the main thread is reported so: it ends the process
//! (no tool catches one there). A panic of another thread is the main
//! thread's to report (the supervisor's real-time thread catches its own and
//! the main thread prints the failure as any other), and printing it here
//! too would make two objects.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::ErrorReport;

/// Set by the first JSON object this process prints on stdout.
static JSON_PRINTED: AtomicBool = AtomicBool::new(false);

/// Notes that a JSON object is (being) printed on stdout.
pub(crate) fn note_json_printed() {
    JSON_PRINTED.store(true, Ordering::Release);
}

/// Installs the panic hook of a tool: the hook in place until now (the
/// default one, or the tool's own logging hook) writes to stderr as before;
/// then, with `json` and on the main thread, the error object goes to stdout
/// unless a JSON object was printed already.
pub fn install_hook(json: bool) {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        previous(info);
        if json && std::thread::current().name() == Some("main") {
            let message = message(info.payload(), info.location());
            // Never panic in here (stdout may be a closed pipe): ignore errors.
            let _ = write_report(&JSON_PRINTED, &mut std::io::stdout(), &message);
        }
    }));
}

/// `internal error: <payload> (at file:line:column)`, on one line.
fn message(
    payload: &(dyn std::any::Any + Send),
    location: Option<&std::panic::Location<'_>>,
) -> String {
    let what = payload
        .downcast_ref::<&str>()
        .copied()
        .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("a panic without a message");
    let what = what.split_whitespace().collect::<Vec<_>>().join(" ");
    match location {
        Some(l) => format!(
            "internal error: {what} (at {}:{}:{})",
            l.file(),
            l.line(),
            l.column()
        ),
        None => format!("internal error: {what}"),
    }
}

/// Writes the error object for `message` to `out` unless `printed` says a
/// JSON object is out already; true if it wrote.
fn write_report(
    printed: &AtomicBool,
    out: &mut impl Write,
    message: &str,
) -> std::io::Result<bool> {
    if printed.swap(true, Ordering::AcqRel) {
        return Ok(false);
    }
    let text = serde_json::to_string(&ErrorReport::message(message))?;
    writeln!(out, "{text}")?;
    out.flush()?;
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_error_object_in_the_shape_of_every_other() {
        let printed = AtomicBool::new(false);
        let mut out = Vec::new();
        let loc = std::panic::Location::caller();
        let payload: Box<dyn std::any::Any + Send> = Box::new(String::from("boom\n  at once"));
        let m = message(payload.as_ref(), Some(loc));
        assert!(m.starts_with("internal error: boom at once (at "), "{m}");
        assert!(write_report(&printed, &mut out, &m).unwrap());
        // Once only.
        assert!(!write_report(&printed, &mut out, "internal error: again").unwrap());
        let text = String::from_utf8(out).unwrap();
        assert_eq!(text.lines().count(), 1, "{text}");
        let r: ErrorReport = serde_json::from_str(&text).unwrap();
        assert_eq!(r, ErrorReport::message(m));
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(
            v["errors"][0],
            serde_json::json!({"axis": null, "key": null, "err": null, "exerr": null,
                               "message": r.errors[0].message})
        );
    }

    #[test]
    fn nothing_after_a_json_object_was_printed() {
        let printed = AtomicBool::new(true);
        let mut out = Vec::new();
        assert!(!write_report(&printed, &mut out, "internal error: x").unwrap());
        assert!(out.is_empty());
    }

    #[test]
    fn a_payload_that_is_not_text() {
        let payload: Box<dyn std::any::Any + Send> = Box::new(42u8);
        assert_eq!(
            message(payload.as_ref(), None),
            "internal error: a panic without a message"
        );
    }
}
