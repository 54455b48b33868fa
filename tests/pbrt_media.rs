//! pbrt-v4 participating media (`MakeNamedMedium`, `MediumInterface`, `Material
//! "interface"`): what they map to, checked against pbrt's definitions by hand
//! (Beer-Lambert through an imported medium, a grid's voxels reordered by the
//! handedness mirror, pbrt's own trilinear lookup where a grid is resampled), the
//! converted RON rendering bit for bit like the `.pbrt`, and hostile files.

use std::path::Path;

use glam::Vec3;
use rust_v::scene::desc::{MediumDesc, PhaseDesc, SpectrumDesc};
use rust_v::scene::pbrt::read_pbrt;
use rust_v::scene::{load_scene, load_scene_with_warnings};

use crate::common::{rust_v, temp_dir};
use crate::pbrt::{HEAD, assert_same_films, film_of, one_error, s, small, write};

/// A cube `[-1, 1]³` as a pbrt `trianglemesh`, outward-facing.
const CUBE: &str = "Shape \"trianglemesh\" \"point3 P\" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1]\n\
 \"integer indices\" [0 2 1  0 3 2  4 5 6  4 6 7  0 1 5  0 5 4  3 7 6  3 6 2  0 4 7  0 7 3  1 2 6  1 6 5]\n";

/// Converts `p` into `dir/out.ron`, returning the RON text.
fn convert(p: &Path, dir: &Path) -> String {
    let ron = dir.join("out.ron");
    let o = rust_v(&["convert", s(p), "-o", s(&ron)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_to_string(&ron).unwrap()
}

/// The sizes and densities of a `.vol` file.
fn read_vol(path: &Path) -> ([usize; 3], Vec<f32>) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[0..4], b"VOL\x03");
    let int = |at: usize| i32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize;
    let data = b[48..].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
    ([int(8), int(12), int(16)], data)
}

