//! Names given in the configuration (axes, I/O processes, gantries, the
//! service prefix, interfaces, SubDevices): what they may hold and how a
//! user-supplied string is shown. The spellings of the enums live with each
//! enum (`motion_homing::spellings!`), e.g. `HomeMode::NAMES`.

/// Longest axis, I/O process or gantry name (the status frame holds 32 bytes).
pub const NAME_MAX: usize = 32;
/// Longest service prefix: it goes into every shared-memory file name and
/// into the paths of iceoryx2's sockets, whose length the kernel limits.
pub const PREFIX_MAX: usize = 32;

fn name_chars_ok(s: &str, dot: bool) -> bool {
    s.chars()
        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || (dot && c == '.'))
}

/// Axis and gantry names: 1..=32 characters of `[A-Za-z0-9_.-]`. Names are
/// printed on terminals and in logs: nothing invisible or escaping.
pub fn check_name(s: &str) -> Result<(), String> {
    if s.is_empty() || s.len() > NAME_MAX || !name_chars_ok(s, true) {
        return Err(format!(
            "{} must be 1..={NAME_MAX} characters of A-Z a-z 0-9 _ . -",
            shown(s)
        ));
    }
    Ok(())
}

/// I/O process names (`[A-Za-z0-9_-]`, a fixed rule), 1..=32 characters:
/// they become part of service names.
pub fn check_io_name(s: &str) -> Result<(), String> {
    if s.is_empty() || s.len() > NAME_MAX || !name_chars_ok(s, false) {
        return Err(format!(
            "{} must be 1..={NAME_MAX} characters of A-Z a-z 0-9 _ -",
            shown(s)
        ));
    }
    Ok(())
}

/// `service_prefix`, from the config or the command line: 1..=32 characters
/// of `[A-Za-z0-9_-]` (no `/`, `.` or space: it names files and services, and
/// two prefixes must never share a file domain).
pub fn check_service_prefix(s: &str) -> Result<(), String> {
    if s.is_empty() || s.len() > PREFIX_MAX || !name_chars_ok(s, false) {
        return Err(format!(
            "service prefix {} must be 1..={PREFIX_MAX} characters of A-Z a-z 0-9 _ -",
            shown(s)
        ));
    }
    Ok(())
}

/// Longest network interface name (the kernel's IFNAMSIZ − 1).
pub const INTERFACE_MAX: usize = 15;
/// Longest EtherCAT SubDevice name an axis may name (SII strings are short).
pub const SUBDEVICE_NAME_MAX: usize = 64;

/// A network interface name (`[[io]] interface`, `motion-io --interface`):
/// 1..=15 printable ASCII characters, none of `/`, `:` or space (the
/// kernel's rules), not `.` or `..`.
pub fn check_interface_name(s: &str) -> Result<(), String> {
    let ok = !s.is_empty()
        && s.len() <= INTERFACE_MAX
        && s != "."
        && s != ".."
        && s.chars()
            .all(|c| c.is_ascii_graphic() && c != '/' && c != ':');
    if !ok {
        return Err(format!(
            "interface name {} must be 1..={INTERFACE_MAX} printable ASCII characters \
             without '/', ':' or spaces",
            shown(s)
        ));
    }
    Ok(())
}

/// An EtherCAT SubDevice name (`ethercat_name`): 1..=64 printable ASCII
/// characters (spaces allowed inside).
pub fn check_subdevice_name(s: &str) -> Result<(), String> {
    let ok = !s.is_empty()
        && s.len() <= SUBDEVICE_NAME_MAX
        && s.chars().all(|c| c.is_ascii_graphic() || c == ' ')
        && s.trim() == s;
    if !ok {
        return Err(format!(
            "SubDevice name {} must be 1..={SUBDEVICE_NAME_MAX} printable ASCII characters \
             (no leading or trailing space)",
            shown(s)
        ));
    }
    Ok(())
}

/// A user-supplied string made safe to print: quoted, control and
/// non-ASCII characters escaped, cut after 40 characters.
pub fn shown(s: &str) -> String {
    const MAX: usize = 40;
    let mut out = String::from("\"");
    for (i, c) in s.chars().enumerate() {
        if i == MAX {
            out += &format!("…\" ({} characters)", s.chars().count());
            return out;
        }
        if c.is_ascii_graphic() || c == ' ' {
            if c == '"' || c == '\\' {
                out.push('\\');
            }
            out.push(c);
        } else {
            out += &c.escape_unicode().to_string();
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod name_tests {
    use super::*;

    #[test]
    fn names_are_printable_and_bounded() {
        assert!(check_name("X").is_ok());
        assert!(check_name("gantry_Y1.left-2").is_ok());
        for bad in ["", "a b", "x\u{1b}[31m", "nul\0", "zw\u{200b}j", "ä"] {
            assert!(check_name(bad).is_err(), "{bad:?}");
        }
        let long = "x".repeat(100_000);
        let e = check_name(&long).unwrap_err();
        assert!(
            e.len() < 200,
            "the message must not echo 100,000 characters"
        );
        assert!(e.contains("100000 characters"));
        assert!(!shown("\u{1b}[31m").contains('\u{1b}'));
        for bad in ["a/b", "x y", "../../tmp/x", "a.b", ""] {
            assert!(check_service_prefix(bad).is_err(), "{bad:?}");
        }
        assert!(check_service_prefix("motion_1-a").is_ok());
        assert!(check_io_name("bus.0").is_err());
        assert!(check_interface_name("eth1").is_ok());
        assert!(check_interface_name("enp3s0f1.100").is_ok());
        for bad in [
            "",
            "0123456789abcdef",
            "a b",
            "a/b",
            "eth0:1",
            ".",
            "..",
            "é",
            "x\u{1b}",
        ] {
            assert!(check_interface_name(bad).is_err(), "{bad:?}");
        }
        assert!(check_subdevice_name("X5-Servo drive").is_ok());
        for bad in ["", " x", "x ", "a\tb", &"n".repeat(65)] {
            assert!(check_subdevice_name(bad).is_err(), "{bad:?}");
        }
    }
}
