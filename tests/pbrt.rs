//! pbrt-v4 scene files (`rust-v render scene.pbrt`, `rust-v convert`, `--strict`):
//! the parser's errors and warnings, transforms and pbrt's left-handed camera
//! computed by hand, Include, and the converted RON rendering bit for bit like
//! the `.pbrt` it came from.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::AtomicBool;

use rust_v::film::Film;
use rust_v::render::{Limits, render};
use rust_v::scene::desc::{LightDesc, MaterialDesc, ShapeDesc, SpectrumDesc};
use rust_v::scene::pbrt::read_pbrt;
use rust_v::scene::{Scene, load_scene, load_scene_with_warnings};
use rust_v::settings::SettingsPatch;

use crate::common::{root, rust_v, temp_dir};

pub(crate) fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    if let Some(d) = p.parent() {
        std::fs::create_dir_all(d).unwrap();
    }
    std::fs::write(&p, text).unwrap();
    p
}

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

pub(crate) fn film_of(scene: &Scene) -> Film {
    let st = &scene.settings;
    let mut film = Film::new(st.width, st.height);
    let stop = AtomicBool::new(false);
    let stats = render(scene, &mut film, 0..st.spp, Limits { stop: &stop, time_budget: None }, &mut |_, _| {});
    assert_eq!(stats.invalid_samples, 0, "NaN or infinite samples");
    film
}

pub(crate) fn small() -> SettingsPatch {
    SettingsPatch { width: Some(24), height: Some(24), spp: Some(4), ..Default::default() }
}

/// The error line of a command that must fail with exit status 1: exactly one
/// `rust-v: error:` line, no panic.
pub(crate) fn one_error(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "exit status; stderr:\n{err}");
    assert!(!err.contains("panicked"), "a panic:\n{err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("rust-v: error:")).collect();
    assert_eq!(lines.len(), 1, "expected one error line:\n{err}");
    lines[0].to_string()
}

pub(crate) const HEAD: &str = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 90\n\
Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 24\nSampler \"zsobol\" \"integer pixelsamples\" 4\nWorldBegin\n";

// ---------------------------------------------------------------------------
// Syntax errors: FILE:LINE:COL and what was expected, one line, exit 1.

#[test]
fn syntax_errors_name_the_file_line_and_column() {
    let d = temp_dir("pbrt-errors");
    let cases: &[(&str, &str, &str)] = &[
        ("Shape \"sphere\" \"float radius\" [ 1 ]\nShape \"sphere\n", "7:7", "unterminated string"),
        ("Shape \"sphere\"\n  Frobnicate 3\n", "7:3", "unknown directive `Frobnicate`"),
        ("Shape \"sphere\" \"float radius\" \"big\"\n", "6:31", "\"float radius\" expects numbers"),
        ("Shape \"sphere\" \"flaot radius\" 1\n", "6:16", "unknown parameter type \"flaot\""),
        ("Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 ]\n", "6:20", "expected exactly 3 values"),
        ("AttributeEnd\n", "6:1", "without a matching AttributeBegin"),
        (
            "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 3]\n",
            "6:53",
            "out of range",
        ),
        ("NamedMaterial \"nope\"\n", "6:15", "unknown material \"nope\""),
    ];
    for (i, (body, at, what)) in cases.iter().enumerate() {
        let scene = write(&d, &format!("e{i}.pbrt"), &format!("{HEAD}{body}"));
        let o = rust_v(&["render", s(&scene), "-o", s(&d.join("x.png"))]);
        let e = one_error(&o);
        assert!(e.contains(&format!("e{i}.pbrt:{at}:")), "case {i}: expected position {at}: {e}");
        assert!(e.contains(what), "case {i}: expected {what:?}: {e}");
    }
}

#[test]
fn include_cycles_and_missing_files_are_errors_at_the_include() {
    let d = temp_dir("pbrt-include-errors");
    write(&d, "a.pbrt", "# a\nInclude \"b.pbrt\"\n");
    write(&d, "b.pbrt", "\n\n   Include \"a.pbrt\"\n");
    let main = write(&d, "main.pbrt", &format!("{HEAD}Include \"a.pbrt\"\n"));
    let e = load_scene(&main, &small()).unwrap_err().to_string();
    assert!(e.contains("b.pbrt:3:12:") && e.contains("cycle"), "{e}");
    let main = write(&d, "missing.pbrt", &format!("{HEAD}Include \"nowhere/c.pbrt\"\n"));
    let e = load_scene(&main, &small()).unwrap_err().to_string();
    assert!(e.contains("missing.pbrt:6:9:") && e.contains("nowhere/c.pbrt"), "{e}");
}

#[test]
fn a_scene_without_world_begin_says_so() {
    let d = temp_dir("pbrt-noworld");
    let p = write(&d, "s.pbrt", "Camera \"perspective\"\n");
    let e = load_scene(&p, &small()).unwrap_err().to_string();
    assert!(e.contains("no WorldBegin"), "{e}");
}

// ---------------------------------------------------------------------------
// Structure: attributes restore the transform, Include paths, inputs.

fn sphere_centers(path: &Path) -> Vec<[f32; 3]> {
    let (desc, _) = read_pbrt(path, false).unwrap();
    desc.objects
        .iter()
        .filter_map(|o| match o.shape {
            ShapeDesc::Sphere { center, .. } => Some(center),
            _ => None,
        })
        .collect()
}

#[test]
fn attribute_end_restores_the_transform_and_material() {
    let d = temp_dir("pbrt-attrs");
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{HEAD}Translate 0 1 0\nAttributeBegin\n Translate 0 0 2\n AttributeBegin\n  Scale 5 5 5\n AttributeEnd\n \
             Material \"conductor\"\n Shape \"sphere\"\nAttributeEnd\nShape \"sphere\"\n"
        ),
    );
    let (desc, _) = read_pbrt(&p, false).unwrap();
    // Both spheres keep radius 1 (the Scale was undone); the second is back at y = 1, z = 0.
    let got: Vec<([f32; 3], f32, Option<String>)> = desc
        .objects
        .iter()
        .map(|o| match &o.shape {
            ShapeDesc::Sphere { center, radius } => (*center, *radius, o.material.clone()),
            s => panic!("{s:?}"),
        })
        .collect();
    assert_eq!(got[0].0, [0.0, 1.0, 2.0]);
    assert_eq!(got[1].0, [0.0, 1.0, 0.0]);
    assert_eq!((got[0].1, got[1].1), (1.0, 1.0));
    assert_ne!(got[0].2, got[1].2, "the material set inside the block is not kept after it");
    assert!(matches!(
        desc.materials.0.iter().find(|(n, _)| Some(n) == got[1].2.as_ref()),
        Some((_, MaterialDesc::Lambertian { .. }))
    ));
}

