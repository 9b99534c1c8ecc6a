//! `[opcua]`: what `motion-opcua` serves on the plant network (endpoint,
//! security policies, users and roles, anonymous access, where the
//! certificates and the trust list live, engineering units).
//!
//! Checked with the rest of the machine (so `motion-supervisor check` names
//! every problem here too, by key), and read typed by `motion-opcua` with
//! [`load`]. Secure by default: no `None` policy unless listed, anonymous
//! access read-only, users only with a salted password hash.

use crate::{names, MachineConfig, Problem};
use std::path::{Path, PathBuf};

mod parse;
pub(crate) use parse::parse;

/// The endpoint when none is configured: this host only.
pub const DEFAULT_ENDPOINT: &str = "opc.tcp://127.0.0.1:4840";

/// A message security policy of an endpoint (always Sign & Encrypt, but `None`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Policy {
    Basic256Sha256,
    Aes128Sha256RsaOaep,
    Aes256Sha256RsaPss,
    /// No security: offered only when listed, and then read-only (anonymous).
    None,
}

impl Policy {
    /// Config spellings (the OPC UA policy names).
    pub const NAMES: [(&'static str, Policy); 4] = [
        ("Basic256Sha256", Policy::Basic256Sha256),
        ("Aes128_Sha256_RsaOaep", Policy::Aes128Sha256RsaOaep),
        ("Aes256_Sha256_RsaPss", Policy::Aes256Sha256RsaPss),
        ("None", Policy::None),
    ];

    pub fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(_, p)| *p == self)
            .map_or("?", |(n, _)| n)
    }
}

/// `anonymous`: may anonymous sessions read?
pub const ANONYMOUS: &[(&str, bool)] = &[("read", true), ("off", false)];

/// `role` of a user.
pub const ROLES: &[(&str, Role)] = &[("operator", Role::Operator), ("viewer", Role::Viewer)];

/// The secure policies offered by default.
pub const DEFAULT_POLICIES: [Policy; 3] = [
    Policy::Basic256Sha256,
    Policy::Aes128Sha256RsaOaep,
    Policy::Aes256Sha256RsaPss,
];

/// What a user may do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Reads, browses, subscribes.
    Viewer,
    /// And calls the methods (Home, Stop, Unhome, HomeAll, StopAll).
    Operator,
}

/// `[[opcua.user]]`.
#[derive(Clone, PartialEq, Eq)]
pub struct User {
    pub name: String,
    /// A PHC string (`$argon2id$v=19$m=…,t=…,p=…$salt$hash`) as printed by
    /// `motion-opcua hash-password`.
    pub password_hash: String,
    pub role: Role,
}

impl std::fmt::Debug for User {
    /// Never prints the hash.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("User")
            .field("name", &self.name)
            .field("role", &self.role)
            .finish_non_exhaustive()
    }
}

/// Engineering unit of an axis (`[opcua] units = { X = "mm" }`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    Millimetre,
    Metre,
    Inch,
    Degree,
    Radian,
}

impl Unit {
    pub const NAMES: [(&'static str, Unit); 5] = [
        ("mm", Unit::Millimetre),
        ("m", Unit::Metre),
        ("in", Unit::Inch),
        ("deg", Unit::Degree),
        ("rad", Unit::Radian),
    ];
}

/// `[opcua]`, typed.
#[derive(Clone, Debug, PartialEq)]
pub struct OpcuaConfig {
    /// `opc.tcp://HOST:PORT[/PATH]`.
    pub endpoint: String,
    pub host: String,
    pub port: u16,
    /// `/` unless the endpoint names a path.
    pub path: String,
    /// Anonymous sessions may read (`anonymous = "read"`, the default).
    pub anonymous: bool,
    pub policies: Vec<Policy>,
    pub users: Vec<User>,
    /// The server's certificate and key (`own/`, `private/`), the trust
    /// list (`trusted/`) and the refused client certificates (`rejected/`).
    pub pki_dir: PathBuf,
    /// Per axis name.
    pub units: Vec<(String, Unit)>,
}

impl OpcuaConfig {
    /// Is a `None` endpoint offered?
    pub fn offers_none(&self) -> bool {
        self.policies.contains(&Policy::None)
    }

