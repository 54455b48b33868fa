//! The medium the camera sits in (`camera: (..., medium:)`) and the check of
//! an object's `exterior:` (`src/scene/surround.rs`).

use std::path::Path;

use rust_v::scene::load_scene_str;
use rust_v::settings::{IntegratorKind, SettingsPatch};

use crate::common::{mean_and_stderr, render_str, rust_v, temp_dir};

fn haze(sigma_a: f32, sigma_s: f32, objects: &str, extra: &str) -> String {
    format!(
        r#"(camera: (eye: (0.2, 0.1, 3), look_at: (0, 0, 0), fov_deg: 40, medium: "haze"),
        render: (width: 16, height: 16, spp: 64, max_bounces: 1000),
        media: {{ "haze": Homogeneous(sigma_a: Constant({sigma_a}), sigma_s: Constant({sigma_s}), phase: HenyeyGreenstein(g: 0.3)) }},
        materials: {{ "white": Lambertian(reflectance: Constant(1)) }},
        objects: [ {objects} ],
        {extra})"#
    )
}

/// A furnace in a haze: a white Lambertian sphere (reflectance 1) with the
/// camera in a medium of albedo 1 (σs 1, a few mean free paths across the
/// sphere that holds it) inside `Uniform(Constant(1))` renders 1 at every
/// pixel with path tracing and BDPT: nothing is lost, so no path that
/// scatters in the haze, crosses its boundary or reaches the environment
/// through it is weighted wrongly. Tolerance: 5 standard errors
/// of the image mean plus 0.5%. With albedo 0.5 the image is darker.
#[test]
fn a_camera_in_a_medium_of_albedo_one_sees_a_furnace() {
    let white = r#"(shape: Sphere(center: (0, 0, 0), radius: 0.3), material: "white")"#;
    let furnace = haze(0.0, 1.0, white, "environment: Uniform(Constant(1))");
    for integrator in [IntegratorKind::Path, IntegratorKind::Bdpt] {
        let film = render_str(&furnace, &SettingsPatch { integrator: Some(integrator), ..Default::default() });
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("camera in haze, albedo 1, {integrator:?}: Y = {mean:.5} ± {se:.5}");
        assert!((mean - 1.0).abs() < 5.0 * se + 5e-3, "{integrator:?}: Y = {mean} ± {se}");
    }
    // Light tracing alone is unbiased here but of infinite variance: a
    // scattering vertex at distance r from the eye connects with weight
    // ∝ 1/r², whose square integrated over the volume around the eye,
    // ∫ r⁻⁴ r² dr, diverges (at 2048 spp the image mean was 1.33 ± 0.38). No
    // tolerance can be stated, so only finiteness is asserted (render_str
    // refuses NaN and infinite samples); docs/failure-matrix.md has the row.
    let film =
        render_str(&furnace, &SettingsPatch { integrator: Some(IntegratorKind::LightTrace), ..Default::default() });
    assert!(mean_and_stderr(&film, 1).0.is_finite());
    let film = render_str(&haze(0.5, 0.5, white, "environment: Uniform(Constant(1))"), &SettingsPatch::default());
    let (mean, se) = mean_and_stderr(&film, 1);
    assert!(mean < 0.9 && mean > 0.05, "albedo 0.5: Y = {mean} ± {se}");
}

