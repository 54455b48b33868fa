//! Files a render reads and writes, checked before any work is done.
//!
//! - Inputs (scene, meshes, data files) must be regular files: a FIFO, a
//!   device or a directory is refused *before* it is opened, because opening
//!   a FIFO blocks until someone writes to it ([`read_input`]).
//! - Outputs (image, checkpoint, snapshots) are checked up front
//!   ([`check_output`]): the directory exists and takes a new file (probed
//!   by creating and removing the very temporary file an atomic write
//!   uses), the name fits the file system's name limit, and an existing
//!   file under that name is a regular file (an atomic write renames over
//!   it, which would replace a device node such as `/dev/null`).
//! - No output may be an input or another output ([`check_aliasing`]):
//!   paths are compared by the file's identity (device and inode) when it
//!   exists, so symbolic and hard links count, and by canonical directory
//!   and name otherwise.

use std::ffi::OsStr;
use std::fs::OpenOptions;
use std::path::{Path, PathBuf};

use super::atomic_file::{NAME_MAX, temp_path};
use crate::error::{Error, Result, show_path};

/// Reads a whole input file, refusing anything but a regular file (checked
/// with `stat` first, so a FIFO never blocks the read).
pub fn read_input(path: &Path) -> Result<Vec<u8>> {
    check_regular(path)?;
    std::fs::read(path).map_err(|e| Error::io(path, e))
}

/// Fails unless `path` is (or links to) a regular file.
pub fn check_regular(path: &Path) -> Result<()> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_file() {
        return Ok(());
    }
    let what = if meta.is_dir() { "a directory" } else { kind_of_special(&meta) };
    Err(Error::Settings(format!("{}: is {what}; expected a regular file", show_path(path))))
}

#[cfg(unix)]
fn kind_of_special(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

#[cfg(not(unix))]
fn kind_of_special(_: &std::fs::Metadata) -> &'static str {
    "not a regular file"
}

/// Checks that `path` can be written atomically, before any rendering:
/// the name is within [`NAME_MAX`], the directory exists and accepts a new
/// file, and nothing but a regular file already has the name. `role` names
/// the output in errors (`image`, `checkpoint`, ...).
pub fn check_output(path: &Path, role: &str) -> Result<()> {
    let bad = |m: String| Error::Settings(format!("{role} {}: {m}", show_path(path)));
    let name = path.file_name().ok_or_else(|| bad("expected a file name".into()))?;
    if name.len() > NAME_MAX {
        return Err(bad(format!("the name is {} bytes long; at most {NAME_MAX} are allowed", name.len())));
    }
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => return Err(bad("is a directory".into())),
        Ok(m) if m.file_type().is_symlink() => {
            // The rename replaces the link itself; what it points to must not be special.
            if let Ok(t) = std::fs::metadata(path)
                && !t.is_file()
            {
                return Err(bad(format!("links to {}; expected a regular file", kind(&t))));
            }
        }
        Ok(m) if !m.is_file() => return Err(bad(format!("is {}; expected a regular file", kind(&m)))),
        _ => {}
    }
    let dir = parent_dir(path);
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => return Err(bad(format!("{} is not a directory", show_path(dir)))),
        Err(e) => return Err(bad(format!("its directory {}: {e}", show_path(dir)))),
    }
    // Probe with the temporary name the atomic write will use.
    let tmp = temp_path(path);
    match OpenOptions::new().write(true).create_new(true).open(&tmp) {
        Ok(f) => {
            drop(f);
            let _ = std::fs::remove_file(&tmp);
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(bad(format!("cannot create a file in {}: {e}", show_path(dir)))),
    }
}

fn kind(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() { "a directory" } else { kind_of_special(meta) }
}

/// The directory a path's file lives in (`.` for a bare name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// What identifies a file: its device and inode when it exists (so links
/// to it compare equal), else its canonical directory and name.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Identity {
    Inode(u64, u64),
    Path(PathBuf),
}

fn identity(path: &Path) -> Option<Identity> {
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(path) {
        use std::os::unix::fs::MetadataExt;
        return Some(Identity::Inode(m.dev(), m.ino()));
    }
    let dir = std::fs::canonicalize(parent_dir(path)).ok()?;
    Some(Identity::Path(dir.join(path.file_name()?)))
}