    pub fn unit_of(&self, axis: &str) -> Option<Unit> {
        self.units.iter().find(|(a, _)| a == axis).map(|(_, u)| *u)
    }
}

/// The shape of an argon2 PHC string (`motion-opcua` verifies it fully at
/// start): anything else is refused, so a clear-text password can never
/// stand in the config for a hash.
pub fn check_phc(s: &str) -> Result<(), String> {
    const HINT: &str = "expected an argon2 hash as printed by `motion-opcua --config FILE \
                        hash-password` (a clear-text password is never accepted)";
    let parts: Vec<&str> = s.split('$').collect();
    let algo_ok = matches!(parts.get(1), Some(&("argon2id" | "argon2i" | "argon2d")));
    if s.is_empty() {
        return Err(format!("missing: {HINT}"));
    }
    if !(algo_ok
        && parts.len() == 6
        && parts[0].is_empty()
        && parts[2].starts_with("v=")
        && parts[3].contains("m=")
        && parts[4].len() >= 11
        && parts[5].len() >= 22
        && s.len() <= 512)
    {
        return Err(format!("not a password hash: {HINT}"));
    }
    Ok(())
}

/// `opc.tcp://HOST:PORT[/PATH]` → host, port, path.
pub(crate) fn split_endpoint(s: &str) -> Result<(String, u16, String), String> {
    let bad = || {
        format!(
            "{} is not opc.tcp://HOST:PORT[/PATH] (e.g. {DEFAULT_ENDPOINT})",
            names::shown(s)
        )
    };
    let rest = s.strip_prefix("opc.tcp://").ok_or_else(bad)?;
    let (hostport, path) = match rest.find('/') {
        Some(i) => (&rest[..i], &rest[i..]),
        None => (rest, "/"),
    };
    let (host, port) = hostport.rsplit_once(':').ok_or_else(bad)?;
    let host_ok = !host.is_empty()
        && host.len() <= 253
        && host
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || ".-[]:".contains(c));
    let path_ok = path.len() <= 100
        && path
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "/_-.".contains(c));
    match port.parse::<u16>() {
        Ok(p) if p > 0 && host_ok && path_ok => Ok((host.to_string(), p, path.to_string())),
        _ => Err(bad()),
    }
}

/// The machine and its `[opcua]` section from one read of `path`.
pub fn load(path: &Path) -> Result<(MachineConfig, OpcuaConfig), Vec<Problem>> {
    let text =
        crate::file::read_config_file(path).map_err(|e| vec![Problem::new(None, "file", e)])?;
    parse_text(&text)
}

