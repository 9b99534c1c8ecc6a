//! Reading `[opcua]` and its `[[opcua.user]]` tables (keys declared in
//! [`crate::keytable::opcua`]) into [`super::OpcuaConfig`].

use super::{
    check_phc, split_endpoint, OpcuaConfig, Policy, Unit, User, ANONYMOUS, DEFAULT_POLICIES, ROLES,
};
use crate::keys::Reader;
use crate::keytable::{opcua::*, Section};
use crate::{names, AxisEntry, Problem};
use std::path::Path;

/// Reads `[opcua]` (`None`: the section is absent; every key defaults).
/// `axes` are the machine's, for `units`; `state_dir` the default home of
/// `pki_dir`.
pub(crate) fn parse(
    table: Option<&toml::Table>,
    axes: &[AxisEntry],
    state_dir: &Path,
    problems: &mut Vec<Problem>,
) -> OpcuaConfig {
    let empty = toml::Table::new();
    let mut r = Reader::new(table.unwrap_or(&empty), None, Section::Opcua, problems);
    let endpoint = r.string(&ENDPOINT);
    let (host, port, path) = match split_endpoint(&endpoint) {
        Ok(x) => x,
        Err(e) => {
            r.problem(&ENDPOINT, e);
            ("127.0.0.1".into(), 4840, "/".into())
        }
    };
    let anonymous = r.choice(&ANONYMOUS_ACCESS, ANONYMOUS);
    let policies = policies(&mut r);
    if policies.contains(&Policy::None) && !anonymous {
        r.problem(
            &POLICIES,
            "\"None\" is offered read-only, to anonymous sessions only: it needs \
             anonymous = \"read\""
                .into(),
        );
    }
    let pki_dir = if r.has(&PKI_DIR) {
        r.directory(&PKI_DIR)
    } else {
        state_dir.join("opcua")
    };
    let units = units(&mut r, axes);
    let user_tables = r.array_of_tables(&USER);
    r.finish();
    let users = users(&user_tables, problems);
    OpcuaConfig {
        endpoint,
        host,
        port,
        path,
        anonymous,
        policies,
        users,
        pki_dir,
        units,
    }
}

fn policies(r: &mut Reader) -> Vec<Policy> {
    let Some(value) = r.value(&POLICIES) else {
        return DEFAULT_POLICIES.to_vec();
    };
    let Some(list) = value
        .as_array()
        .and_then(|a| a.iter().map(|v| v.as_str()).collect::<Option<Vec<_>>>())
    else {
        r.problem(&POLICIES, "expected a list of policy names".into());
        return DEFAULT_POLICIES.to_vec();
    };
    let mut out = Vec::new();
    for s in list {
        match Policy::NAMES.iter().find(|(n, _)| *n == s) {
            Some((_, p)) if !out.contains(p) => out.push(*p),
            Some(_) => r.problem(&POLICIES, format!("{} listed twice", names::shown(s))),
            None => r.problem(
                &POLICIES,
                format!(
                    "{} is not one of {}",
                    names::shown(s),
                    Policy::NAMES
                        .iter()
                        .map(|(n, _)| format!("\"{n}\""))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ),
        }
    }
    if out.is_empty() {
        r.problem(&POLICIES, "no policy: list at least one".into());
    }
    out
}

fn units(r: &mut Reader, axes: &[AxisEntry]) -> Vec<(String, Unit)> {
    let Some(t) = r.table(&UNITS) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (axis, v) in &t {
        if !axes.iter().any(|a| &a.name == axis) {
            r.problem_at(
                &format!("units.{axis}"),
                format!("no axis is called {}", names::shown(axis)),
            );
            continue;
        }
        match v
            .as_str()
            .and_then(|s| Unit::NAMES.iter().find(|(n, _)| *n == s))
        {
            Some((_, u)) => out.push((axis.clone(), *u)),
            None => r.problem_at(
                &format!("units.{axis}"),
                format!(
                    "expected one of {}",
                    Unit::NAMES
                        .iter()
                        .map(|(n, _)| format!("\"{n}\""))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ),
        }
    }
    out
}

fn users(tables: &[toml::Table], problems: &mut Vec<Problem>) -> Vec<User> {
    let mut out: Vec<User> = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        let mut r = Reader::new(t, None, Section::OpcuaUser, problems);
        let name = r.string(&USER_NAME);
        let at = format!("[[opcua.user]] #{}", i + 1);
        if let Err(e) = names::check_name(&name) {
            r.problem(&USER_NAME, format!("{at}: {e}"));
        } else if out.iter().any(|u| u.name == name) {
            r.problem(&USER_NAME, format!("user {name} configured twice"));
        }
        if r.has(&PASSWORD) {
            r.mark_used(&PASSWORD);
            r.problem(
                &PASSWORD,
                format!(
                    "{at}: a clear-text password is never accepted: put the output of \
                     `motion-opcua --config FILE hash-password` in password_hash"
                ),
            );
        }
        let password_hash = r.string(&PASSWORD_HASH);
        if let Err(e) = check_phc(&password_hash) {
            r.problem(&PASSWORD_HASH, format!("user {}: {e}", names::shown(&name)));
        }
        let role = r.choice(&ROLE, ROLES);
        if !r.has(&ROLE) {
            r.problem(
                &ROLE,
                format!(
                    "user {}: missing (\"operator\" or \"viewer\")",
                    names::shown(&name)
                ),
            );
        }
        r.finish();
        out.push(User {
            name,
            password_hash,
            role,
        });
    }
    out
}
