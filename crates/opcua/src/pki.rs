//! The server's certificate and key, and the trust list, under `pki_dir`
//! (the layout the stack reads: `own/cert.der`, `private/private.pem`,
//! `trusted/`, `rejected/`).
//!
//! The key is created at first start with mode 0600 (created exclusively,
//! never widened by the umask), the directories 0700. A client certificate
//! the server has not seen lands in `rejected/`; `motion-opcua trust`
//! copies it into `trusted/` and removes it from `rejected/`, and the next
//! connection is accepted: the stack reads the directories on every
//! connection.

use opcua::crypto::{CertificateStore, X509Data, X509};
use opcua::types::{ApplicationDescription, ApplicationType, LocalizedText, UAString};
use std::fs::{self, OpenOptions};
use std::io::Write;
use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

pub const CERT: &str = "own/cert.der";
pub const KEY: &str = "private/private.pem";
/// Validity of a created server certificate (5 years; delete `own/` and
/// `private/` to make a new one, then clients trust the new one).
pub const CERT_DAYS: u32 = 5 * 365;
/// Largest certificate file `trust` reads.
const MAX_CERT_BYTES: u64 = 64 * 1024;

/// The application URI of this server: in its certificate, and what
/// clients check it against.
pub fn application_uri() -> String {
    let host = opcua::crypto::hostname().unwrap_or_else(|_| "localhost".into());
    format!("urn:{host}:motion-opcua")
}

fn mkdir_private(p: &Path) -> Result<(), String> {
    fs::create_dir_all(p).map_err(|e| format!("cannot create {}: {e}", p.display()))?;
    fs::set_permissions(p, fs::Permissions::from_mode(0o700))
        .map_err(|e| format!("cannot make {} owner-only: {e}", p.display()))
}

/// Creates the directories, and the certificate and key if there is none.
/// Returns true if it created them.
pub fn ensure(pki: &Path, host: &str) -> Result<bool, String> {
    for d in ["", "own", "private", "trusted", "rejected"] {
        mkdir_private(&pki.join(d))?;
    }
    let (cert, key) = (pki.join(CERT), pki.join(KEY));
    if cert.exists() && key.exists() {
        let mode = fs::metadata(&key)
            .map_err(|e| format!("{}: {e}", key.display()))?
            .permissions()
            .mode();
        if mode & 0o077 != 0 {
            return Err(format!(
                "{} is readable by others (mode {:o}): chmod 600 it",
                key.display(),
                mode & 0o777
            ));
        }
        return Ok(false);
    }
    let uri = application_uri();
    let desc = ApplicationDescription {
        application_uri: UAString::from(uri.as_str()),
        application_name: LocalizedText::new("", "motion-opcua"),
        application_type: ApplicationType::Server,
        ..Default::default()
    };
    let mut data = X509Data::from((desc, Some(vec![host.to_string()])));
    data.certificate_duration_days = CERT_DAYS;
    let (x509, pkey) = X509::cert_and_pkey(&data)?;
    let pem = pkey
        .to_der()
        .map_err(|e| format!("encoding the key: {e}"))?
        .to_pem("PRIVATE KEY", rsa::pkcs8::LineEnding::LF)
        .map_err(|e| format!("encoding the key: {e}"))?;
    let _ = fs::remove_file(&key);
    let mut f = OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .open(&key)
        .map_err(|e| format!("cannot create {}: {e}", key.display()))?;
    f.write_all(pem.as_bytes())
        .map_err(|e| format!("{}: {e}", key.display()))?;
    let der = x509
        .to_der()
        .map_err(|e| format!("encoding the certificate: {e}"))?;
    fs::write(&cert, der).map_err(|e| format!("{}: {e}", cert.display()))?;
    Ok(true)
}

/// Reads a certificate (DER or PEM) of at most 64 KiB from a regular file.
pub fn read_cert(path: &Path) -> Result<X509, String> {
    let meta = fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if !meta.is_file() || meta.len() > MAX_CERT_BYTES {
        return Err(format!(
            "{}: not a regular file of at most {MAX_CERT_BYTES} bytes",
            path.display()
        ));
    }
    let bytes = fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    X509::from_der(&bytes)
        .or_else(|_| X509::from_pem(&bytes))
        .map_err(|_| format!("{}: not an X.509 certificate (DER or PEM)", path.display()))
}

/// What an administrator checks against the client's own display before
/// trusting a certificate: the subject (escaped: it is the client's
/// text) and the SHA-1 (what OPC UA calls the thumbprint) and SHA-256
/// fingerprints of the DER.
pub fn describe(cert: &X509) -> Result<String, String> {
    use sha2::{Digest, Sha256};
    let der = cert
        .to_der()
        .map_err(|e| format!("encoding the certificate: {e}"))?;
    let sha256: String = Sha256::digest(&der)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    Ok(format!(
        "subject {}\n  SHA-1   {}\n  SHA-256 {sha256}",
        motion_config::names::shown(&cert.subject_name()),
        cert.thumbprint().as_hex_string().to_lowercase(),
    ))
}

