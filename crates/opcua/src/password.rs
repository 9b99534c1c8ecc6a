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

/// Is `phc` a hash this program can check?
pub fn parses(phc: &str) -> Result<(), String> {
    PasswordHash::new(phc)
        .map(|_| ())
        .map_err(|e| format!("not an argon2 PHC string: {e}"))
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
    }
}
