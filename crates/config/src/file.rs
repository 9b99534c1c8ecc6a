//! Reading a configuration file someone else may have pointed us at.
//!
//! Only a regular file (after following symlinks) of at most
//! [`MAX_CONFIG_BYTES`] is read: a FIFO would block forever, `/dev/zero` would
//! be read until memory runs out, a directory gives a confusing error.

use std::io::Read;
use std::path::Path;

/// Largest configuration file accepted (1 MiB: a 64-axis machine is ~20 KB).
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// Reads `path` as UTF-8 text, refusing anything but a regular file of at
/// most [`MAX_CONFIG_BYTES`].
pub fn read_config_file(path: &Path) -> Result<String, String> {
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {shown}: {e}"))?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a directory"
        } else {
            "not a regular file (a FIFO, socket or device)"
        };
        return Err(format!("{shown} is {what}: give a configuration file"));
    }
    if meta.len() > MAX_CONFIG_BYTES {
        return Err(format!(
            "{shown} is {} bytes; a configuration is at most {MAX_CONFIG_BYTES} bytes",
            meta.len()
        ));
    }
    // The file may change between the check and the read: the read is
    // bounded too.
    let f = std::fs::File::open(path).map_err(|e| format!("cannot read {shown}: {e}"))?;
    let mut bytes = Vec::new();
    f.take(MAX_CONFIG_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {shown}: {e}"))?;
    if bytes.len() as u64 > MAX_CONFIG_BYTES {
        return Err(format!(
            "{shown} grew beyond {MAX_CONFIG_BYTES} bytes while being read"
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "{shown} is not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_is_not_a_small_regular_file() {
        assert!(read_config_file(Path::new("/dev/zero"))
            .unwrap_err()
            .contains("not a regular file"));
        assert!(read_config_file(Path::new("/tmp"))
            .unwrap_err()
            .contains("directory"));
        assert!(read_config_file(Path::new("/nonexistent/x.toml"))
            .unwrap_err()
            .contains("cannot read"));
        let dir = std::env::temp_dir().join(format!("cfgfile-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("fifo");
        let _ = std::fs::remove_file(&fifo);
        nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
        // Must return at once, not block on the FIFO.
        assert!(read_config_file(&fifo)
            .unwrap_err()
            .contains("not a regular file"));
        let big = dir.join("big.toml");
        std::fs::write(&big, vec![b'#'; (MAX_CONFIG_BYTES + 1) as usize]).unwrap();
        assert!(read_config_file(&big).unwrap_err().contains("at most"));
        let bin = dir.join("bin.toml");
        std::fs::write(&bin, [0x66, 0xff, 0xfe]).unwrap();
        assert!(read_config_file(&bin).unwrap_err().contains("UTF-8"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