#[test]
fn homogeneous_media_in_interface_and_glass_spheres_map_convert_and_render_bit_identically() {
    let d = temp_dir("pbrt-media-homogeneous");
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{HEAD}LightSource \"infinite\" \"rgb L\" [1 1 1]\n\
             MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.05 0.05 0.05]\n \
               \"rgb sigma_s\" [0.4 0.4 0.4] \"float scale\" 2 \"float g\" 0.3\n\
             MakeNamedMedium \"tint\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 0.2 0.4]\n \
               \"spectrum sigma_s\" [400 0.5 700 0.25]\n\
             AttributeBegin\n MediumInterface \"fog\" \"\"\n Material \"interface\"\n Shape \"sphere\" \"float radius\" 1\nAttributeEnd\n\
             AttributeBegin\n Translate 1.6 0 0\n MediumInterface \"tint\" \"\"\n Material \"dielectric\" \"float eta\" 1.33\n\
             Shape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n"
        ),
    );
    let (desc, warnings) = read_pbrt(&p, true).expect("no warnings, even with strict");
    assert!(warnings.is_empty(), "{warnings:?}");
    let media: Vec<&str> = desc.media.0.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(media, ["fog", "tint"]);
    // pbrt: σ = scale · sigma; a grey RGB is that constant; g is Henyey-Greenstein's.
    match &desc.media.0[0].1 {
        MediumDesc::Homogeneous {
            sigma_a: SpectrumDesc::Constant(a),
            sigma_s: SpectrumDesc::Constant(s),
            phase: PhaseDesc::HenyeyGreenstein { g },
        } => assert_eq!((*a, *s, *g), (0.1, 0.8, 0.3)),
        other => panic!("{other:?}"),
    }
    // A coloured σa: pbrt's RGBUnboundedSpectrum, larger in the blue than in the red.
    match &desc.media.0[1].1 {
        MediumDesc::Homogeneous { sigma_a: SpectrumDesc::Samples(v), sigma_s: SpectrumDesc::Table(t), .. } => {
            assert_eq!(v.len(), 36);
            assert!(v.iter().all(|x| *x >= 0.0 && *x <= 0.8), "{v:?}");
            assert!(v[7] > 0.3 && v[27] < 0.15, "450 nm {} and 650 nm {}", v[7], v[27]);
            assert_eq!(t, &[(400.0, 0.5), (700.0, 0.25)]);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(desc.objects[0].material.as_deref(), Some("pbrt-interface"));
    assert_eq!(desc.objects[0].interior.as_deref(), Some("fog"));
    assert_eq!(desc.objects[1].interior.as_deref(), Some("tint"));

    // Beer-Lambert through the fog sphere's diameter: exp(−(0.1 + 0.8) · 2) in every bin.
    let scene = load_scene(&p, &small()).unwrap();
    let from = Vec3::new(0.0, 0.0, 2.0);
    let stack = scene.volumes_at(from);
    let t = scene
        .transmittance(from, Vec3::ZERO, Some(&stack), Vec3::new(0.0, 0.0, -2.0), Vec3::ZERO)
        .expect("an index-matched boundary does not block")
        .spectrum()
        .expect("a medium on the way");
    let want = (-0.9f32 * 2.0).exp();
    for b in 0..rust_v::color::N_BINS {
        assert!((t[b] - want).abs() <= 2e-5 * want, "bin {b}: {} vs {want}", t[b]);
    }

    let text = convert(&p, &d);
    assert!(text.contains("interior: \"fog\"") && text.contains("Interface"), "{text}");
    let a = film_of(&scene);
    let b = film_of(&load_scene(&d.join("out.ron"), &small()).unwrap());
    assert_same_films(&a, &b);
    // The fog dims the sky behind it: the centre pixel is darker than a corner.
    let y = a.mean_xyz();
    let (centre, corner) = (y[12 * 24 + 12][1], y[0][1]);
    assert!(centre < 0.8 * corner, "centre {centre}, corner {corner}");
}

#[test]
fn a_uniformgrid_is_carried_over_voxel_for_voxel_or_resampled_and_never_written_beside_the_scene() {
    let d = temp_dir("pbrt-media-grid");
    let grid = "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"integer nx\" 3 \"integer ny\" 2 \"integer nz\" 1\n \
                \"float density\" [0 1 2 3 4 5] \"point3 p0\" [-1 -1 -1] \"point3 p1\" [1 1 1]\n \
                \"rgb sigma_a\" [0.5 0.5 0.5] \"rgb sigma_s\" [2 2 2]\n";
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{HEAD}LightSource \"infinite\" \"rgb L\" [1 1 1]\n{grid}\
             AttributeBegin\n MediumInterface \"smoke\" \"\"\n Material \"interface\"\n {CUBE}AttributeEnd\n"
        ),
    );
    let before: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
    let (scene, w) = load_scene_with_warnings(&p, &small(), false).unwrap();
    assert!(w.len() == 1 && w[0].contains("half a voxel"), "{w:?}");
    let a = film_of(&scene);
    let after: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(before, after, "rendering a .pbrt writes no file beside it");

    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let text = convert(&p, &out);
    assert!(text.contains("Grid(") && text.contains("\"out-medium-0.vol\""), "{text}");
    // This camera needs the mirror x → −x (docs/pbrt.md, Handedness): world x runs
    // against the medium's, so each row of 3 voxels is reversed; y and z stay.
    let (n, data) = read_vol(&out.join("out-medium-0.vol"));
    assert_eq!(n, [3, 2, 1]);
    assert_eq!(data, [2.0, 1.0, 0.0, 5.0, 4.0, 3.0]);
    let b = film_of(&load_scene(&out.join("out.ron"), &small()).unwrap());
    assert_same_films(&a, &b);

    // A sphere of radius 2 around the box: pbrt's density (1 inside p0..p1, 0 outside)
    // resampled over the sphere's bounds [-2, 2]³ at pbrt's voxel size 0.5: 8³ voxels,
    // 1 where the voxel centre lies inside [-1, 1]³ (pbrt's lookup there is exactly 1).
    let ones = "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"integer nx\" 4 \"integer ny\" 4 \"integer nz\" 4\n \
                \"float density\" [1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 \
                1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1] \"point3 p0\" [-1 -1 -1] \"point3 p1\" [1 1 1]\n";
    let p = write(
        &d,
        "r.pbrt",
        &format!(
            "{HEAD}LightSource \"infinite\" \"rgb L\" [1 1 1]\n{ones}\
             AttributeBegin\n MediumInterface \"smoke\" \"\"\n Material \"interface\"\n Shape \"sphere\" \"float radius\" 2\nAttributeEnd\n"
        ),
    );
    let (_, w) = load_scene_with_warnings(&p, &small(), false).unwrap();
    assert!(w.len() == 1 && w[0].contains("resampled onto 8x8x8"), "{w:?}");
    let r = d.join("r");
    std::fs::create_dir_all(&r).unwrap();
    convert(&p, &r);
    let (n, data) = read_vol(&r.join("out-medium-0.vol"));
    assert_eq!(n, [8, 8, 8]);
    for (k, v) in data.iter().enumerate() {
        let c = [k % 8, (k / 8) % 8, k / 64].map(|i| -2.0 + 0.5 * (i as f32 + 0.5));
        let inside = c.iter().all(|x| x.abs() < 1.0);
        assert_eq!(*v, if inside { 1.0 } else { 0.0 }, "voxel {k} at {c:?}");
    }
}

