//! A render too big for its process's memory limits is refused before the
//! first pass, with one line naming the limit, instead of aborting at the end
//! with nothing written (issue 34, item 1: under `ulimit -v 4194304` a 2048²
//! `--spectral` render ran for 7-15 s and aborted, exit 134, "memory
//! allocation failed", no image, no checkpoint).

use std::process::Command;

use crate::common::{root, temp_dir};

/// Runs the binary under `ulimit -v KB` (a POSIX shell's, in KiB).
fn under_ulimit(kb: u64, args: &str) -> std::process::Output {
    let bin = env!("CARGO_BIN_EXE_rust-v");
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kb} && exec '{bin}' {args}"))
        .current_dir(root())
        .output()
        .expect("sh runs")
}

#[test]
fn a_render_beyond_the_address_space_limit_is_refused_up_front() {
    if !std::path::Path::new("/proc/self/limits").exists() {
        eprintln!("skipped: no /proc/self/limits (not Linux)");
        return;
    }
    let dir = temp_dir("memory-limit");
    let out = dir.join("e.exr");
    for size in ["--spectral --width 2048 --height 2048", "--width 8192 --height 8192"] {
        let o = under_ulimit(
            4 << 20,
            &format!(
                "render scenes/cornell.ron {size} --spp 1 -q -o '{}' --checkpoint '{}'",
                out.display(),
                dir.join("e.ckpt").display()
            ),
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{size}: {err}");
        assert!(err.contains("needs about") && err.contains("ulimit -v"), "{size}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
        assert!(!out.exists(), "nothing rendered, nothing written");
    }
    // The same limit lets a small render through (the check does not refuse everything).
    let o = under_ulimit(
        4 << 20,
        &format!("render scenes/cornell.ron --width 32 --height 32 --spp 1 -q -o '{}'", out.display()),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists());
}
