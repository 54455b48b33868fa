//! Crash-safe file replacement: write a temporary file in the same
//! directory, fsync it, rename it over the target, fsync the directory.
//!
//! Images, snapshots and checkpoints are all written this way, so a crash,
//! a `kill -9` or a full disk at any moment leaves under the final name
//! either the old file or the complete new one, never a partial file. What
//! can be left behind is a stale temporary file `.NAME.tmp-PID` beside it.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::hash::fnv1a;
use crate::error::{Error, Result};

/// The longest file name (in bytes) on Linux and most Unix file systems.
pub const NAME_MAX: usize = 255;

/// `dir/.name.tmp-PID`: a temporary name in the same directory (so the
/// rename is atomic). When that would exceed the file system's name limit
/// for a long but legal `name`, the name is shortened and a hash of it
/// keeps temporary names of different files apart.
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let suffix = format!(".tmp-{}", std::process::id());
    let full = format!(".{name}{suffix}");
    if full.len() <= NAME_MAX {
        return path.with_file_name(full);
    }
    let hash = format!("~{:016x}", fnv1a(name.as_bytes()));
    let mut keep = NAME_MAX - 1 - hash.len() - suffix.len();
    while !name.is_char_boundary(keep) {
        keep -= 1;
    }
    path.with_file_name(format!(".{}{hash}{suffix}", &name[..keep]))
}

/// Replaces `path` with `bytes` atomically (see the module docs).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// Replaces `path` atomically with what `fill` writes. When `fill` or any
/// later step fails, the temporary file is removed and `path` is untouched.
pub fn write_atomic_with(path: &Path, fill: impl FnOnce(&mut File) -> std::io::Result<()>) -> Result<()> {
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = File::create(&tmp)?;
        fill(&mut f)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    sync_parent_dir(path);
    Ok(())
}

/// Makes the rename durable where the platform allows it (a directory can
/// be opened and synced on Unix; elsewhere this quietly does nothing).
fn sync_parent_dir(path: &Path) {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rust-v-atomic-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_intact_and_no_temporary() {
        let d = dir("fail");
        let path = d.join("x.ckpt");
        write_atomic(&path, b"old complete file").unwrap();
        let err = write_atomic_with(&path, |f| {
            f.write_all(b"new but only half")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("x.ckpt") && err.to_string().contains("disk full"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old complete file");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1, "temporary file left behind");
        write_atomic(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
    }

    #[test]
    fn temporary_names_stay_within_the_name_limit() {
        let short = temp_path(Path::new("d/out.png"));
        assert_eq!(short, Path::new(&format!("d/.out.png.tmp-{}", std::process::id())));
        for n in [200, 240, 250, 255] {
            let name = "é".repeat(n / 2) + &"x".repeat(n % 2);
            let t = temp_path(&Path::new("d").join(&name));
            let len = t.file_name().unwrap().len();
            assert!(len <= NAME_MAX, "{n}: {len}");
        }
        let (a, b) = ("a".repeat(250) + "1.png", "a".repeat(250) + "2.png");
        assert_ne!(temp_path(Path::new(&a)), temp_path(Path::new(&b)));
    }

    #[test]
    fn a_missing_directory_is_an_error_naming_the_file() {
        let err = write_atomic(Path::new("/no/such/dir/x.png"), b"x").unwrap_err();
        assert!(err.to_string().contains("/no/such/dir/x.png"), "{err}");
    }
}