#[test]
fn hostile_media_give_one_error_line_at_the_place() {
    let d = temp_dir("pbrt-media-hostile");
    let sphere = "MediumInterface \"fog\" \"\"\nMaterial \"interface\"\nShape \"sphere\"\n";
    let cases = [
        (
            "unknown.pbrt",
            format!("{HEAD}MakeNamedMedium \"haze\" \"string type\" \"homogeneous\"\n{sphere}"),
            ":9:7:",
            "unknown medium \"fog\"",
        ),
        (
            "length.pbrt",
            format!(
                "{HEAD}MakeNamedMedium \"fog\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [1 2 3]\n{sphere}"
            ),
            ":6:66:",
            "expected nx·ny·nz = 2x1x1 = 2 values, found 3",
        ),
        (
            "negative.pbrt",
            format!(
                "{HEAD}MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 -1 0.1]\n{sphere}"
            ),
            ":6:51:",
            "expected non-negative coefficients",
        ),
        (
            "negative-spectrum.pbrt",
            format!(
                "{HEAD}MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"spectrum sigma_s\" [400 1 700 -1]\n{sphere}"
            ),
            ":6:51:",
            "expected non-negative coefficients",
        ),
        (
            // pbrt trusts the declared outside; rust-v checks it (the camera is in vacuum here).
            "exterior.pbrt",
            format!(
                "{HEAD}MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nMediumInterface \"\" \"fog\"\nShape \"sphere\"\n"
            ),
            ":8:7:",
            "objects[0].exterior (from here): \"fog\", but just outside its surface is vacuum",
        ),
        (
            "type.pbrt",
            format!("{HEAD}MakeNamedMedium \"fog\" \"string type\" \"vapour\"\n{sphere}"),
            ":6:23:",
            "unknown medium type \"vapour\"",
        ),
    ];
    for (name, text, place, what) in cases {
        let p = write(&d, name, &text);
        let e = one_error(&rust_v(&["render", s(&p), "-o", s(&d.join("x.png"))]));
        assert!(e.contains(&format!("{name}{place}")) && e.contains(what), "{name}: expected {place} {what:?}: {e}");
    }
}

