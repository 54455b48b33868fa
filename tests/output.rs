//! Image output: `--color-space` and `--spectral` for EXR, checked against the sRGB render of the
//! same scene and against the colour weights.

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

/// `--spectral`: the EXR holds the 36 bins as channels `S0.380,000000nm` ... `S0.730,000000nm`
/// (Fichet et al. 2021) with the layout's attributes, and on every pixel the bins weighted by
/// the colour weights W_b give the XYZ channels of the same file to f32 rounding (the film sums
/// both exactly; XYZ is the colour integral of each sample's bins). On the N-SF11 glass spheres
/// (`auto` splits into single wavelengths in them), and with `spectral` hero packets.
#[test]
fn spectral_exr_bins_reproduce_the_xyz() {
    use exr::prelude::*;
    let dir = temp_dir("spectral-exr");
    let w = rust_v::color::color_weights();
    for extra in [&["--integrator", "auto"][..], &["--integrator", "spectral", "--wavelengths", "hero"][..]] {
        let path = dir.join("s.exr");
        let scene = root().join("scenes/spheres.ron");
        let mut args = vec!["render", scene.to_str().unwrap(), "-o", path.to_str().unwrap(), "--quiet"];
        args.extend_from_slice(&[
            "--width",
            "16",
            "--height",
            "12",
            "--spp",
            "4",
            "--spectral",
            "--color-space",
            "xyz",
        ]);
        args.extend_from_slice(extra);
        let o = rust_v(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let image = read_all_flat_layers_from_file(&path).expect("EXR reads");
        let layer = &image.layer_data[0];
        let attr = |k: &str| layer.attributes.other.get(&Text::from(k)).cloned();
        assert_eq!(attr("spectralLayoutVersion"), Some(AttributeValue::Text(Text::from("1.0"))));
        let channel = |name: &str| -> Vec<f32> {
            let c = layer.channel_data.list.iter().find(|c| c.name == *name);
            c.unwrap_or_else(|| panic!("no channel {name}")).sample_data.values_as_f32().collect()
        };
        let xyz = [channel("X"), channel("Y"), channel("Z")];
        let bins: Vec<Vec<f32>> = (0..36).map(|b| channel(&format!("S0.{},000000nm", 380 + 10 * b))).collect();
        assert_eq!(layer.channel_data.list.len(), 39);
        let mut lit = 0;
        for p in 0..xyz[0].len() {
            let scale: f64 = (0..36).map(|b| bins[b][p].abs() as f64).sum::<f64>().max(1e-3);
            for c in 0..3 {
                let want: f64 = (0..36).map(|b| w[b][c] as f64 * bins[b][p] as f64).sum();
                assert!(
                    (xyz[c][p] as f64 - want).abs() < 1e-5 * scale,
                    "{extra:?} pixel {p} channel {c}: {} vs {want}",
                    xyz[c][p]
                );
            }
            lit += (xyz[1][p] > 0.0) as usize;
        }
        assert!(lit > 10, "{extra:?}: the box is lit ({lit} lit pixels)");
    }
    // --spectral needs an EXR.
    let o = rust_v(&["render", "scenes/prism.ron", "-o", dir.join("x.png").to_str().unwrap(), "--spectral", "--quiet"]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--spectral needs an .exr"));
    // --spectral keeps the bin centres, so it refuses continuous packets (as it refuses rgb).
    let out = dir.join("x.exr");
    let args = ["render", "scenes/prism.ron", "-o", out.to_str().unwrap(), "--spectral", "--quiet"];
    for w in ["continuous", "rgb"] {
        let o = rust_v(&[&args[..], &["--integrator", "spectral", "--wavelengths", w]].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains("--spectral") && err.contains(w), "{w}: {err}");
    }
}

/// Through the binary: two halves rendered with `--passes` and `--spectral`, merged, give the
/// same EXR bytes (colour and 36 bins) as one render of all passes.
#[test]
fn spectral_halves_merge_to_the_whole_render() {
    let dir = temp_dir("spectral-merge");
    let scene = root().join("scenes/spheres.ron");
    let part = |name: &str, passes: Option<&str>| {
        let out = dir.join(format!("{name}.exr"));
        let ckpt = dir.join(format!("{name}.ckpt"));
        let mut args = vec!["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--quiet", "--spectral"];
        args.extend_from_slice(&[
            "--width",
            "12",
            "--height",
            "8",
            "--spp",
            "6",
            "--checkpoint",
            ckpt.to_str().unwrap(),
        ]);
        if let Some(p) = passes {
            args.extend_from_slice(&["--passes", p]);
        }
        let o = rust_v(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (out, ckpt)
    };
    let (whole, _) = part("whole", None);
    let (_, a) = part("a", Some("0..3"));
    let (_, b) = part("b", Some("3..6"));
    let merged = dir.join("merged.exr");
    let o = rust_v(&["merge", b.to_str().unwrap(), a.to_str().unwrap(), "-o", merged.to_str().unwrap(), "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(&merged).unwrap(), std::fs::read(&whole).unwrap());
}

/// `--exposure 1` doubles every linear value exactly (a power of two), in EXR
/// output and in spectral channels' colour alike; `--exposure 0` is the image
/// without the flag, bit for bit; `--tonemap filmic` changes a PNG (the
/// Cornell box's light is brighter than 1, so clipping and the filmic curve
/// differ there) and keeps it the same size; `--tonemap` with an EXR output is
/// an error (EXR stays linear).
#[test]
fn exposure_doubles_exactly_and_tone_mapping_is_for_png() {
    let d = temp_dir("picture");
    let (plain, plus, zero) = (d.join("a.exr"), d.join("b.exr"), d.join("c.exr"));
    for (out, extra) in [(&plain, &[][..]), (&plus, &["--exposure", "1"][..]), (&zero, &["--exposure", "0"][..])] {
        let o = render(out, extra);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let linear = |p: &Path| match read_image(p).unwrap().2 {
        Pixels::Linear(v) => v,
        Pixels::Code16(_) => panic!("an EXR reads as floats"),
    };
    let (a, b) = (linear(&plain), linear(&plus));
    assert!(a.iter().any(|p| p.iter().any(|&v| v > 0.0)));
    for (p, q) in a.iter().zip(&b) {
        assert_eq!(p.map(|v| v * 2.0), *q);
    }
    assert_eq!(std::fs::read(&plain).unwrap(), std::fs::read(&zero).unwrap());
    let (clip, filmic) = (d.join("clip.png"), d.join("filmic.png"));
    assert!(render(&clip, &[]).status.success());
    assert!(render(&filmic, &["--tonemap", "filmic"]).status.success());
    let (Pixels::Code16(c), Pixels::Code16(f)) = (read_image(&clip).unwrap().2, read_image(&filmic).unwrap().2) else {
        panic!("PNGs read as codes")
    };
    assert_eq!(c.len(), f.len());
    assert_ne!(c, f);
    let o = render(&d.join("x.exr"), &["--tonemap", "filmic"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("--tonemap filmic is for PNG output"), "{err}");
    let o = render(&d.join("y.png"), &["--exposure", "nan"]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
}
