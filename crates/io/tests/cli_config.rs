//! Command-line and config mistakes: exit 2, every mistake printed, nothing
//! created in /dev/shm.

use std::time::Duration;

use motion_harness::leftovers::clean_and_assert_empty;
use motion_harness::*;

/// A config with several independent mistakes.
const BAD: &str = r#"
[supervisor]
cycle_us = 5
io = "bogus"
io_watchdog_cycles = 0
colour = "blue"

[[axis]]
name = "X"
counts_per_unit = 1000.0
home_sequence = "marker"
home_speed = -3.0
home_direction = "sideways"

[axis.sim]
marker_every = -1.0
"#;

#[test]
fn config_with_several_mistakes_exits_2_and_prints_every_one() {
    let cfg = Machine::parse(BAD).write("iotest_bad");
    let prefix = cfg.prefix.clone();
    let _guard = DomainGuard(prefix.clone());
    let text = std::fs::read_to_string(&cfg.path).unwrap();
    let expected = motion_config::parse(&text).expect_err("the config has mistakes");
    assert!(expected.len() >= 5, "{expected:?}");
    let mut io = spawn_io(&["--config", cfg.arg()]);
    let st = io.wait_exit(Duration::from_secs(10)).expect("no exit");
    assert_eq!(st.code(), Some(2), "{}", io.stderr());
    let err = io.stderr();
    for p in &expected {
        let line = format!("motion-io: error: config: {p}");
        assert!(
            io.lines().iter().any(|(_, l)| *l == line),
            "missing {line:?} in\n{err}"
        );
    }
    assert_eq!(
        io.count("motion-io: error: config: "),
        expected.len(),
        "one line per problem:\n{err}"
    );
    println!("{} problems reported:\n{err}", expected.len());
    // nothing was created
    assert_eq!(shm_leftovers(&prefix), Vec::<String>::new());
    clean_and_assert_empty(None, &prefix);
}

#[test]
fn unreadable_config_file_exits_2() {
    let mut io = spawn_io(&["--config", "/nonexistent/motion-io.toml"]);
    let st = io.wait_exit(Duration::from_secs(10)).expect("no exit");
    assert_eq!(st.code(), Some(2));
    assert!(
        io.find("motion-io: error: config: file: cannot read /nonexistent/motion-io.toml")
            .is_some(),
        "{}",
        io.stderr()
    );
}

#[test]
fn command_line_mistakes_exit_2_with_usage() {
    for (args, needle) in [
        (
            &["--backend", "ethercab"][..],
            "invalid value 'ethercab' for '--backend",
        ),
        (&["--cpu"][..], "a value is required for '--cpu <N>'"),
        (&["--priority", "0"][..], "1..=99"),
        (&["--frobnicate"][..], "unexpected argument '--frobnicate'"),
        (&["stray"][..], "unrecognized subcommand 'stray'"),
        (&["--service-prefix", "../../tmp/x"][..], "service prefix"),
    ] {
        let mut io = spawn_io(args);
        let st = io.wait_exit(Duration::from_secs(10)).expect("no exit");
        assert_eq!(st.code(), Some(2), "{args:?}");
        let err = io.stderr();
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(err.contains("--help"), "{args:?}: {err}");
    }
    // --help is not a mistake
    let help = spawn_io(&["--help"]).finish();
    help.expect_code(0);
    assert!(help.stdout.contains("--exit-with-supervisor"));
}
