//! Atomic replacement of a small file: write a temporary file next to it,
//! fsync it, rename it over the old one, fsync the directory. A crash at any
//! point leaves either the old file or the new one, never a mix; a stray
//! temporary file is ignored by readers (and replaced on the next write).

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::Path;

/// Replaces `path` with `bytes` atomically (mode 0600).
pub fn write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map_or_else(|| "state".into(), |n| n.to_string_lossy().into_owned());
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    // A leftover of a crashed writer with our pid: ours to replace.
    let _ = std::fs::remove_file(&tmp);
    let result = (|| {
        let mut f = OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .custom_flags(libc_o_nofollow())
            .open(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)?;
        File::open(dir)?.sync_all()
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Reads `path` if it is a regular file owned by this user, of at most
/// `max` bytes; `Ok(None)` when it does not exist.
pub fn read_own(path: &Path, max: u64) -> std::io::Result<Option<Vec<u8>>> {
    let f = match OpenOptions::new()
        .read(true)
        .custom_flags(libc_o_nofollow())
        .open(path)
    {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e),
    };
    let m = f.metadata()?;
    let bad = |why: String| Err(std::io::Error::new(std::io::ErrorKind::InvalidData, why));
    if !m.is_file() {
        return bad("not a regular file".into());
    }
    if m.uid() != nix::unistd::geteuid().as_raw() {
        return bad(format!("owned by uid {}, not by us", m.uid()));
    }
    if m.len() > max {
        return bad(format!("{} bytes, more than the {max} allowed", m.len()));
    }
    let mut v = Vec::with_capacity(m.len() as usize);
    f.take(max + 1).read_to_end(&mut v)?;
    if v.len() as u64 > max {
        return bad(format!("more than the {max} bytes allowed"));
    }
    Ok(Some(v))
}

/// `O_NOFOLLOW`: a symlink planted in place of a state file is refused,
/// never followed.
pub(crate) fn libc_o_nofollow() -> i32 {
    nix::fcntl::OFlag::O_NOFOLLOW.bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_and_leaves_no_temporary_file() {
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("x.json");
        write(&p, b"one").unwrap();
        write(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(t.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn a_crash_before_the_rename_keeps_the_old_file() {
        // What a crash mid-write leaves: the old file and a partial
        // temporary file. Readers see the old file.
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("x.json");
        write(&p, b"old").unwrap();
        std::fs::write(t.path().join(".x.json.tmp-99999"), b"{\"trunc").unwrap();
        assert_eq!(read_own(&p, 100).unwrap().unwrap(), b"old");
        write(&p, b"new").unwrap();
        assert_eq!(read_own(&p, 100).unwrap().unwrap(), b"new");
    }

    #[test]
    fn refuses_symlinks_and_oversized_files() {
        let t = tempfile::tempdir().unwrap();
        let target = t.path().join("target");
        std::fs::write(&target, b"x").unwrap();
        let link = t.path().join("link");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        assert!(read_own(&link, 100).is_err());
        let big = t.path().join("big");
        std::fs::write(&big, vec![b'x'; 200]).unwrap();
        assert!(read_own(&big, 100).is_err());
        assert!(read_own(&t.path().join("none"), 100).unwrap().is_none());
    }
}
