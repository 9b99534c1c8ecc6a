//! Salted password hashes (argon2id, the `argon2` crate of RustCrypto):
//! `hash-password` makes them, logins check them. The config never holds
//! a clear-text password.

use argon2::password_hash::rand_core::OsRng;
use argon2::password_hash::{PasswordHash, PasswordHasher, PasswordVerifier, SaltString};
use argon2::Argon2;
use std::sync::OnceLock;

/// Longest password accepted (argon2 takes any length; this bounds the
/// work a client can ask for).
pub const MAX_PASSWORD: usize = 1024;

/// An argon2id PHC string of `password` with a fresh random salt.
pub fn hash(password: &str) -> Result<String, String> {
    if password.is_empty() {
        return Err("an empty password is not accepted".into());
    }
    if password.len() > MAX_PASSWORD {
        return Err(format!("a password of at most {MAX_PASSWORD} bytes"));
    }
    let salt = SaltString::generate(&mut OsRng);
    Argon2::default()
        .hash_password(password.as_bytes(), &salt)
        .map(|h| h.to_string())
        .map_err(|e| format!("argon2: {e}"))
}

/// The most work a configured hash may ask of one login: memory (KiB,
/// 256 MiB), passes and lanes. `hash` makes m=19456, t=2, p=1 (argon2's
/// defaults, OWASP's minimum); a hash beyond these bounds would let the
/// config — or anyone who may write it — make every login (and every
/// hostile login attempt, which is verified the same way) a denial of
/// service.
pub const MAX_M_KIB: u32 = 256 * 1024;
pub const MAX_T: u32 = 16;
pub const MAX_P: u32 = 8;

/// Is `phc` an argon2 hash this program can check, within the bounds?
pub fn parses(phc: &str) -> Result<(), String> {
    let h = PasswordHash::new(phc).map_err(|e| format!("not an argon2 PHC string: {e}"))?;
    bounded(&h)
}

fn bounded(h: &PasswordHash) -> Result<(), String> {
    if !h.algorithm.as_str().starts_with("argon2") {
        return Err(format!("{} is not an argon2 hash", h.algorithm));
    }
    for (name, max) in [("m", MAX_M_KIB), ("t", MAX_T), ("p", MAX_P)] {
        match h.params.get_decimal(name) {
            Some(v) if v >= 1 && v <= max => {}
            Some(v) => return Err(format!("{name}={v} is outside 1..={max}")),
            None => return Err(format!("the parameter {name} is missing")),
        }
    }
    Ok(())
}

/// Does `password` match `phc`? `None` (no such user) is checked against
/// a hash of a random password, so it costs the same time and is false.
pub fn verify(phc: Option<&str>, password: &str) -> bool {
    static DUMMY: OnceLock<String> = OnceLock::new();
    let dummy = DUMMY.get_or_init(|| {
        let mut b = [0u8; 16];
        let _ = getrandom::fill(&mut b);
        let p: String = b.iter().map(|x| format!("{x:02x}")).collect();
        hash(&p).unwrap_or_default()
    });
    let (target, real) = match phc {
        Some(h) => (h, true),
        None => (dummy.as_str(), false),
    };
    if password.len() > MAX_PASSWORD {
        return false;
    }
    let Ok(parsed) = PasswordHash::new(target) else {
        return false;
    };
    if bounded(&parsed).is_err() {
        return false;
    }
    let ok = Argon2::default()
        .verify_password(password.as_bytes(), &parsed)
        .is_ok();
    ok && real
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_are_salted_and_verify() {
        let a = hash("correct horse").unwrap();
        let b = hash("correct horse").unwrap();
        assert_ne!(a, b, "a fresh salt each time");
        assert!(a.starts_with("$argon2id$"));
        motion_config::opcua::check_phc(&a).expect("the config accepts what we print");
        assert!(verify(Some(&a), "correct horse"));
        assert!(!verify(Some(&a), "correct horsE"));
        assert!(!verify(None, "correct horse"));
        assert!(!verify(Some("garbage"), ""));
        assert!(hash("").is_err());
        assert!(!verify(Some(&a), &"x".repeat(MAX_PASSWORD + 1)));
        assert!(parses(&a).is_ok());
    }

    #[test]
    fn absurd_work_factors_are_refused_unverified() {
        let salt = "c2FsdHNhbHRzYWx0c2FsdA";
        let out = "AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA";
        for (params, ok) in [
            ("m=19456,t=2,p=1", true),
            ("m=4294967295,t=2,p=1", false),
            ("m=19456,t=100000,p=1", false),
            ("m=19456,t=2,p=255", false),
            ("m=19456,t=0,p=1", false),
        ] {
            let phc = format!("$argon2id$v=19${params}${salt}${out}");
            assert_eq!(parses(&phc).is_ok(), ok, "{phc}: {:?}", parses(&phc));
            // Refused before any work: returns at once, false.
            assert!(!verify(Some(&phc), "pw"));
        }
        let e = parses(&format!("$argon2id$v=19$m=4294967295,t=2,p=1${salt}${out}")).unwrap_err();
        assert!(e.contains("m=4294967295 is outside"), "{e}");
    }
}
