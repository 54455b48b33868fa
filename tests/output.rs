//! Image output: `--color-space` for EXR, checked against the sRGB render of the same scene.

use std::path::Path;

use rust_v::color::{ColorSpace, LINEAR_SRGB_TO_XYZ};
use rust_v::io::image::{Pixels, read_image};

use crate::common::{root, rust_v, temp_dir};

/// Renders the canonical Cornell box at 8x8, 2 spp, into `out` with the given extra flags.
fn render(out: &Path, extra: &[&str]) -> std::process::Output {
    let scene = root().join("scenes/cornell-lambert.ron");
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "2",
        "--quiet",
    ];
    args.extend_from_slice(extra);
    rust_v(&args)
}

/// The three float channels and the chromaticities attribute of an EXR, read with the exr crate.
fn read_exr(path: &Path) -> (Vec<String>, Vec<[f32; 3]>, [f32; 8]) {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).expect("EXR reads");
    let layer = &image.layer_data[0];
    let names: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
    let n = layer.size.area();
    let mut px = vec![[0.0f32; 3]; n];
    // Channels are stored sorted by name: B, G, R or X, Y, Z.
    let order: [usize; 3] = if names[0] == "B" { [2, 1, 0] } else { [0, 1, 2] };
    for (k, c) in layer.channel_data.list.iter().enumerate() {
        for (i, v) in c.sample_data.values_as_f32().enumerate() {
            px[i][order[k]] = v;
        }
    }
    let ch = image.attributes.chromaticities.expect("a chromaticities attribute");
    let xy = [ch.red.0, ch.red.1, ch.green.0, ch.green.1, ch.blue.0, ch.blue.1, ch.white.0, ch.white.1];
    (names, px, xy)
}

/// Each space's EXR holds the sRGB render's pixels converted by the space's matrix (through
/// XYZ), to f32 rounding; XYZ files have channels X, Y, Z and the OpenEXR XYZ chromaticities.
/// The sampler is deterministic, so the renders see identical samples.
#[test]
fn color_spaces_convert_the_same_render() {
    let dir = temp_dir("color-space");
    let srgb_path = dir.join("srgb.exr");
    assert!(render(&srgb_path, &[]).status.success());
    let Ok((_, _, Pixels::Linear(srgb))) = read_image(&srgb_path) else { panic!("linear EXR") };
    for space in [ColorSpace::Rec2020, ColorSpace::AcesCg, ColorSpace::Xyz] {
        let path = dir.join(format!("{}.exr", space.name()));
        let o = render(&path, &["--color-space", space.name()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let (names, px, xy) = read_exr(&path);
        let want_names = if space == ColorSpace::Xyz { ["X", "Y", "Z"] } else { ["B", "G", "R"] };
        assert_eq!(names, want_names);
        let c = space.chromaticities();
        for (k, v) in xy.iter().enumerate() {
            assert!((v - c[k / 2][k % 2] as f32).abs() < 1e-6, "{space:?} chromaticity {k}");
        }
        for (p, s) in px.iter().zip(&srgb) {
            let m = LINEAR_SRGB_TO_XYZ;
            let xyz: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| m[i][j] as f64 * s[j]).sum());
            let want = space.from_xyz(xyz);
            for k in 0..3 {
                // f32 storage of both files plus the 6-decimal sRGB matrices (inverse to 1e-5).
                assert!((p[k] as f64 - want[k]).abs() < 1e-4 * (1.0 + want[k].abs()), "{space:?}: {p:?} vs {want:?}");
            }
        }
    }
}

/// PNG output is always sRGB: asking for another space is an error naming the file.
#[test]
fn color_space_needs_an_exr() {
    let dir = temp_dir("color-space-png");
    let o = render(&dir.join("x.png"), &["--color-space", "acescg"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--color-space acescg") && err.contains("x.png"), "{err}");
    let o = render(&dir.join("x.exr"), &["--color-space", "p3"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("rec2020"));
}