#[test]
fn include_paths_are_relative_to_the_main_file_and_are_inputs() {
    let d = temp_dir("pbrt-include");
    // pbrt-v4 resolves every relative path against the main file's folder, also inside
    // an included file.
    write(&d, "geo/a.pbrt", "Include \"geo/b.pbrt.gz\"\nShape \"sphere\"\n");
    // b is gzipped, as pbrt-v4 allows.
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    std::io::Write::write_all(&mut gz, b"Translate 3 0 0 Shape \"sphere\"\n").unwrap();
    std::fs::write(d.join("geo/b.pbrt.gz"), gz.finish().unwrap()).unwrap();
    let main = write(
        &d,
        "main.pbrt",
        &format!("{HEAD}AttributeBegin\nInclude \"geo/a.pbrt\"\nAttributeEnd\nShape \"sphere\"\n"),
    );
    // Mirrored x (see the handedness test): pbrt's x = 3 is rust-v's x = -3.
    assert_eq!(sphere_centers(&main), vec![[-3.0, 0.0, 0.0], [-3.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
    let scene = load_scene(&main, &small()).unwrap();
    let names: Vec<String> =
        scene.inputs.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["a.pbrt", "b.pbrt.gz"]);
    // A changed include changes the scene's identity (resume and merge refuse it).
    let before = scene.content_hash;
    write(&d, "geo/b.pbrt.gz", "not gzip");
    let e = load_scene(&main, &small()).err().map(|e| e.to_string()).expect("an error");
    assert!(e.contains("a.pbrt:1:9:") && e.contains("gzip"), "{e}");
    write(&d, "geo/a.pbrt", "Include \"geo/c.pbrt\"\nShape \"sphere\"\n");
    write(&d, "geo/c.pbrt", "Translate 3 0 0 Shape \"sphere\"\n");
    assert_ne!(load_scene(&main, &small()).unwrap().content_hash, before);
}

// ---------------------------------------------------------------------------
// Where things land: by hand, from pbrt-v4's definitions.

/// pbrt-v4's raster position of world point `p` for `LookAt eye look up` and a
/// square film of `n` pixels with `fov` degrees: camera space is x = normalize(up ×
/// dir) (pbrt's LookAt), y = dir × x, z = dir; raster x = (1 + x/z / tan(fov/2)) n / 2,
/// raster y = (1 − y/z / tan(fov/2)) n / 2 (pbrt's screen-to-raster flips y only).
fn pbrt_raster(eye: [f64; 3], look: [f64; 3], up: [f64; 3], fov: f64, n: f64, p: [f64; 3]) -> (f64, f64) {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross =
        |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let norm = |a: [f64; 3]| {
        let l = dot(a, a).sqrt();
        [a[0] / l, a[1] / l, a[2] / l]
    };
    let dir = norm(sub(look, eye));
    let x = norm(cross(norm(up), dir));
    let y = cross(dir, x);
    let q = sub(p, eye);
    let (cx, cy, cz) = (dot(q, x), dot(q, y), dot(q, dir));
    let t = (fov.to_radians() / 2.0).tan();
    ((1.0 + cx / cz / t) * n / 2.0, (1.0 - cy / cz / t) * n / 2.0)
}

#[test]
fn look_at_and_translate_put_the_object_where_pbrt_does() {
    let d = temp_dir("pbrt-where");
    let (eye, look, up) = ([1.0, 2.0, 6.0], [0.5, 0.0, 0.0], [0.2, 1.0, 0.0]);
    let p = write(
        &d,
        "s.pbrt",
        "LookAt 1 2 6  0.5 0 0  0.2 1 0\nCamera \"perspective\" \"float fov\" 50\n\
         Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 64\nWorldBegin\n\
         AttributeBegin\n Translate 1.5 -0.5 0.75\n Rotate 30 0 1 0\n Translate 0.4 0 0\n Shape \"sphere\" \"float radius\" 0.1\nAttributeEnd\n",
    );
    // The sphere's centre by hand: Translate(1.5, -0.5, 0.75) · RotateY(30°) · (0.4, 0, 0).
    let (c, sn) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let world = [1.5 + 0.4 * c, -0.5, 0.75 - 0.4 * sn];
    let want = pbrt_raster(eye, look, up, 50.0, 64.0, world);
    let scene = load_scene(&p, &SettingsPatch::default()).unwrap();
    let center = sphere_centers(&p)[0];
    let dir = (glam::Vec3::from(center) - scene.camera.eye()).normalize();
    let got = scene.camera.project(dir).expect("the sphere is in view");
    assert!(
        (got.x as f64 - want.0).abs() < 1e-3 && (got.y as f64 - want.1).abs() < 1e-3,
        "rust-v {got:?}, pbrt {want:?}"
    );
    // And not its mirror image: the point is well off the centre column.
    assert!((want.0 - 32.0).abs() > 3.0, "{want:?}");
}

#[test]
fn fov_is_the_shorter_side_and_portrait_films_convert_it() {
    let d = temp_dir("pbrt-fov");
    let p = write(
        &d,
        "s.pbrt",
        "Camera \"perspective\" \"float fov\" 40 \"float lensradius\" 0.05 \"float focaldistance\" 3\n\
         Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 200\n\
         WorldBegin\nShape \"sphere\"\n",
    );
    let (desc, _) = read_pbrt(&p, false).unwrap();
    // No Sampler or Integrator: pbrt-v4's defaults (16 spp, path with maxdepth 5).
    let r = &desc.render;
    assert_eq!((r.width, r.height, r.spp, r.max_bounces), (Some(100), Some(200), Some(16), Some(5)));
    // The 40° spans the 100-pixel width; rust-v's vertical fov spans 200 pixels.
    let want = 2.0 * (20f64.to_radians().tan() * 2.0).atan().to_degrees();
    // pbrt's thin lens: the same radius and focal plane distance.
    assert_eq!((desc.camera.aperture_radius, desc.camera.focus_distance), (0.05, Some(3.0)));
    let fov = desc.camera.fov_deg.expect("a fov") as f64;
    assert!((fov - want).abs() < 1e-4, "{fov} vs {want}");
}

#[test]
fn the_image_is_not_mirrored() {
    // pbrt's camera space is left-handed: looking from +z towards the origin with +y up,
    // pbrt's image right is up × dir = −x. So a red emitter at x = +1 is on the image's
    // left, a blue one at x = −1 on its right.
    let d = temp_dir("pbrt-handed");
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{HEAD}AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [1 0 0]\n Translate 1 0 0\n Shape \"sphere\" \"float radius\" 0.6\nAttributeEnd\n\
             AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [0 0 1]\n Translate -1 0 0\n Shape \"sphere\" \"float radius\" 0.6\nAttributeEnd\n"
        ),
    );
    let scene = load_scene(&p, &small()).unwrap();
    let film = film_of(&scene);
    let xyz = film.mean_xyz();
    let (w, h) = (24usize, 24usize);
    let half = |left: bool| {
        let mut sum = [0.0; 3];
        for y in 0..h {
            for x in 0..w {
                if (x < w / 2) == left {
                    (0..3).for_each(|c| sum[c] += xyz[y * w + x][c]);
                }
            }
        }
        sum
    };
    let (l, r) = (half(true), half(false));
    // Red has X well above Z, blue Z well above X (sRGB primaries in XYZ).
    assert!(l[0] > 2.0 * l[2] && l[0] > 0.5, "left half should be red: XYZ {l:?}");
    assert!(r[2] > 2.0 * r[0] && r[2] > 0.5, "right half should be blue: XYZ {r:?}");
    // The same with a camera that mirrors itself (Scale -1 1 1 before LookAt, as
    // exporters write): pbrt's right is then +x, so red is on the right.
    let p = write(&d, "m.pbrt", &format!("Scale -1 1 1\n{}", std::fs::read_to_string(&p).unwrap()));
    let film = film_of(&load_scene(&p, &small()).unwrap());
    let xyz = film.mean_xyz();
    let right_red: f64 = (0..h).flat_map(|y| (w / 2..w).map(move |x| y * w + x)).map(|i| xyz[i][0] - xyz[i][2]).sum();
    assert!(right_red > 0.5, "with Scale -1 1 1 red is on the right: {right_red}");
}