/// Is the client certificate of a session still trusted? (Its file in
/// `trusted/`: removing it revokes the trust for new connections at once
/// — the stack checks there — and for method calls of sessions already
/// open, which `manager.rs` checks here.)
pub fn still_trusted(pki: &Path, cert: &X509) -> bool {
    pki.join("trusted")
        .join(CertificateStore::cert_file_name(cert))
        .is_file()
}

/// Most certificates kept in `rejected/`, and the largest: every client
/// that presents an unknown certificate leaves one there (for an
/// administrator to trust), so a hostile client could fill the disk.
pub const MAX_REJECTED: usize = 100;
pub const MAX_REJECTED_BYTES: u64 = 16 * 1024;

/// Bounds `rejected/`: removes files over [`MAX_REJECTED_BYTES`] and
/// anything that is not a regular file, then the oldest beyond
/// [`MAX_REJECTED`]. Returns how many it removed.
pub fn prune_rejected(pki: &Path) -> usize {
    let Ok(dir) = fs::read_dir(pki.join("rejected")) else {
        return 0;
    };
    let mut kept = Vec::new();
    let mut removed = 0;
    for e in dir.flatten() {
        let Ok(meta) = e.path().symlink_metadata() else {
            continue;
        };
        if !meta.is_file() || meta.len() > MAX_REJECTED_BYTES {
            let gone = if meta.is_dir() {
                fs::remove_dir_all(e.path())
            } else {
                fs::remove_file(e.path())
            };
            removed += usize::from(gone.is_ok());
        } else {
            kept.push((meta.modified().ok(), e.path()));
        }
    }
    if kept.len() > MAX_REJECTED {
        kept.sort();
        let extra = kept.len() - MAX_REJECTED;
        for (_, p) in kept.into_iter().take(extra) {
            removed += usize::from(fs::remove_file(p).is_ok());
        }
    }
    removed
}

/// Trusts the certificate at `path`: copies it into `trusted/` under the
/// stack's name for it and removes it from `rejected/`. Returns where it
/// went.
pub fn trust(pki: &Path, path: &Path) -> Result<PathBuf, String> {
    let cert = read_cert(path)?;
    mkdir_private(&pki.join("trusted"))?;
    let name = CertificateStore::cert_file_name(&cert);
    let der = cert
        .to_der()
        .map_err(|e| format!("encoding the certificate: {e}"))?;
    let to = pki.join("trusted").join(&name);
    let tmp = pki.join("trusted").join(format!(".{name}.tmp"));
    fs::write(&tmp, der).map_err(|e| format!("{}: {e}", tmp.display()))?;
    fs::rename(&tmp, &to).map_err(|e| format!("{}: {e}", to.display()))?;
    match fs::remove_file(pki.join("rejected").join(&name)) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(format!("removing it from rejected/: {e}")),
    }
    Ok(to)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_start_makes_a_private_key_and_trust_moves_a_rejected_cert() {
        let dir = std::env::temp_dir().join(format!("opcua-pki-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        assert!(ensure(&dir, "localhost").unwrap());
        let mode = fs::metadata(dir.join(KEY)).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o600);
        assert!(
            !ensure(&dir, "localhost").unwrap(),
            "kept at the next start"
        );
        // The server's own certificate stands in for a client's.
        let cert = read_cert(&dir.join(CERT)).unwrap();
        let name = CertificateStore::cert_file_name(&cert);
        fs::copy(dir.join(CERT), dir.join("rejected").join(&name)).unwrap();
        let to = trust(&dir, &dir.join(CERT)).unwrap();
        assert!(to.exists());
        assert!(!dir.join("rejected").join(&name).exists());
        fs::set_permissions(dir.join(KEY), fs::Permissions::from_mode(0o644)).unwrap();
        assert!(ensure(&dir, "localhost").unwrap_err().contains("chmod 600"));
        assert!(read_cert(&dir.join("trusted")).is_err());
        assert!(still_trusted(&dir, &cert));
        let d = describe(&cert).unwrap();
        assert!(d.contains("SHA-256 ") && d.contains("subject \""), "{d}");
        fs::remove_file(&to).unwrap();
        assert!(!still_trusted(&dir, &cert), "removing the file revokes");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn rejected_is_bounded_oldest_first() {
        let dir = std::env::temp_dir().join(format!("opcua-rej-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(dir.join("rejected/sub")).unwrap();
        for i in 0..MAX_REJECTED + 5 {
            fs::write(dir.join(format!("rejected/c{i:03}.der")), [0u8; 10]).unwrap();
        }
        fs::write(dir.join("rejected/huge.der"), vec![0u8; 20_000]).unwrap();
        let removed = prune_rejected(&dir);
        assert_eq!(
            removed,
            5 + 2,
            "5 beyond the bound, the huge file, the directory"
        );
        assert_eq!(
            fs::read_dir(dir.join("rejected")).unwrap().count(),
            MAX_REJECTED
        );
        assert_eq!(prune_rejected(&dir), 0);
        fs::remove_dir_all(&dir).unwrap();
    }
}