/// Refuses any output that is the same file as an input or as another
/// output. Each entry is `(role, path)`, e.g. `("scene", scene.ron)`.
pub fn check_aliasing(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<()> {
    let ids: Vec<Option<Identity>> = outputs.iter().map(|(_, p)| identity(p)).collect();
    for (i, (role, path)) in outputs.iter().enumerate() {
        let Some(id) = &ids[i] else { continue };
        for (in_role, in_path) in inputs {
            if identity(in_path).as_ref() == Some(id) {
                return Err(Error::Settings(format!(
                    "{role} {} is the {in_role} {}: refusing to overwrite an input",
                    show_path(path),
                    show_path(in_path)
                )));
            }
        }
        for (j, (other_role, other)) in outputs.iter().enumerate().take(i) {
            if ids[j].as_ref() == Some(id) {
                return Err(Error::Settings(format!(
                    "{role} {} and {other_role} {} are the same file",
                    show_path(path),
                    show_path(other)
                )));
            }
        }
    }
    Ok(())
}

/// True when `name` is what a snapshot of an output of stem `stem` is called
/// (`stem-00128.png`: the stem, a dash, five or more digits, `.png`).
pub fn is_snapshot_name(name: &OsStr, stem: &str) -> bool {
    let Some(name) = name.to_str() else { return false };
    name.strip_prefix(stem)
        .and_then(|r| r.strip_prefix('-'))
        .and_then(|r| r.strip_suffix(".png"))
        .is_some_and(|digits| digits.len() >= 5 && digits.bytes().all(|b| b.is_ascii_digit()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rust-v-files-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn inputs_must_be_regular_files() {
        let d = dir("inputs");
        let e = read_input(&d).unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        let e = read_input(Path::new("/dev/null")).unwrap_err().to_string();
        assert!(e.contains("a device"), "{e}");
        std::fs::write(d.join("a.ron"), "x").unwrap();
        assert_eq!(read_input(&d.join("a.ron")).unwrap(), b"x");
    }

    #[test]
    fn outputs_are_checked_before_writing() {
        let d = dir("outputs");
        assert!(check_output(&d.join("ok.png"), "image").is_ok());
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0, "the probe is removed");
        let long = "x".repeat(NAME_MAX - 3) + ".png";
        let e = check_output(&d.join(&long), "image").unwrap_err().to_string();
        assert!(e.contains("at most 255"), "{e}");
        // A legal long name: its temporary name must stay legal too.
        let legal = "y".repeat(NAME_MAX - 4) + ".png";
        check_output(&d.join(&legal), "image").unwrap();
        let e = check_output(&d.join("no/such/x.png"), "image").unwrap_err().to_string();
        assert!(e.contains("its directory"), "{e}");
        let e = check_output(Path::new("/dev/null"), "image").unwrap_err().to_string();
        assert!(e.contains("a device"), "{e}");
        let e = check_output(&d, "checkpoint").unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
    }

    #[test]
    fn aliases_are_found_through_links() {
        let d = dir("alias");
        let scene = d.join("scene.ron");
        std::fs::write(&scene, "x").unwrap();
        std::fs::hard_link(&scene, d.join("hard.ron")).unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(&scene, d.join("soft.ron")).unwrap();
        let inputs = [("scene", scene.as_path())];
        for alias in ["scene.ron", "hard.ron", "soft.ron", "./scene.ron"] {
            let out = d.join(alias);
            let e = check_aliasing(&inputs, &[("checkpoint", &out)]).unwrap_err().to_string();
            assert!(e.contains("refusing to overwrite"), "{alias}: {e}");
        }
        let a = d.join("out.png");
        let b = d.join("sub/../out.png");
        std::fs::create_dir(d.join("sub")).unwrap();
        let e = check_aliasing(&inputs, &[("image", &a), ("checkpoint", &b)]).unwrap_err().to_string();
        assert!(e.contains("are the same file"), "{e}");
        assert!(check_aliasing(&inputs, &[("image", &a), ("checkpoint", &d.join("out.ckpt"))]).is_ok());
    }

    #[test]
    fn snapshot_names() {
        assert!(is_snapshot_name(OsStr::new("out-00128.png"), "out"));
        assert!(is_snapshot_name(OsStr::new("out-1234567.png"), "out"));
        assert!(!is_snapshot_name(OsStr::new("out-128.png"), "out"));
        assert!(!is_snapshot_name(OsStr::new("out.png"), "out"));
    }
}