#[test]
fn the_camera_sits_in_the_outside_medium_at_camera_and_outside_media_become_exteriors() {
    let d = temp_dir("pbrt-media-camera");
    // pbrt-v4's scene.cpp: `CameraSceneEntity(..., graphicsState.currentOutsideMedium)`.
    let p = write(
        &d,
        "s.pbrt",
        "MediumInterface \"\" \"fog\"\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 60\n\
         Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 24\nSampler \"zsobol\" \"integer pixelsamples\" 4\n\
         WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n\
         MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.01 0.01 0.01] \"rgb sigma_s\" [0.05 0.05 0.05]\n\
         MakeNamedMedium \"smoke\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.5 0.5 0.5] \"rgb sigma_s\" [2 2 2]\n\
         AttributeBegin\n MediumInterface \"smoke\" \"fog\"\n Material \"interface\"\n Shape \"sphere\" \"float radius\" 0.8\nAttributeEnd\n\
         AttributeBegin\n Translate 0 -1 0\n Rotate -90 1 0 0\n Material \"diffuse\"\n Shape \"disk\" \"float radius\" 3\nAttributeEnd\n\
         AttributeBegin\n MediumInterface \"fog\" \"fog\"\n Translate 1.5 0 0\n Material \"dielectric\"\n Shape \"sphere\" \"float radius\" 0.3\nAttributeEnd\n\
         AttributeBegin\n Translate -1.5 0 0\n Material \"interface\"\n Shape \"sphere\" \"float radius\" 0.3\nAttributeEnd\n\
         AttributeBegin\n Translate 0 1.5 0\n ReverseOrientation\n MediumInterface \"fog\" \"smoke\"\n Material \"interface\"\n\
         Shape \"sphere\" \"float radius\" 0.3\nAttributeEnd\n",
    );
    let (desc, w) = read_pbrt(&p, true).expect("no warnings with strict");
    assert!(w.len() == 1 && w[0].contains("inside out"), "one note: {w:?}");
    assert_eq!(desc.camera.medium.as_deref(), Some("fog"));
    let media = |i: usize| (desc.objects[i].interior.as_deref(), desc.objects[i].exterior.as_deref());
    // A boundary between smoke and fog; the disk (MediumInterface "" "fog" still
    // current from before WorldBegin) has fog outside; the glass with fog on both
    // sides is no transition in pbrt-v4 (the ray keeps its medium): fog inside, no check.
    // (The last sphere: `MediumInterface "" "fog"` is still current.)
    assert_eq!(media(0), (Some("smoke"), Some("fog")));
    assert_eq!(media(1), (None, Some("fog")));
    assert_eq!(media(2), (Some("fog"), None));
    // An interface with vacuum inside and fog outside: a clear bubble in the fog.
    assert_eq!(media(3), (None, Some("fog")));
    assert_eq!(desc.objects[3].material.as_deref(), Some("pbrt-interface"));
    // ReverseOrientation turns pbrt's sphere inside out: its "inside" (fog) is around
    // it, its "outside" (smoke) within.
    assert_eq!(media(4), (Some("smoke"), Some("fog")));
    let scene = load_scene(&p, &small()).expect("the exteriors agree with the nesting");
    let text = convert(&p, &d);
    assert!(text.contains("medium: \"fog\"") && text.contains("exterior: \"fog\""), "{text}");
    assert_same_films(&film_of(&scene), &film_of(&load_scene(&d.join("out.ron"), &small()).unwrap()));
}

/// pbrt-v4's named media: `"preset" "Ketchup"` is Jensen et al.'s σa = (0.061, 0.97,
/// 1.45) and σs′ = (0.18, 0.07, 0.03) per mm, as RGB coefficients, still times
/// `scale` (the same description as writing them out); parameters beside a preset
/// and an unknown preset warn.
#[test]
fn medium_presets_are_pbrts_table() {
    let d = temp_dir("pbrt-media-preset");
    let p = write(
        &d,
        "s.pbrt",
        &format!(
            "{HEAD}MakeNamedMedium \"k\" \"string type\" \"homogeneous\" \"string preset\" \"Ketchup\" \"float scale\" 0.5\n\
             MakeNamedMedium \"e\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.061 0.97 1.45] \"rgb sigma_s\" [0.18 0.07 0.03] \"float scale\" 0.5\n\
             MakeNamedMedium \"w\" \"string type\" \"homogeneous\" \"string preset\" \"Wholemilk\" \"rgb sigma_a\" [1 1 1]\n\
             MakeNamedMedium \"u\" \"string type\" \"homogeneous\" \"string preset\" \"Custard\"\n\
             Shape \"sphere\"\n"
        ),
    );
    let (desc, w) = read_pbrt(&p, false).unwrap();
    let show = |i: usize| format!("{:?}", desc.media.0[i].1);
    assert_eq!(show(0), show(1));
    assert!(show(0).contains("Samples"), "{}", show(0));
    assert!(w.len() == 2 && w[0].contains("ignored with a preset") && w[1].contains("\"Custard\""), "{w:?}");
    match &desc.media.0[3].1 {
        MediumDesc::Homogeneous { sigma_a: SpectrumDesc::Constant(a), sigma_s: SpectrumDesc::Constant(s), .. } => {
            assert_eq!((*a, *s), (1.0, 1.0), "pbrt's defaults")
        }
        other => panic!("{other:?}"),
    }
}