/// As [`load`], from the text of a config.
pub fn parse_text(text: &str) -> Result<(MachineConfig, OpcuaConfig), Vec<Problem>> {
    let machine = crate::parse(text)?;
    // `parse` has checked [opcua] already: this only types it.
    let table: toml::Table = text.parse().map_err(|e| vec![Problem::syntax(text, &e)])?;
    let section = table.get("opcua").and_then(|v| v.as_table());
    let mut problems = Vec::new();
    let cfg = parse::parse(
        section,
        &machine.axes,
        &machine.supervisor.state_dir,
        &mut problems,
    );
    if problems.is_empty() {
        Ok((machine, cfg))
    } else {
        Err(problems)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HASH: &str = "$argon2id$v=19$m=19456,t=2,p=1$c29tZXNhbHRzb21lc2FsdA$\
                        qDYw3NfO0x0l5w5Np4r3b7g8kD9n5fZ3yq1u2qvXq0o";

    fn with(section: &str) -> Result<OpcuaConfig, Vec<Problem>> {
        let text = format!("{}\n{section}", crate::DEMO_TOML);
        parse_text(&text).map(|(_, c)| c)
    }

    fn keys(section: &str) -> Vec<String> {
        with(section)
            .expect_err("problems expected")
            .iter()
            .map(|p| format!("{}: {}", p.key, p.message))
            .collect()
    }

    #[test]
    fn defaults_are_secure() {
        let c = with("").unwrap();
        assert_eq!(c.endpoint, DEFAULT_ENDPOINT);
        assert_eq!(
            (c.host.as_str(), c.port, c.path.as_str()),
            ("127.0.0.1", 4840, "/")
        );
        assert!(c.anonymous);
        assert!(!c.offers_none());
        assert_eq!(c.policies, DEFAULT_POLICIES);
        assert!(c.users.is_empty());
        assert!(c.pki_dir.ends_with("opcua"));
    }

    #[test]
    fn a_full_section_is_read() {
        let c = with(&format!(
            "[opcua]\nendpoint = \"opc.tcp://0.0.0.0:48400/motion\"\nanonymous = \"off\"\n\
             policies = [\"Basic256Sha256\"]\npki_dir = \"/tmp/pki\"\nunits = {{ X = \"mm\", C = \"deg\" }}\n\
             [[opcua.user]]\nname = \"op1\"\npassword_hash = \"{HASH}\"\nrole = \"operator\"\n\
             [[opcua.user]]\nname = \"view\"\npassword_hash = \"{HASH}\"\nrole = \"viewer\"\n"
        ))
        .unwrap();
        assert_eq!(
            (c.host.as_str(), c.port, c.path.as_str()),
            ("0.0.0.0", 48400, "/motion")
        );
        assert!(!c.anonymous);
        assert_eq!(c.policies, [Policy::Basic256Sha256]);
        assert_eq!(c.users.len(), 2);
        assert_eq!(c.users[0].role, Role::Operator);
        assert_eq!(c.unit_of("C"), Some(Unit::Degree));
        assert_eq!(c.unit_of("Z"), None);
        assert!(
            !format!("{:?}", c.users[0]).contains("argon2"),
            "Debug hides the hash"
        );
    }

    #[test]
    fn every_problem_is_named_by_key() {
        let k = keys(
            "[opcua]\nendpoint = \"http://x\"\nanonymous = \"yes\"\npolicies = [\"Basic128Rsa15\"]\n\
             pki_dir = \"rel\"\nunits = { Q = \"mm\", X = \"furlong\" }\ncolour = 1\n\
             [[opcua.user]]\nname = \"a b\"\npassword = \"secret\"\nrole = \"admin\"\n",
        );
        let has = |s: &str| k.iter().any(|x| x.starts_with(s));
        for key in [
            "opcua.endpoint",
            "opcua.anonymous",
            "opcua.policies",
            "opcua.pki_dir",
            "opcua.units.Q",
            "opcua.units.X",
            "opcua.colour: unknown key",
            "opcua.user.name",
            "opcua.user.password: [[opcua.user]] #1: a clear-text password",
            "opcua.user.password_hash",
            "opcua.user.role",
        ] {
            assert!(has(key), "{key} not in {k:#?}");
        }
    }

    #[test]
    fn none_only_read_only_and_hashes_only() {
        let k = keys("[opcua]\nanonymous = \"off\"\npolicies = [\"None\"]\n");
        assert!(k.iter().any(|x| x.contains("needs anonymous")), "{k:?}");
        let k = keys(
            "[[opcua.user]]\nname = \"a\"\npassword_hash = \"hunter2hunter2\"\nrole = \"viewer\"\n\
             [[opcua.user]]\nname = \"a\"\npassword_hash = \"$argon2id$x\"\nrole = \"viewer\"\n",
        );
        assert_eq!(
            k.iter()
                .filter(|x| x.contains("not a password hash"))
                .count(),
            2
        );
        assert!(k.iter().any(|x| x.contains("configured twice")), "{k:?}");
        assert!(check_phc(HASH).is_ok());
    }

    #[test]
    fn endpoints_are_split_or_refused() {
        assert_eq!(
            split_endpoint("opc.tcp://[::1]:4840").unwrap(),
            ("[::1]".into(), 4840, "/".into())
        );
        for bad in [
            "opc.tcp://host",
            "opc.tcp://:4840",
            "opc.tcp://h:0",
            "opc.tcp://h:70000",
            "opc.tcp://h:1/a b",
            "opc.tcp://h\u{0}:1",
        ] {
            assert!(split_endpoint(bad).is_err(), "{bad}");
        }
    }
}