// ---------------------------------------------------------------------------
// Mapping: lights normalised as pbrt-v4 does.

#[test]
fn light_spectra_are_normalised_to_luminance_as_pbrt_does() {
    let d = temp_dir("pbrt-lights");
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{HEAD}LightSource \"point\" \"blackbody I\" 3000 \"float scale\" 2 \"point3 from\" [1 2 3]\n\
             LightSource \"point\" \"rgb I\" [0.5 0.25 1] \"float power\" 100\n\
             LightSource \"infinite\" \"rgb L\" [0.1 0.2 0.3]\nShape \"sphere\"\n"
        ),
    );
    let (desc, w) = read_pbrt(&p, false).unwrap();
    assert!(w.is_empty(), "{w:?}");
    // A spectrum: scaled to luminance `scale`; an RGB: its illuminant has luminance 1, so
    // the RGB times scale (and `power` / 4π for a point light).
    match &desc.lights[0] {
        LightDesc::Point { position, intensity: SpectrumDesc::Luminance(y, b) } => {
            assert_eq!(*position, [-1.0, 2.0, 3.0]);
            assert_eq!(*y, 2.0);
            assert!(matches!(**b, SpectrumDesc::Blackbody(t) if t == 3000.0));
        }
        l => panic!("{l:?}"),
    }
    match &desc.lights[1] {
        LightDesc::Point { intensity: SpectrumDesc::Scaled(k, rgb), .. } => {
            assert!((*k as f64 - 100.0 / (4.0 * std::f64::consts::PI)).abs() < 1e-5, "{k}");
            assert!(matches!(**rgb, SpectrumDesc::Rgb(r, g, b) if (r, g, b) == (0.5, 0.25, 1.0)));
        }
        l => panic!("{l:?}"),
    }
    assert!(desc.environment.is_some());
}

// ---------------------------------------------------------------------------
// Warnings and --strict.

#[test]
fn unsupported_things_warn_once_with_a_count_and_strict_makes_them_errors() {
    let d = temp_dir("pbrt-strict");
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "PixelFilter \"gaussian\"\n{HEAD}Shape \"sphere\" \"float radiuss\" 2\nShape \"sphere\" \"float radiuss\" 3\n\
             Shape \"sphere\" \"float radiuss\" 4\n"
        ),
    );
    let (_, warnings) = load_scene_with_warnings(&p, &small(), false).unwrap();
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(
        warnings[0]
            .ends_with("s.pbrt:1:13: PixelFilter \"gaussian\" is not supported: rust-v uses a one-pixel box filter"),
        "{warnings:?}"
    );
    assert!(
        warnings[1].contains("s.pbrt:7:16:")
            && warnings[1].contains("\"float radiuss\" is not supported (ignored); read here: alpha, emissionfilename, phimax, radius, zmax, zmin")
            && warnings[1].ends_with("(and 2 more)"),
        "{warnings:?}"
    );
    let e = load_scene_with_warnings(&p, &small(), true).unwrap_err().to_string();
    assert!(e.contains("s.pbrt:1:13:") && e.contains("gaussian") && e.contains("--strict"), "{e}");

    // The command line: the warning printer, and --strict's one error line.
    let out = d.join("x.png");
    let o = rust_v(&["render", s(&p), "-o", s(&out), "-q"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.lines().any(|l| l.starts_with("rust-v: warning: ") && l.contains("s.pbrt:1:13: PixelFilter")), "{err}");
    let e = one_error(&rust_v(&["render", s(&p), "-o", s(&out), "--strict"]));
    assert!(e.contains("s.pbrt:1:13:"), "{e}");
    let e = one_error(&rust_v(&["convert", s(&p), "-o", s(&d.join("x.ron")), "--strict"]));
    assert!(e.contains("s.pbrt:1:13:"), "{e}");
    // Notes (understood, not carried over) stay warnings under --strict.
    let p = write(&d, "n.pbrt", &format!("Film \"rgb\" \"string filename\" \"a.exr\"\n{HEAD}Shape \"sphere\"\n"));
    let (_, w) = load_scene_with_warnings(&p, &small(), true).unwrap();
    assert!(w.len() == 1 && w[0].contains("filename"), "{w:?}");
}

// ---------------------------------------------------------------------------
// convert: the RON renders the same image bit for bit.

pub(crate) fn assert_same_films(a: &Film, b: &Film) {
    let (x, y) = (a.mean_xyz(), b.mean_xyz());
    assert_eq!(x.len(), y.len());
    for (i, (p, q)) in x.iter().zip(&y).enumerate() {
        assert!(p.iter().zip(q).all(|(u, v)| u.to_bits() == v.to_bits()), "pixel {i}: {p:?} vs {q:?}");
    }
}

