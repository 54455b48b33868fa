//! Equal-area environment maps (`environment: Image(..., mapping: EqualArea)`) and
//! pbrt-v4's image infinite lights: a constant map renders like `Uniform`, the
//! furnace, and a map bright in one octant of pbrt's light space lights the
//! directions pbrt-v4 would light (computed here from pbrt's own definitions:
//! `EqualAreaSquareToSphere`, the light's transform, the handedness mirror), with
//! and without a camera transform that swaps handedness; the converted RON renders
//! bit for bit like the `.pbrt`.

use std::path::Path;

use glam::{DMat4, DVec3};
use rust_v::light::Light;
use rust_v::scene::{Scene, load_scene, load_scene_with_warnings};
use rust_v::settings::SettingsPatch;

use crate::common::{mean_and_stderr, render_file, render_str, rust_v, temp_dir};
use crate::pbrt::{assert_same_films, film_of, s, small, write};

/// Writes a linear float EXR of `w` x `h` pixels.
fn exr(path: &Path, w: u32, h: u32, rgb: &[[f32; 3]]) {
    let data: Vec<f32> = rgb.iter().flatten().copied().collect();
    image::Rgb32FImage::from_raw(w, h, data).unwrap().save(path).unwrap();
}

/// A white sphere (ρ 1) and a grey one under a constant equal-area map: the white
/// one's centre is 1 (the furnace), and the image's means match those under
/// `Uniform(Rgb(...))` of the map's colour within 5 standard errors.
#[test]
fn a_constant_equal_area_map_renders_like_uniform_and_passes_the_furnace() {
    let dir = temp_dir("env-equal-area-constant");
    exr(&dir.join("one.exr"), 8, 8, &[[1.0, 1.0, 1.0]; 64]);
    let c = [0.8f32, 0.5, 0.25];
    exr(&dir.join("map.exr"), 8, 8, &[c; 64]);
    let scene = |rho: &str, env: &str| {
        format!(
            r#"(
            camera: (eye: (0.2, 0.1, 3), look_at: (0, 0, 0), fov_deg: 40),
            render: (width: 16, height: 16, spp: 64, max_bounces: 100, integrator: path),
            materials: {{ "m": Lambertian(reflectance: {rho}) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m") ],
            environment: {env},
        )"#
        )
    };
    let path = dir.join("furnace.ron");
    std::fs::write(
        &path,
        scene("Constant(1)", r#"Image(path: "one.exr", mapping: EqualArea, rotate_deg: (20, 40, 0))"#),
    )
    .unwrap();
    let xyz = render_file(&path, &SettingsPatch::default()).mean_xyz();
    let block: Vec<f64> = (4..12).flat_map(|y| (4..12).map(move |x| (x, y))).map(|(x, y)| xyz[y * 16 + x][1]).collect();
    let mean = block.iter().sum::<f64>() / block.len() as f64;
    assert!((mean - 1.0).abs() < 3e-3, "furnace: centre Y = {mean}");
    assert!((xyz[0][1] - 1.0).abs() < 2e-3, "corner Y = {}", xyz[0][1]);

    let path = dir.join("map.ron");
    std::fs::write(&path, scene("Rgb(0.2, 0.6, 0.9)", r#"Image(path: "map.exr", mapping: EqualArea)"#)).unwrap();
    let film = render_file(&path, &SettingsPatch::default());
    let uniform = render_str(
        &scene("Rgb(0.2, 0.6, 0.9)", &format!("Uniform(Rgb({}, {}, {}))", c[0], c[1], c[2])),
        &SettingsPatch::default(),
    );
    for ch in 0..3 {
        let (a, sa) = mean_and_stderr(&film, ch);
        let (b, sb) = mean_and_stderr(&uniform, ch);
        assert!(
            (a - b).abs() < 5.0 * (sa * sa + sb * sb).sqrt() + 1e-4,
            "channel {ch}: map {a} ± {sa}, uniform {b} ± {sb}"
        );
    }
    assert_eq!(film.mean_xyz()[0], uniform.mean_xyz()[0], "the environment seen directly: the same spectrum");
}

/// pbrt-v4's `EqualAreaSquareToSphere` (src/pbrt/util/math.cpp), in f64.
fn pbrt_square_to_sphere(u: f64, v: f64) -> DVec3 {
    let (u, v) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed = 1.0 - (up + vp);
    let r = 1.0 - signed.abs();
    let phi = (if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 }) * std::f64::consts::FRAC_PI_4;
    let z = (1.0 - r * r).copysign(signed);
    let k = r * (2.0 - r * r).max(0.0).sqrt();
    DVec3::new(phi.cos().copysign(u) * k, phi.sin().copysign(v) * k, z)
}

fn environment(scene: &Scene) -> &rust_v::light::EnvironmentLight {
    scene
        .lights
        .iter()
        .find_map(|l| match l {
            Light::Environment(e) => Some(&**e),
            _ => None,
        })
        .expect("an environment")
}

/// A 32x32 map, 10 where pbrt's light-space direction of the texel's centre lies in
/// the octant (+x, +y, +z), 0.01 elsewhere, under `Rotate -90 1 0 0` and `Rotate 30
/// 0 0 1`. pbrt lights world direction `C w` from light-space `w` (C: the light's
/// transform); rust-v's world is pbrt's seen through the importer's mirror `M` (the
/// identity when the camera transform already mirrors: `Scale -1 1 1`). The octant's
/// centre direction must be bright in rust-v at `M C w`, the other seven centres dim;
/// the converted RON renders bit for bit like the `.pbrt` (with the map flipped in
/// memory and written beside the RON when the frame mirrors).
#[test]
fn a_map_bright_in_one_octant_lights_where_pbrt_does() {
    let d = temp_dir("pbrt-envmap-octant");
    let n = 32usize;
    let mut rgb = vec![[0.01f32; 3]; n * n];
    for j in 0..n {
        for i in 0..n {
            let w = pbrt_square_to_sphere((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            if w.x > 0.0 && w.y > 0.0 && w.z > 0.0 {
                rgb[j * n + i] = [10.0; 3];
            }
        }
    }
    exr(&d.join("oct.exr"), n as u32, n as u32, &rgb);
    let light = "AttributeBegin\n Rotate -90 1 0 0\n Rotate 30 0 0 1\n LightSource \"infinite\" \"string filename\" \"oct.exr\"\nAttributeEnd\n\
                 Shape \"sphere\" \"float radius\" 0.2\n";
    let c =
        DMat4::from_axis_angle(DVec3::X, (-90f64).to_radians()) * DMat4::from_axis_angle(DVec3::Z, 30f64.to_radians());
    for (name, camera, mirror) in [
        ("plain", "LookAt 0 0 5  0 0 0  0 1 0\n", DVec3::new(-1.0, 1.0, 1.0)),
        ("mirrored", "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\n", DVec3::ONE),
    ] {
        let p = write(
            &d,
            &format!("{name}.pbrt"),
            &format!(
                "{camera}Camera \"perspective\" \"float fov\" 60\nFilm \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n\
                 Sampler \"zsobol\" \"integer pixelsamples\" 4\nWorldBegin\n{light}"
            ),
        );
        let (scene, warnings) = load_scene_with_warnings(&p, &small(), false).unwrap();
        assert_eq!(warnings.len(), usize::from(name == "mirrored"), "{name}: {warnings:?}");
        let env = environment(&scene);
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                for sz in [-1.0, 1.0] {
                    let w = DVec3::new(sx, sy, sz).normalize();
                    let world = (mirror * c.transform_vector3(w)).as_vec3();
                    let y = env.radiance(world).average();
                    let bright = sx > 0.0 && sy > 0.0 && sz > 0.0;
                    assert!(if bright { y > 5.0 } else { y < 0.1 }, "{name}: light-space {w} (world {world}): {y}");
                }
            }
        }
        let out = d.join(name);
        std::fs::create_dir_all(&out).unwrap();
        let ron = out.join("out.ron");
        let o = rust_v(&["convert", s(&p), "-o", s(&ron)]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(&ron).unwrap();
        assert!(text.contains("mapping: EqualArea"), "{text}");
        assert_eq!(out.join("out-envmap.exr").exists(), name == "mirrored", "{text}");
        assert_same_films(&film_of(&scene), &film_of(&load_scene(&ron, &small()).unwrap()));
    }
}

/// `illuminance` scales a map as pbrt-v4's `lights.cpp` does: by E / k, k = 2π/(w·h)
/// Σ Y cos θ over the upper hemisphere's texels, which for a white map (Y = 1) is
/// (2π/N)·(N/4π)·∫ cos dω = π/2 over the hemisphere: E = 2 gives scale 4/π (1%: the
/// sum over 32² texels). A map that is not square is one error at its `filename`.
#[test]
fn illuminance_scales_a_map_as_pbrt_does_and_a_wide_map_is_an_error_at_its_filename() {
    let d = temp_dir("pbrt-envmap-illuminance");
    exr(&d.join("white.exr"), 32, 32, &[[1.0; 3]; 32 * 32]);
    exr(&d.join("wide.exr"), 4, 2, &[[1.0; 3]; 8]);
    let head = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{head}LightSource \"infinite\" \"string filename\" \"white.exr\" \"float illuminance\" 2\nShape \"sphere\"\n"
        ),
    );
    let (desc, _) = rust_v::scene::pbrt::read_pbrt(&p, true).unwrap();
    match desc.environment {
        Some(rust_v::scene::desc::EnvironmentDesc::Image { scale, .. }) => {
            let want = 4.0 / std::f32::consts::PI;
            assert!((scale / want - 1.0).abs() < 0.01, "scale {scale}, want {want}");
        }
        other => panic!("{other:?}"),
    }
    let p = write(
        &d,
        "w.pbrt",
        &format!("{head}LightSource \"infinite\" \"string filename\" \"wide.exr\"\nShape \"sphere\"\n"),
    );
    let e = crate::pbrt::one_error(&rust_v(&["render", s(&p), "-o", s(&d.join("x.png"))]));
    assert!(e.contains("w.pbrt:4:24: environment.path (from here)") && e.contains("square"), "{e}");
}
