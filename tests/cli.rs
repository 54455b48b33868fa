//! The command line: help, and bad input that must fail with a clear message
//! (file, line:column or field, what was expected), a non-zero exit code and
//! no panic.

use crate::common::{rust_v, temp_dir};

/// Runs `render` on a scene text and returns stderr, asserting failure without a panic.
fn fails_with(scene_text: &str, extra: &[&str]) -> String {
    // A fresh folder per call: tests run in parallel threads of one process.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = temp_dir(&format!("bad-{}", CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
    let path = dir.join("bad.ron");
    std::fs::write(&path, scene_text).unwrap();
    let out = dir.join("out.png");
    let mut args = vec!["render", path.to_str().unwrap(), "-o", out.to_str().unwrap(), "--quiet", "--spp", "1"];
    if extra.is_empty() {
        args.extend_from_slice(&["--width", "4", "--height", "4"]);
    }
    args.extend_from_slice(extra);
    let o = rust_v(&args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success(), "expected failure for:\n{scene_text}");
    assert!(!err.contains("panicked") && !err.contains("RUST_BACKTRACE"), "panic: {err}");
    assert!(err.contains("bad.ron") || extra.iter().any(|a| err.contains(a)), "error does not name the file: {err}");
    err
}

const GOOD: &str = r#"(
    camera: (eye: (0, 1, 3), look_at: (0, 1, 0), fov_deg: 45),
    materials: { "white": Lambertian(reflectance: Constant(0.5)) },
    objects: [
        (shape: Sphere(center: (0, 1, 0), radius: 0.5), material: "white"),
        (shape: Sphere(center: (0, 3, 0), radius: 0.5), emission: Constant(5)),
    ],
)"#;

#[test]
fn the_good_scene_renders() {
    let dir = temp_dir("good");
    let path = dir.join("good.ron");
    std::fs::write(&path, GOOD).unwrap();
    let out = dir.join("good.png");
    let o = rust_v(&[
        "render",
        path.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "6",
        "--spp",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    // Not a terminal: no bar, only the summary (tests/hostile.rs checks the plain progress lines).
    assert!(err.contains("wrote") && err.contains("Msamples/s") && !err.contains('\r'), "summary: {err}");
    assert_eq!(image::open(&out).unwrap().width(), 8);
}

#[test]
fn missing_scene_file() {
    let o = rust_v(&["render", "no/such/scene.ron", "--quiet"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("no/such/scene.ron") && err.contains("No such file"), "{err}");
}

#[test]
fn syntax_error_names_line_and_column() {
    let bad = GOOD.replace("fov_deg: 45)", "fov_deg: 45");
    let err = fails_with(&bad, &[]);
    assert!(err.contains("bad.ron:3:"), "{err}");
}

#[test]
fn unknown_field_is_an_error_with_position() {
    let err = fails_with(&GOOD.replace("fov_deg: 45", "fov_deg: 45, focus: 2"), &[]);
    assert!(err.contains("bad.ron:2:") && err.contains("focus"), "{err}");
}

#[test]
fn unknown_colour_and_material_names() {
    let err = fails_with(&GOOD.replace("Constant(0.5)", "ColorChecker(\"mauve\")"), &[]);
    assert!(
        err.contains("materials.\"white\".reflectance") && err.contains("mauve") && err.contains("dark skin"),
        "{err}"
    );
    let err = fails_with(&GOOD.replace("material: \"white\"", "material: \"whte\""), &[]);
    assert!(err.contains("objects[0].material") && err.contains("whte"), "{err}");
    let err = fails_with(&GOOD.replace("Lambertian(", "Lambertan("), &[]);
    assert!(err.contains("bad.ron:3:") && err.contains("Lambertan"), "{err}");
}

#[test]
fn missing_and_broken_meshes() {
    let mesh = GOOD.replace("Sphere(center: (0, 1, 0), radius: 0.5)", "Mesh(path: \"nothere.obj\")");
    let err = fails_with(&mesh, &[]);
    assert!(err.contains("nothere.obj"), "{err}");
    // A PLY with a face index out of range, next to the scene file.
    let dir = temp_dir("broken-mesh");
    std::fs::write(dir.join("broken.ply"), "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").unwrap();
    let scene = dir.join("bad.ron");
    std::fs::write(&scene, GOOD.replace("Sphere(center: (0, 1, 0), radius: 0.5)", "Mesh(path: \"broken.ply\")"))
        .unwrap();
    let o = rust_v(&["render", scene.to_str().unwrap(), "-o", dir.join("o.png").to_str().unwrap(), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("broken.ply") && !err.contains("panicked"), "{err}");
}

#[test]
fn zero_and_negative_sizes() {
    let err = fails_with(&GOOD.replace("radius: 0.5)", "radius: -0.5)"), &[]);
    assert!(err.contains("objects[0].shape.radius") && err.contains("positive"), "{err}");
    let err = fails_with(&GOOD.replace("camera:", "render: (width: 0), camera:"), &["--height", "4"]);
    assert!(err.contains("render.width") && err.contains("positive"), "{err}");
    let err = fails_with(GOOD, &["--width", "0"]);
    assert!(err.contains("--width") && err.contains('0'), "{err}");
    let err = fails_with(&GOOD.replace("fov_deg: 45", "fov_deg: 0"), &[]);
    assert!(err.contains("camera.fov_deg"), "{err}");
}

#[test]
fn help_documents_every_render_flag() {
    let o = rust_v(&["render", "--help"]);
    let help = String::from_utf8_lossy(&o.stdout);
    for flag in [
        "--output",
        "--spp",
        "--seed",
        "--threads",
        "--width",
        "--height",
        "--quiet",
        "--integrator",
        "--wavelengths",
        "--packet-size",
        "--max-bounces",
        "--color-space",
    ] {
        assert!(help.contains(flag), "--help lacks {flag}");
    }
}
