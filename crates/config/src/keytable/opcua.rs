//! `[opcua]` and `[[opcua.user]]`: what `motion-opcua` serves.

use super::{keys, names_of, Key, Kind, Section, Status};
use crate::opcua::{Policy, Unit, ANONYMOUS, DEFAULT_ENDPOINT, ROLES};

keys! {
    GROUP {
        section: Section::Opcua,
        title: "[opcua]",
        intro: "`motion-opcua` serves the machine on the plant network. Secure by default: \
                every endpoint Sign & Encrypt but an explicitly listed `\"None\"`, anonymous \
                sessions read-only, users only with a salted password hash. `check` names every \
                problem of this section by key.",
    }
    ENDPOINT: Key::new(Section::Opcua, "endpoint", Kind::Text)
        .text(DEFAULT_ENDPOINT)
        .bounded("opc.tcp://HOST:PORT[/PATH]")
        .fixed()
        .meaning("Where the server listens; the default serves this host only.")
        .example("\"opc.tcp://192.168.10.5:4840\"");
    ANONYMOUS_ACCESS: Key::new(Section::Opcua, "anonymous", Kind::Choice(|| names_of(ANONYMOUS)))
        .text("read")
        .fixed()
        .meaning("`\"read\"`: anonymous sessions may browse, read and subscribe; `\"off\"`: only \
                  users log in.")
        .example("\"off\"");
    POLICIES: Key::new(Section::Opcua, "policies", Kind::ChoiceList(|| names_of(&Policy::NAMES)))
        .derived("the three secure policies")
        .bounded("at least one, each once; `\"None\"` needs `anonymous = \"read\"`")
        .meaning("The endpoints' security policies, each Sign & Encrypt; `\"None\"` adds an \
                  unsecured endpoint, read-only and anonymous only.")
        .example("[\"Basic256Sha256\"]");
    PKI_DIR: Key::new(Section::Opcua, "pki_dir", Kind::Text)
        .derived("`state_dir`/opcua")
        .bounded("an absolute path of at most 200 characters without `..`")
        .meaning("The server's certificate and key (`own/`, `private/`), the trust list \
                  (`trusted/`) and the refused client certificates (`rejected/`).")
        .example("\"/var/lib/motion/opcua\"");
    UNITS: Key::new(Section::Opcua, "units", Kind::NameMap(|| names_of(&Unit::NAMES)))
        .unset("generic units")
        .bounded("names of configured axes")
        .meaning("Engineering units of the axes' positions, speeds and accelerations, per axis.")
        .example("{ X = \"mm\", C = \"deg\" }");
    USER: Key::new(Section::Opcua, "user", Kind::Tables)
        .unset("no users: anonymous sessions only")
        .meaning("The users (`[[opcua.user]]`).")
        .example("[{ name = \"op1\", password_hash = \"…\", role = \"operator\" }]");
}

keys! {
    USER_GROUP {
        section: Section::OpcuaUser,
        title: "[[opcua.user]]",
        intro: "A user logs in by name and password; the password is checked against a salted \
                argon2 hash printed by `motion-opcua --config FILE hash-password`.",
    }
    USER_NAME: Key::new(Section::OpcuaUser, "name", Kind::Text)
        .bounded("1..=32 characters of A-Z a-z 0-9 _ . -, unique")
        .fixed()
        .meaning("The user's login name.")
        .example("\"operator1\"");
    PASSWORD_HASH: Key::new(Section::OpcuaUser, "password_hash", Kind::Text)
        .bounded("an argon2 PHC string, work factors at most m = 256 MiB, t = 16, p = 8")
        .fixed()
        .meaning("The salted password hash, as `hash-password` prints it.")
        .example("\"$argon2id$v=19$m=19456,t=2,p=1$c29tZXNhbHRzb21lc2FsdA$qDYw3NfO0x0l5w5Np4r3b7g8kD9n5fZ3yq1u2qvXq0o\"");
    ROLE: Key::new(Section::OpcuaUser, "role", Kind::Choice(|| names_of(ROLES)))
        .fixed()
        .meaning("`\"operator\"` may call the methods (over Sign & Encrypt); `\"viewer\"` may \
                  browse, read and subscribe.")
        .example("\"operator\"");
    PASSWORD: Key::new(Section::OpcuaUser, "password", Kind::Text)
        .unset("—")
        .status(Status::Refused("put the output of `motion-opcua --config FILE hash-password` \
                                 in `password_hash`"))
        .meaning("A clear-text password is never accepted.")
        .example("\"secret\"");
}
