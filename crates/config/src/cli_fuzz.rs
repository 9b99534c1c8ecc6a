//! The argument-vector fuzz test of every binary (no input panics),
//! written once. Behind the `cli-fuzz` feature, which only the
//! binaries' dev-dependencies enable: the product never links proptest.

use clap::Parser;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::ffi::OsString;
use std::os::unix::ffi::OsStringExt;

#[rustfmt::skip]
const VALUES: &[&str] = &[
    "", "-", "--", "=", "0", "-1", "1", "99", "1e308", "-1e308", "nan", "inf", "-inf",
    "18446744073709551616", "0x10", "../../etc/passwd", "/dev/zero", "/tmp", "a/b",
    "\u{1b}[31m", "X", "all", "--help", "--version", "-h", "\u{0}",
];

/// Every flag and subcommand name of `c`, recursively.
fn words(c: &clap::Command, out: &mut Vec<String>) {
    for a in c.get_arguments() {
        out.extend(a.get_long().map(|l| format!("--{l}")));
        out.extend(a.get_short().map(|s| format!("-{s}")));
    }
    for s in c.get_subcommands() {
        out.push(s.get_name().to_string());
        words(s, out);
    }
}

/// Any argument vector — the real subcommands and flags in any order and
/// combination, hostile values, arbitrary and non-UTF-8 strings — is parsed
/// by `T` (as `program`) or refused, never a panic (clap's debug-build
/// checks of the definition included). Panics on the first failure.
pub fn any_argument_vector_is_parsed_or_refused<T: Parser + std::fmt::Debug>(program: &str) {
    let mut known = Vec::new();
    words(&T::command(), &mut known);
    assert!(known.len() > 3, "{known:?}");
    // Mostly behind a real subcommand, to get past the first word.
    let mut first: Vec<String> = T::command()
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    first.push(String::new());
    let token = prop_oneof![
        4 => prop::sample::select(known.clone()).prop_map(OsString::from),
        2 => prop::sample::select(VALUES).prop_map(OsString::from),
        1 => (prop::sample::select(known), prop::sample::select(VALUES))
            .prop_map(|(k, v)| OsString::from(format!("{k}={v}"))),
        1 => ".{0,16}".prop_map(OsString::from),
        1 => prop::collection::vec(any::<u8>(), 0..8).prop_map(OsString::from_vec),
    ];
    let mut runner = TestRunner::new(Config {
        cases: 512,
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(
            &(
                prop::sample::select(first),
                prop::collection::vec(token, 0..10),
            ),
            |(sub, args)| {
                let sub = (!sub.is_empty()).then(|| OsString::from(sub));
                let argv = std::iter::once(OsString::from(program))
                    .chain(sub)
                    .chain(args);
                match T::try_parse_from(argv) {
                    Ok(c) => drop(format!("{c:?}")),
                    Err(e) => drop(e.render().to_string()),
                }
                Ok(())
            },
        )
        .unwrap();
}