#[test]
fn converted_cornell_box_renders_bit_identically() {
    // Named glass (glass-BK7), named metal (metal-Au), an Include and instancing.
    let d = temp_dir("pbrt-convert");
    let src = root().join("scenes/pbrt/cornell.pbrt");
    let ron = d.join("cornell.ron");
    let o = rust_v(&["convert", s(&src), "-o", s(&ron)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a = film_of(&load_scene(&src, &small()).unwrap());
    let b = film_of(&load_scene(&ron, &small()).unwrap());
    assert_same_films(&a, &b);
    // Something was rendered: the light and the walls are not black.
    assert!(a.mean_xyz().iter().map(|p| p[1]).sum::<f64>() > 1.0);
}

#[test]
fn plymesh_is_placed_in_world_space_and_converted_to_a_mesh_file() {
    let d = temp_dir("pbrt-ply");
    // A binary PLY quad with normals and uvs, facing +z in object space.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for (x, y, u, v) in
        [(-1.0f32, -1.0f32, 0.0f32, 0.0f32), (1.0, -1.0, 1.0, 0.0), (1.0, 1.0, 1.0, 1.0), (-1.0, 1.0, 0.0, 1.0)]
    {
        for f in [x, y, 0.0, 0.0, 0.0, 1.0, u, v] {
            ply.extend_from_slice(&f.to_le_bytes());
        }
    }
    ply.push(4);
    for i in [0i32, 1, 2, 3] {
        ply.extend_from_slice(&i.to_le_bytes());
    }
    std::fs::create_dir_all(d.join("geometry")).unwrap();
    std::fs::write(d.join("geometry/quad.ply"), &ply).unwrap();
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{HEAD}LightSource \"distant\" \"point3 from\" [0 0 5] \"point3 to\" [0 0 0] \"rgb L\" [1 1 1]\n\
             Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" 4 \"float vscale\" 4 \"rgb tex1\" [0.8 0.1 0.1]\n\
             Material \"diffuse\" \"texture reflectance\" \"checks\"\n\
             AttributeBegin\n Rotate 20 0 1 0\n Scale 1.5 1 1\n Shape \"plymesh\" \"string filename\" \"geometry/quad.ply\"\nAttributeEnd\n"
        ),
    );
    let scene = load_scene(&p, &small()).unwrap();
    assert!(scene.inputs.iter().any(|i| i.ends_with("geometry/quad.ply")), "{:?}", scene.inputs);
    let out_dir = d.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    let ron = out_dir.join("s.ron");
    let o = rust_v(&["convert", s(&p), "-o", s(&ron)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&ron).unwrap();
    assert!(text.contains("Mesh(") && text.contains("\"s-mesh-0.ply\""), "{text}");
    let a = film_of(&scene);
    let b = film_of(&load_scene(&ron, &small()).unwrap());
    assert_same_films(&a, &b);
    assert!(a.mean_xyz().iter().map(|p| p[0]).sum::<f64>() > 0.1, "the quad is lit and seen");
}

#[test]
fn the_shipped_pbrt_scene_loads_without_unexpected_warnings() {
    let (_, w) = load_scene_with_warnings(&root().join("scenes/pbrt/cornell.pbrt"), &small(), true).unwrap();
    // Notes only: the film's file name and the flattened instances.
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("Film \"filename\"") && w[1].contains("ObjectInstance") && w[1].ends_with("(and 1 more)"),
        "{w:?}"
    );
}

