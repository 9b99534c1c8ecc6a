//! Reading a configuration file someone else may have pointed us at.
//!
//! Only a regular file (after following symlinks) of at most
//! [`MAX_CONFIG_BYTES`] is read: a FIFO would block forever, `/dev/zero` would
//! be read until memory runs out, a directory gives a confusing error.
//!
//! The file judged is the file read: it is opened without blocking
//! (`O_NONBLOCK`: a FIFO swapped in after a check by path would otherwise
//! block the open forever) and judged by `fstat` of what was opened.

use std::fs::{File, Metadata, OpenOptions};
use std::io::Read;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;

/// Largest configuration file accepted (1 MiB: a 64-axis machine is ~20 KB).
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// Reads `path` as UTF-8 text, refusing anything but a regular file of at
/// most [`MAX_CONFIG_BYTES`].
pub fn read_config_file(path: &Path) -> Result<String, String> {
    let shown = path.display();
    // First by path, which opens nothing: a device named by mistake is
    // refused without the side effects opening it may have.
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {shown}: {e}"))?;
    judge(path, &meta)?;
    // Then what is opened, which may not be what was looked at.
    let f = OpenOptions::new()
        .read(true)
        .custom_flags(nix::libc::O_NONBLOCK | nix::libc::O_NOCTTY)
        .open(path)
        .map_err(|e| format!("cannot read {shown}: {e}"))?;
    let meta = f
        .metadata()
        .map_err(|e| format!("cannot read {shown}: {e}"))?;
    judge(path, &meta)?;
    read_bounded(path, f)
}

/// A regular file of at most [`MAX_CONFIG_BYTES`].
fn judge(path: &Path, meta: &Metadata) -> Result<(), String> {
    let shown = path.display();
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
    Ok(())
}

/// The file may grow after `fstat`: the read is bounded too.
fn read_bounded(path: &Path, f: File) -> Result<String, String> {
    let shown = path.display();
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

    /// An attack on the reader: the path is swapped between a regular file
    /// and a FIFO while it is read (a symlink replaced atomically, over and
    /// over). A
    /// check by path followed by a blocking open of the same path could
    /// judge the file and then open the FIFO, and block forever; the file
    /// judged must be the file opened.
    #[test]
    fn a_fifo_swapped_in_while_reading_never_blocks() {
        use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
        use std::sync::Arc;
        use std::time::{Duration, Instant};

        let dir = std::env::temp_dir().join(format!("cfgswap-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let reg = dir.join("machine.toml");
        std::fs::write(&reg, "# a machine\n").unwrap();
        let fifo = dir.join("fifo");
        nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
        let path = dir.join("cfg.toml");
        std::os::unix::fs::symlink(&reg, &path).unwrap();

        let stop = Arc::new(AtomicBool::new(false));
        let swapper = {
            let (stop, dir, reg, fifo, path) = (
                stop.clone(),
                dir.clone(),
                reg.clone(),
                fifo.clone(),
                path.clone(),
            );
            std::thread::spawn(move || {
                let tmp = dir.join("tmp");
                for target in [&reg, &fifo].into_iter().cycle() {
                    if stop.load(Ordering::Relaxed) {
                        return;
                    }
                    let _ = std::fs::remove_file(&tmp);
                    std::os::unix::fs::symlink(target, &tmp).unwrap();
                    std::fs::rename(&tmp, &path).unwrap();
                }
            })
        };
        let reads = Arc::new(AtomicU64::new(0));
        let reader = {
            let (stop, reads, path) = (stop.clone(), reads.clone(), path.clone());
            std::thread::spawn(move || {
                let mut odd = Vec::new();
                while !stop.load(Ordering::Relaxed) {
                    match read_config_file(&path) {
                        Ok(text) if text == "# a machine\n" => {}
                        Err(e) if e.contains("not a regular file") || e.contains("cannot read") => {
                        }
                        other => odd.push(format!("{other:?}")),
                    }
                    reads.fetch_add(1, Ordering::Relaxed);
                }
                odd
            })
        };
        let end = Instant::now() + Duration::from_millis(1000);
        let mut last = (0, Instant::now());
        let mut blocked = false;
        while Instant::now() < end {
            std::thread::sleep(Duration::from_millis(20));
            let n = reads.load(Ordering::Relaxed);
            if n != last.0 {
                last = (n, Instant::now());
            } else if last.1.elapsed() > Duration::from_millis(300) {
                blocked = true;
                break;
            }
        }
        stop.store(true, Ordering::Relaxed);
        if blocked {
            // Release the reader: a writer on the FIFO lets its open return.
            let _w = std::fs::OpenOptions::new().write(true).open(&fifo);
        }
        swapper.join().unwrap();
        let odd = reader.join().unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(!blocked, "read_config_file blocked on a FIFO swapped in");
        assert!(odd.is_empty(), "{odd:?}");
        assert!(reads.load(Ordering::Relaxed) > 100);
    }
}