/// A camera in a medium that only absorbs (σa 0.5) looking straight at an
/// emitting quad 2 units away: the centre pixels are the clear scene's times
/// exp(−0.5 · 2) per channel (the rays' lengths across the centre pixels vary
/// by less than 0.01%, so 1e-3 relative). The medium is bounded: the
/// uniform environment around the quad is seen through the haze's
/// thickness, darker than 1 and brighter than nothing.
#[test]
fn an_absorbing_camera_medium_attenuates_by_beer_lambert() {
    let quad = r#"(shape: Quad(origin: (-0.5, -0.5, 0), edge_u: (1, 0, 0), edge_v: (0, 1, 0)), emission: Constant(2))"#;
    let scene = |medium: &str| {
        format!(
            r#"(camera: (eye: (0, 0, 2), look_at: (0, 0, 0), fov_deg: 10{medium}),
            render: (width: 8, height: 8, spp: 4),
            media: {{ "ink": Homogeneous(sigma_a: Constant(0.5), sigma_s: Constant(0)) }},
            objects: [ {quad} ],
            environment: Uniform(Constant(1)))"#
        )
    };
    let clear = render_str(&scene(""), &SettingsPatch::default()).mean_xyz();
    let inked = render_str(&scene(r#", medium: "ink""#), &SettingsPatch::default()).mean_xyz();
    let want = (-0.5f64 * 2.0).exp();
    for p in [27, 28, 35, 36] {
        for c in 0..3 {
            let ratio = inked[p][c] / clear[p][c];
            assert!((ratio - want).abs() < 1e-3 * want, "pixel {p}, channel {c}: {ratio} vs {want}");
        }
    }
    // Wide enough to see past the quad: the environment through the haze.
    let wide = scene(r#", medium: "ink""#).replace("fov_deg: 10", "fov_deg: 120");
    let film = render_str(&wide, &SettingsPatch::default());
    let corner = film.mean_xyz()[0][1];
    assert!(corner > 0.05 && corner < 0.9, "the environment through the haze: Y = {corner}");
}

/// The same haze renders bit-identically on 1 and 2 threads.
#[test]
fn a_camera_medium_renders_the_same_on_any_thread_count() {
    let dir = temp_dir("surround-threads");
    let white = r#"(shape: Sphere(center: (0, 0, 0), radius: 0.3), material: "white")"#;
    let file = dir.join("haze.ron");
    std::fs::write(&file, haze(0.2, 1.0, white, "environment: Uniform(Constant(1))")).unwrap();
    for t in ["1", "2"] {
        let out = dir.join(format!("t{t}.exr"));
        let o = rust_v(&[
            "render",
            file.to_str().unwrap(),
            "--spp",
            "8",
            "--threads",
            t,
            "-o",
            out.to_str().unwrap(),
            "--quiet",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(std::fs::read(dir.join("t1.exr")).unwrap(), std::fs::read(dir.join("t2.exr")).unwrap());
}

fn load(text: &str) -> Result<(), String> {
    load_scene_str(text, Path::new("s.ron"), &SettingsPatch::default()).map(|_| ()).map_err(|e| e.to_string())
}

fn nested(exterior_inner: &str, camera: &str) -> String {
    format!(
        r#"(camera: (eye: (0, 0, 5), look_at: (0, 0, 0), fov_deg: 30{camera}),
        media: {{ "milk": Homogeneous(sigma_a: Constant(0.1), sigma_s: Constant(1)),
                  "haze": Homogeneous(sigma_a: Constant(0), sigma_s: Constant(0.1)) }},
        materials: {{ "clear": Interface, "white": Lambertian(reflectance: Constant(0.5)) }},
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 1), material: "clear", interior: "milk"),
            (shape: Sphere(center: (0, 0, 0), radius: 0.2), material: "white"{exterior_inner}),
            (shape: Sphere(center: (3, 0, 0), radius: 0.2), material: "white"),
        ],
        environment: Uniform(Constant(1)))"#
    )
}

/// `exterior:` is checked against the volumes around the object: the small
/// sphere inside the milk may say "milk"; saying "haze" there, or "milk" for
/// a sphere in vacuum, or naming an unknown medium is refused with the field
/// and what surrounds the object. With the camera in "haze", objects outside
/// the milk are in the haze.
#[test]
fn an_exterior_must_match_the_volumes_around_the_object() {
    assert_eq!(load(&nested(r#", exterior: "milk""#, "")), Ok(()));
    let err = load(&nested(r#", exterior: "haze""#, "")).unwrap_err();
    assert!(err.contains("objects[1].exterior") && err.contains("\"milk\", the interior of objects[0]"), "{err}");
    let vacuum = nested("", "").replace(
        r#"(3, 0, 0), radius: 0.2), material: "white")"#,
        r#"(3, 0, 0), radius: 0.2), material: "white", exterior: "milk")"#,
    );
    let err = load(&vacuum).unwrap_err();
    assert!(err.contains("objects[2].exterior") && err.contains("vacuum"), "{err}");
    let err = load(&nested(r#", exterior: "fog""#, "")).unwrap_err();
    assert!(err.contains("objects[1].exterior") && err.contains("unknown medium \"fog\""), "{err}");
    // In the camera's haze: the far sphere's outside is the haze, the milk's too.
    let hazy = nested("", r#", medium: "haze""#)
        .replace(
            r#"(3, 0, 0), radius: 0.2), material: "white")"#,
            r#"(3, 0, 0), radius: 0.2), material: "white", exterior: "haze")"#,
        )
        .replace(r#"interior: "milk")"#, r#"interior: "milk", exterior: "haze")"#);
    assert_eq!(load(&hazy), Ok(()));
    let err = load(&nested(r#", exterior: "haze""#, r#", medium: "haze""#)).unwrap_err();
    assert!(err.contains("objects[1].exterior") && err.contains("milk"), "{err}");
}

/// An unknown camera medium, and a Grid camera medium under Whitted, are
/// refused naming `camera.medium`.
#[test]
fn a_bad_camera_medium_names_the_field() {
    let err = load(&nested("", r#", medium: "smog""#)).unwrap_err();
    assert!(err.contains("camera.medium") && err.contains("unknown medium \"smog\""), "{err}");
    let dir = temp_dir("surround-grid");
    std::fs::write(dir.join("g.vol"), rust_v::medium::grid::write_vol([2, 2, 2], &[1.0; 8])).unwrap();
    let text = nested("", r#", medium: "g""#)
        .replace(r#""haze":"#, r#""g": Grid(path: "g.vol", sigma_a: Constant(0.1), sigma_s: Constant(0.1)), "haze":"#)
        .replace("environment:", "render: (integrator: whitted), environment:");
    let file = dir.join("w.ron");
    std::fs::write(&file, text).unwrap();
    let err = rust_v::scene::load_scene(&file, &SettingsPatch::default()).map(|_| ()).unwrap_err().to_string();
    assert!(err.contains("camera.medium") && err.contains("whitted"), "{err}");
}