/// `ObjectBegin`/`ObjectInstance` of meshes is native: one group (its meshes in object
/// space, placed by their CTMs), one `Instance` object per `ObjectInstance` placed by a
/// matrix (a mirror among them), no note about copies. It renders like the same
/// shapes written out under the same transforms (the importer's copies, an independent
/// path: same samples, so 8×8 block means within 1% of the image mean), and its
/// conversion writes `groups:`, `Instance` and the group's PLY triangles as a file, and
/// renders bit for bit like the `.pbrt`.
#[test]
fn object_instances_are_native_and_convert_bit_identically() {
    let d = temp_dir("pbrt-instances");
    let tet = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
element face 4\nproperty list uchar int vertex_indices\nend_header\n\
-0.4 -0.4 -0.3\n0.5 -0.4 -0.2\n-0.1 -0.4 0.5\n0.1 0.4 0.0\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
    std::fs::write(d.join("tet.ply"), tet).unwrap();
    let body = "AttributeBegin\n Translate 0 0.5 0\n Material \"diffuse\" \"rgb reflectance\" [0.7 0.2 0.2]\n \
        Shape \"trianglemesh\" \"point3 P\" [-0.3 0 -0.3 0.3 0 -0.3 0.3 0 0.3 -0.3 0 0.3 0 0.4 0] \
        \"integer indices\" [0 1 4 1 2 4 2 3 4 3 0 4 0 2 1 0 3 2]\nAttributeEnd\n\
        Shape \"plymesh\" \"string filename\" \"tet.ply\"\n";
    let places = [
        "Translate -1.2 0 0\n Rotate 30 0 1 0",
        "Translate 1.2 0.2 0\n Scale -1 1 1",
        "Translate 0 -1 -1\n Scale 0.6 0.9 0.6",
    ];
    let light = "LightSource \"point\" \"point3 from\" [1 3 4] \"rgb I\" [8 8 8]\nLightSource \"infinite\" \"rgb L\" [0.2 0.2 0.2]\n";
    let each = |f: &dyn Fn(&str) -> String| {
        places.iter().map(|p| format!("AttributeBegin\n{p}\n{}AttributeEnd\n", f(p))).collect::<String>()
    };
    let instanced = write(
        &d,
        "inst.pbrt",
        &format!(
            "{HEAD}{light}ObjectBegin \"thing\"\n{body}ObjectEnd\n{}",
            each(&|_| "ObjectInstance \"thing\"\n".into())
        ),
    );
    let copies = write(&d, "copies.pbrt", &format!("{HEAD}{light}{}", each(&|_| body.to_string())));
    let (scene, w) = load_scene_with_warnings(&instanced, &small(), false).unwrap();
    assert!(!w.iter().any(|w| w.contains("ObjectInstance")), "{w:?}");
    let (desc, _) = read_pbrt(&instanced, false).unwrap();
    assert_eq!(desc.groups.0.len(), 1);
    assert_eq!(desc.groups.0[0].1.len(), 2);
    let instances: Vec<_> =
        desc.objects.iter().filter(|o| matches!(&o.shape, ShapeDesc::Instance { group } if group == "thing")).collect();
    assert_eq!(instances.len(), 3);
    assert!(instances.iter().all(|o| o.transform.as_ref().is_some_and(|t| t.matrix.is_some())));
    assert_eq!(scene.objects.iter().filter(|o| matches!(o.shape, rust_v::shape::Shape::Instance(_))).count(), 6);
    let a = film_of(&scene);
    let c = film_of(&load_scene(&copies, &small()).unwrap());
    let (ba, bc) = (crate::common::block_means(&a, 8), crate::common::block_means(&c, 8));
    let mean = ba.iter().sum::<f64>() / ba.len() as f64;
    let diff = ba.iter().zip(&bc).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    println!("native instances vs copies: largest block difference {diff:.2e}, image mean {mean:.4}");
    assert!(mean > 0.01 && diff < 0.01 * mean, "{diff} (mean {mean})");
    let ron = d.join("out.ron");
    let o = rust_v(&["convert", s(&instanced), "-o", s(&ron), "--strict"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&ron).unwrap();
    assert!(
        text.contains("groups:")
            && text.contains("Instance(")
            && text.contains("group: \"thing\"")
            && text.contains("\"out-group-0-mesh-1.ply\""),
        "{text}"
    );
    assert!(d.join("out-group-0-mesh-1.ply").exists());
    assert_same_films(&a, &film_of(&load_scene(&ron, &small()).unwrap()));
    // A group member's error is at its `Shape` directive, the field kept in the message.
    let flat = write(
        &d,
        "flat.pbrt",
        &format!(
            "{HEAD}ObjectBegin \"t\"\n  Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 2 0 0] \"integer indices\" [0 1 2]\nObjectEnd\nObjectInstance \"t\"\n"
        ),
    );
    let e = load_scene(&flat, &small()).err().map(|e| e.to_string()).expect("an error");
    assert!(e.contains("flat.pbrt:7:9:") && e.contains("groups.\"t\"[0]") && e.contains("no valid triangles"), "{e}");
}

// ---------------------------------------------------------------------------
// Hostile files and the commands that take a scene.

#[test]
fn hostile_pbrt_files_give_one_error_line() {
    let d = temp_dir("pbrt-hostile");
    // A chain of 40 includes (no cycle) is stopped at the depth limit.
    for i in 0..40 {
        write(&d, &format!("i{i}.pbrt"), &format!("Include \"i{}.pbrt\"\n", i + 1));
    }
    write(&d, "i40.pbrt", "Shape \"sphere\"\n");
    let deep = write(&d, "deep.pbrt", &format!("{HEAD}Include \"i0.pbrt\"\n"));
    let cases: Vec<(PathBuf, &str)> = vec![
        (deep, "nested more than 32 deep"),
        (write(&d, "nan.pbrt", &format!("{HEAD}Shape \"sphere\" \"float radius\" nan\n")), "expects numbers"),
        (write(&d, "inf.pbrt", &format!("{HEAD}Translate 1e999 0 0\n")), "expected a finite number"),
        (write(&d, "nested.pbrt", &format!("{HEAD}Shape \"sphere\" \"float radius\" [ [ 1 ] ]\n")), "do not nest"),
        (write(&d, "open.pbrt", &format!("{HEAD}Shape \"sphere\" \"float radius\" [ 1\n")), "the file ends here"),
        (write(&d, "short.pbrt", &format!("{HEAD}LookAt 1 2 3\n")), "9 numbers for LookAt"),
        (write(&d, "zero.pbrt", &format!("{HEAD}Rotate 30 0 0 0\n")), "non-zero axis"),
        (write(&d, "two.pbrt", &format!("{HEAD}WorldBegin\n")), "a second WorldBegin"),
        (write(&d, "pre.pbrt", "Shape \"sphere\"\nWorldBegin\n"), "before WorldBegin"),
        (write(&d, "bad.pbrt", &format!("{HEAD}Shape \"plymesh\" \"string filename\" \"no.ply\"\n")), "no.ply"),
    ];
    for (p, what) in cases {
        let e = one_error(&rust_v(&["render", s(&p), "-o", s(&d.join("x.png"))]));
        assert!(e.contains(what), "{}: expected {what:?}: {e}", p.display());
        assert!(e.contains(".pbrt:"), "names the file: {e}");
    }
    // A long token is reported shortened.
    let long = "A".repeat(1 << 20);
    let p = write(&d, "long.pbrt", &format!("{HEAD}{long}\n"));
    let e = one_error(&rust_v(&["render", s(&p), "-o", s(&d.join("x.png"))]));
    assert!(e.len() < 400 && e.contains("long.pbrt:6:1: unknown directive"), "{e}");
}

#[test]
fn resume_works_on_a_pbrt_scene_and_refuses_a_changed_include() {
    let d = temp_dir("pbrt-resume");
    write(&d, "geo.pbrt", "Shape \"sphere\"\n");
    let p =
        write(&d, "s.pbrt", &format!("{HEAD}LightSource \"point\" \"point3 from\" [0 3 3]\nInclude \"geo.pbrt\"\n"));
    let (out, ckpt) = (d.join("a.exr"), d.join("a.ckpt"));
    let o = rust_v(&["render", s(&p), "-o", s(&out), "--spp", "2", "--checkpoint", s(&ckpt), "-q"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = rust_v(&["resume", s(&ckpt), "--spp", "4", "-q"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    write(&d, "geo.pbrt", "Shape \"sphere\" \"float radius\" 0.5\n");
    let e = one_error(&rust_v(&["resume", s(&ckpt), "--spp", "6", "-q"]));
    assert!(e.contains("geo.pbrt") && e.contains("changed"), "{e}");
}

#[test]
fn a_killeroo_like_scene_loads_without_unexpected_warnings_and_renders() {
    // The structure of pbrt-v4-scenes' killeroo-simple.pbrt (written here, not copied):
    // a Rotate before the camera, a halton sampler, an emitting sphere, uv'd
    // trianglemesh walls, coateddiffuse and an included loopsubdiv shape.
    let d = temp_dir("pbrt-killeroo");
    write(
        &d,
        "geometry/blob.pbrt",
        "Shape \"loopsubdiv\" \"integer levels\" [ 2 ]\n  \"point3 P\" [ 10 0 0  -10 0 0  0 10 0  0 -10 0  0 0 10  0 0 -10 ]\n  \
         \"integer indices\" [ 0 2 4  2 1 4  1 3 4  3 0 4  2 0 5  1 2 5  3 1 5  0 3 5 ]\n",
    );
    let p = write(
        &d,
        "scene.pbrt",
        "LookAt 60 5 10  0 0 0  0 0 1\nRotate -5 0 0 1\nCamera \"perspective\" \"float fov\" [ 39 ]\n\
         Film \"rgb\" \"string filename\" [ \"k.exr\" ] \"integer yresolution\" [ 24 ] \"integer xresolution\" [ 24 ]\n\
         Sampler \"halton\" \"integer pixelsamples\" [ 4 ]\nWorldBegin\n\
         AttributeBegin\n Material \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n Translate 30 0 40\n \
         AreaLightSource \"diffuse\" \"rgb L\" [ 200 200 200 ]\n Shape \"sphere\" \"float radius\" [ 3 ]\nAttributeEnd\n\
         AttributeBegin\n Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.8 ]\n Translate 0 0 -10\n \
         Shape \"trianglemesh\" \"point2 uv\" [ 0 0 5 0 5 5 0 5 ] \"integer indices\" [ 0 1 2 2 3 0 ]\n  \
         \"point3 P\" [ -100 -100 0 100 -100 0 100 100 0 -100 100 0 ]\nAttributeEnd\n\
         AttributeBegin\n Material \"coateddiffuse\" \"float roughness\" [ 0.025 ] \"rgb reflectance\" [ 0.4 0.2 0.2 ]\n \
         Include \"geometry/blob.pbrt\"\nAttributeEnd\n",
    );
    let (scene, w) = load_scene_with_warnings(&p, &small(), false).unwrap();
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w[0].contains("filename") && w[1].contains("coateddiffuse is rendered as Plastic"), "{w:?}");
    let film = film_of(&scene);
    assert!(film.mean_xyz().iter().map(|p| p[1]).sum::<f64>() > 0.1);
    // The blob: 8 · 4² triangles, with normals, within the control octahedron.
    let (desc, _) = read_pbrt(&p, false).unwrap();
    match &desc.objects[2].shape {
        ShapeDesc::Triangles { positions, indices, normals, .. } => {
            assert_eq!(indices.len(), 128);
            assert!(normals.is_some());
            assert!(positions.iter().all(|v| v[0].abs() + v[1].abs() + v[2].abs() <= 10.0 + 1e-3));
        }
        s => panic!("{s:?}"),
    }
}

#[test]
fn one_sided_emitters_face_where_pbrt_says() {
    // pbrt-v4: a triangle's normal is (p0 − p2) × (p1 − p2) in world space, flipped by
    // ReverseOrientation and again by a transform that swaps handedness (so a mirror
    // keeps the object-space side). This quad's normal is −y by hand:
    // ((0.5, 0, 0) × (0.5, 0, 0.5)) = (0, −0.25, 0), towards the floor. The camera sees
    // the floor, not the light (21° above its view direction, outside the 15° half-angle).
    let d = temp_dir("pbrt-sides");
    let floor_light_with = |extra: &str, indices: &str, normals: &str| {
        let p = write(
            &d,
            "s.pbrt",
            &format!(
                "LookAt 0 0.8 4  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nWorldBegin\n\
                 Shape \"trianglemesh\" \"point3 P\" [ -2 0 -2  -2 0 2  2 0 2  2 0 -2 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n\
                 AttributeBegin\n {extra}\n AreaLightSource \"diffuse\" \"rgb L\" [ 4 4 4 ]\n\
                 Shape \"trianglemesh\" \"point3 P\" [ -0.25 1.5 -0.25  0.25 1.5 -0.25  0.25 1.5 0.25  -0.25 1.5 0.25 ]\n\
                 \"integer indices\" [ {indices} ] {normals}\nAttributeEnd\n"
            ),
        );
        let film = film_of(&load_scene(&p, &small()).unwrap());
        film.mean_xyz().iter().map(|p| p[1]).sum::<f64>()
    };
    let floor_light = |extra: &str| floor_light_with(extra, "0 1 2 0 2 3", "");
    assert!(floor_light("") > 0.1, "the light faces the floor");
    // Reversed it faces up: nothing is lit (up to rounding: 4e-14 was measured; the lit
    // floor sums to more than 0.1).
    let reversed = floor_light("ReverseOrientation");
    assert!(reversed < 1e-9, "reversed, it faces the ceiling: nothing is lit, found {reversed}");
    assert!(floor_light("Scale -1 1 1") > 0.1, "a mirror keeps the side");
    assert!(floor_light("Scale -1 1 1\n ReverseOrientation") < 1e-9);
    // With shading normals pbrt faces each triangle towards them (FaceForward), whatever
    // the winding: the reversed winding with normals pointing down still lights the floor.
    let down = "\"normal N\" [ 0 -1 0  0 -1 0  0 -1 0  0 -1 0 ]";
    assert!(floor_light_with("", "0 2 1 0 3 2", down) > 0.1);
    assert!(floor_light_with("", "0 1 2 0 2 3", &down.replace("-1", "1")) < 1e-9);
}

#[test]
fn convert_rewrites_texture_paths_and_reads_spectrum_files() {
    let d = temp_dir("pbrt-tex");
    let png = std::fs::read_dir(root().join("docs/images"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "png"))
        .expect("a PNG in docs/images");
    std::fs::create_dir_all(d.join("tex")).unwrap();
    std::fs::copy(&png, d.join("tex/t.png")).unwrap();
    write(&d, "spd/green.spd", "# a green reflectance\n400 0.1\n500 0.2\n550 0.7\n600 0.2 700 0.1\n");
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{HEAD}LightSource \"point\" \"point3 from\" [0 0 4] \"float power\" 400\n\
             Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"tex/t.png\" \"float uscale\" 2\n\
             AttributeBegin\n Material \"diffuse\" \"texture reflectance\" \"img\"\n\
             Shape \"trianglemesh\" \"point3 P\" [-2 -2 0  2 -2 0  2 2 0  -2 2 0] \"integer indices\" [0 1 2 0 2 3]\n\
              \"point2 uv\" [0 0 1 0 1 1 0 1]\nAttributeEnd\n\
             Material \"diffuse\" \"spectrum reflectance\" \"spd/green.spd\"\nShape \"sphere\" \"float radius\" 0.5\n"
        ),
    );
    let scene = load_scene(&p, &small()).unwrap();
    let names: Vec<String> =
        scene.inputs.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert!(names.contains(&"t.png".to_string()) && names.contains(&"green.spd".to_string()), "{names:?}");
    let ron = d.join("out/s.ron");
    std::fs::create_dir_all(d.join("out")).unwrap();
    let o = rust_v(&["convert", s(&p), "-o", s(&ron)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&ron).unwrap();
    assert!(text.contains("path: \"../tex/t.png\""), "{text}");
    assert!(text.contains("Table([(400.0, 0.1), (500.0, 0.2), (550.0, 0.7), (600.0, 0.2), (700.0, 0.1)])"), "{text}");
    assert_same_films(&film_of(&scene), &film_of(&load_scene(&ron, &small()).unwrap()));
}

#[test]
fn a_real_gzipped_ply_loads_through_plymesh_and_converts() {
    // The Stanford dragon at its coarsest resolution, when ../shared is present.
    let Some(ply) = crate::common::shared("meshes/dragon_vrip_res4.ply.gz") else {
        eprintln!("skipped: ../shared/meshes/dragon_vrip_res4.ply.gz is absent");
        return;
    };
    let d = temp_dir("pbrt-dragon");
    let p = write(
        &d,
        "dragon.pbrt",
        &format!(
            "LookAt 0 0.15 0.4  0 0.1 0  0 1 0\nCamera \"perspective\" \"float fov\" 35\nWorldBegin\n\
             LightSource \"distant\" \"point3 from\" [1 1 1] \"point3 to\" [0 0 0]\n\
             Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.05\n\
             AttributeBegin\n Rotate 30 0 1 0\n Shape \"plymesh\" \"string filename\" \"{}\"\nAttributeEnd\n",
            s(&ply)
        ),
    );
    let (scene, w) = load_scene_with_warnings(&p, &small(), true).unwrap();
    assert!(w.is_empty(), "{w:?}");
    let ron = d.join("dragon.ron");
    let o = rust_v(&["convert", s(&p), "-o", s(&ron), "--strict"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(d.join("dragon-mesh-0.ply").exists());
    let a = film_of(&scene);
    assert_same_films(&a, &film_of(&load_scene(&ron, &small()).unwrap()));
    assert!(a.mean_xyz().iter().map(|p| p[1]).sum::<f64>() > 0.01, "the dragon is seen and lit");
}

#[test]
fn expansion_is_bounded() {
    let d = temp_dir("pbrt-bounded");
    let tri = "\"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]";
    let p = write(&d, "sub.pbrt", &format!("{HEAD}Shape \"loopsubdiv\" \"integer levels\" 14 {tri}\n"));
    let e = load_scene(&p, &small()).err().map(|e| e.to_string()).expect("an error");
    assert!(e.contains("sub.pbrt:6:7:") && e.contains("268435456"), "{e}");
    // (Native instances count their group's triangles once; the limit on copied instances
    // and on instanced objects is not tested here: reaching either takes about 1 GB.)
}

#[test]
fn matrices_coordinate_systems_disks_and_spots_by_hand() {
    let d = temp_dir("pbrt-matrices");
    // `Transform` lists the matrix column by column (pbrt transposes what it reads): the
    // translation is in elements 13-15. `ConcatTransform` post-multiplies: a scale by 2
    // after the translation scales the sphere about its own centre.
    // `CoordSysTransform "camera"` puts a shape at the eye (pbrt's "camera" system is
    // world-from-camera), and `Translate 0 0 3` then moves it 3 along the view (+z in
    // pbrt's camera space).
    let p = write(
        &d,
        "s.pbrt",
        "LookAt 1 2 3  1 2 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
         AttributeBegin\n Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 ]\n \
         ConcatTransform [ 2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 1 ]\n Shape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n\
         AttributeBegin\n CoordSysTransform \"camera\"\n Translate 0 0 3\n Shape \"sphere\" \"float radius\" 0.25\nAttributeEnd\n\
         AttributeBegin\n Translate 0 1 0\n Rotate 90 1 0 0\n \
         Shape \"disk\" \"float radius\" 2 \"float height\" 0.5\nAttributeEnd\n\
         LightSource \"spot\" \"point3 from\" [0 4 0] \"point3 to\" [0 0 0] \"float coneangle\" 25 \"float conedeltaangle\" 10\n",
    );
    let (desc, w) = read_pbrt(&p, false).unwrap();
    assert!(w.is_empty(), "{w:?}");
    // In rust-v's world x is mirrored (see the_image_is_not_mirrored).
    match &desc.objects[0].shape {
        ShapeDesc::Sphere { center, radius } => assert_eq!((*center, *radius), ([-5.0, 6.0, 7.0], 1.0)),
        s => panic!("{s:?}"),
    }
    // The eye (1, 2, 3) looking down −z: 3 along the view is (1, 2, 0).
    match &desc.objects[1].shape {
        ShapeDesc::Sphere { center, radius } => {
            assert!((glam::Vec3::from(*center) - glam::Vec3::new(-1.0, 2.0, 0.0)).length() < 1e-5, "{center:?}");
            assert_eq!(*radius, 0.25);
        }
        s => panic!("{s:?}"),
    }
    // The disk: its plane z = 0.5 turned 90° about x (z → −y... by hand: R_x(90°) maps
    // (0, 0, 1) to (0, −1, 0)), then lifted by 1: centre (0, 0.5, 0), normal (0, −1, 0).
    match &desc.objects[2].shape {
        ShapeDesc::Disk { center, normal, radius } => {
            assert!((glam::Vec3::from(*center) - glam::Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6, "{center:?}");
            assert!((glam::Vec3::from(*normal) - glam::Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6, "{normal:?}");
            assert_eq!(*radius, 2.0);
        }
        s => panic!("{s:?}"),
    }
    match &desc.lights[0] {
        LightDesc::Spot { position, look_at, cone_deg, falloff_deg, .. } => {
            assert_eq!((*position, *look_at), ([0.0, 4.0, 0.0], [0.0, 0.0, 0.0]));
            assert_eq!((*cone_deg, *falloff_deg), (25.0, 10.0));
        }
        l => panic!("{l:?}"),
    }
}

#[test]
fn ply_files_are_read_once_each_in_order_of_first_use() {
    let d = temp_dir("pbrt-plys");
    let ply = |z: f32| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
             element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 {z}\n1 0 {z}\n0 1 {z}\n3 0 1 2\n"
        )
    };
    write(&d, "b.ply", &ply(1.0));
    write(&d, "a.ply", &ply(2.0));
    let shape = |f: &str| format!("Shape \"plymesh\" \"string filename\" \"{f}\"\n");
    let p =
        write(&d, "s.pbrt", &format!("{HEAD}{}Translate 0 0 1\n{}{}", shape("b.ply"), shape("a.ply"), shape("b.ply")));
    let scene = load_scene(&p, &small()).unwrap();
    let names: Vec<String> =
        scene.inputs.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["b.ply", "a.ply"]);
    let (desc, _) = read_pbrt(&p, false).unwrap();
    let z: Vec<f32> = desc
        .objects
        .iter()
        .map(|o| match &o.shape {
            ShapeDesc::Triangles { positions, .. } => positions[0][2],
            s => panic!("{s:?}"),
        })
        .collect();
    // Each in file order, with its own transform: b at z 1, a at 2 + 1, b at 1 + 1.
    assert_eq!(z, [1.0, 3.0, 2.0]);
}

#[test]
fn an_area_light_seen_directly_has_pbrts_luminance() {
    // pbrt-v4 divides an area light's scale by its spectrum's luminance ("equivalent to 1
    // nit"), except an RGB, which keeps its colour: a blackbody at scale 2 is seen with
    // luminance Y = 2 whatever its temperature, and "rgb L" [0.5 0.5 0.5] with Y = 0.5.
    let d = temp_dir("pbrt-nits");
    let seen = |l: &str| {
        let p = write(
            &d,
            "s.pbrt",
            &format!(
                "LookAt 0 0 0  0 0 -1  0 1 0\nCamera \"perspective\" \"float fov\" 30\nWorldBegin\n\
                 AreaLightSource \"diffuse\" {l}\n\
                 Shape \"trianglemesh\" \"point3 P\" [ -10 -10 -5  10 -10 -5  10 10 -5  -10 10 -5 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n"
            ),
        );
        let o = SettingsPatch { width: Some(8), height: Some(8), spp: Some(2), ..Default::default() };
        let film = film_of(&load_scene(&p, &o).unwrap());
        let xyz = film.mean_xyz();
        xyz.iter().map(|p| p[1]).sum::<f64>() / xyz.len() as f64
    };
    for (l, want) in [
        ("\"blackbody L\" 3000 \"float scale\" 2", 2.0),
        ("\"blackbody L\" 6500 \"float scale\" 2", 2.0),
        ("\"spectrum L\" [ 400 1 500 3 600 0.5 700 2 ]", 1.0),
        ("\"rgb L\" [ 0.5 0.5 0.5 ]", 0.5),
        ("\"rgb L\" [ 1 1 1 ] \"float power\" 100", 100.0 / (400.0 * std::f64::consts::PI)),
    ] {
        let y = seen(l);
        assert!((y - want).abs() < 2e-3 * want, "{l}: Y {y}, expected {want}");
    }
}

#[test]
fn killeroo_simple_from_pbrt_v4_scenes_loads_and_renders() {
    // scripts/fetch-pbrt-scenes.sh puts it in ../shared/pbrt-v4-scenes.
    let Some(p) = crate::common::shared("pbrt-v4-scenes/killeroos/killeroo-simple.pbrt") else {
        eprintln!("skipped: run scripts/fetch-pbrt-scenes.sh to fetch killeroo-simple.pbrt");
        return;
    };
    let (scene, w) = load_scene_with_warnings(&p, &small(), false).unwrap();
    // Expected: the film's file name (a note) and coateddiffuse rendered as Plastic.
    assert!(
        w.iter().all(|l| l.contains("Film \"filename\"") || l.contains("coateddiffuse is rendered as Plastic")),
        "{w:?}"
    );
    let film = film_of(&scene);
    assert!(film.mean_xyz().iter().map(|p| p[1]).sum::<f64>() > 0.01, "the scene is lit");
}

/// pbrt's `mix` imports as a `Mix` without a warning: its materials by name
/// (either may be a mix), its amount a float or a constant float texture, an
/// amount outside [0, 1] clamped (pbrt's choice, second where amount ≥ u for
/// u in [0, 1), makes 1.5 the second everywhere); `convert` writes the Mix,
/// and the RON renders bit for bit like the `.pbrt`. A mix of an unknown
/// material or of an interface is one error naming the line.
#[test]
fn mix_imports_as_a_mix_and_converts_bit_identically() {
    let d = temp_dir("pbrt-mix");
    let body = "LightSource \"point\" \"point3 from\" [0 2 4] \"float power\" 400\n\
        MakeNamedMaterial \"red\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.8 0.1 0.1]\n\
        MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.1\n\
        Texture \"amt\" \"float\" \"constant\" \"float value\" 0.3\n\
        MakeNamedMaterial \"worn\" \"string type\" \"mix\" \"string materials\" [\"red\" \"gold\"] \"texture amount\" \"amt\"\n\
        MakeNamedMaterial \"over\" \"string type\" \"mix\" \"string materials\" [\"worn\" \"red\"] \"float amount\" 1.5\n\
        AttributeBegin\n NamedMaterial \"worn\"\n Translate -0.6 0 0\n Shape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n\
        AttributeBegin\n NamedMaterial \"over\"\n Translate 0.6 0 0\n Shape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n";
    let p = write(&d, "mix.pbrt", &format!("{HEAD}{body}"));
    let (desc, warnings) = read_pbrt(&p, true).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let mix = |name: &str| match desc.materials.0.iter().find(|(n, _)| n == name).map(|(_, m)| m) {
        Some(MaterialDesc::Mix { materials, amount }) => (materials.clone(), amount.clone()),
        other => panic!("{name}: {other:?}"),
    };
    use rust_v::scene::desc::ScalarDesc;
    assert_eq!(mix("worn"), (("red".to_string(), "gold".to_string()), ScalarDesc::Value(0.3)));
    assert_eq!(mix("over"), (("worn".to_string(), "red".to_string()), ScalarDesc::Value(1.0)));
    let ron = d.join("mix.ron");
    let o = rust_v(&["convert", s(&p), "-o", s(&ron), "--strict"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&ron).unwrap();
    assert!(text.contains("Mix(") && text.contains("materials: (\"red\", \"gold\")"), "{text}");
    let a = film_of(&load_scene(&p, &small()).unwrap());
    assert_same_films(&a, &film_of(&load_scene(&ron, &small()).unwrap()));
    assert!(a.mean_xyz().iter().map(|p| p[1]).sum::<f64>() > 0.1, "something is lit");
    for (line, what) in [
        (
            "MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"red\" \"nope\"]\n",
            "unknown material \"nope\"",
        ),
        (
            "MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"red\" \"interface\"]\n",
            "is an interface",
        ),
        ("MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"red\"]\n", "two material names"),
    ] {
        let setup = "MakeNamedMaterial \"red\" \"string type\" \"diffuse\"\nMakeNamedMaterial \"interface\" \"string type\" \"interface\"\n";
        let p = write(&d, "bad.pbrt", &format!("{HEAD}{setup}{line}"));
        let e = one_error(&rust_v(&["render", s(&p), "-o", s(&d.join("bad.png"))]));
        assert!(e.contains("bad.pbrt:8:") && e.contains(what), "{e}");
    }
}
