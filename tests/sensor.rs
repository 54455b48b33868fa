//! Camera sensors (`--sensor`): the CMFs given as a file reproduce the default; the fitted
//! colour-correction matrix reproduces the ColorChecker within its stated residual (recomputed
//! here by an independent 1 nm integral); renders with a sensor are deterministic and resume and
//! merge bit for bit; bad sensor files and flags are clear one-line errors.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use rust_v::checkpoint::Checkpoint;
use rust_v::color::{COLOR_CHECKER_NAMES, Sensor, Spectrum, color_checker, d65};
use rust_v::film::Film;
use rust_v::io::image::{Pixels, read_image};
use rust_v::render::{Limits, render};
use rust_v::scene::{Scene, load_scene};
use rust_v::settings::SettingsPatch;

use crate::common::{root, rust_v, temp_dir};

fn sensor_file(name: &str) -> PathBuf {
    root().join("scenes/sensors").join(name)
}

fn scene(file: &str, size: u32, spp: u32, extra: SettingsPatch) -> Scene {
    let o = SettingsPatch { width: Some(size), height: Some(size), spp: Some(spp), ..extra };
    load_scene(&root().join("scenes").join(file), &o).expect("scene loads")
}

/// Renders `scene` (its sensor replaced by `sensor`) on `threads` threads.
fn render_with(scene: &mut Scene, sensor: &Arc<Sensor>, passes: std::ops::Range<u32>, threads: usize) -> Film {
    scene.sensor = sensor.clone();
    let s = &scene.settings;
    let mut film = Film::starting_at(s.width, s.height, passes.start);
    film.set_sensor(sensor.clone()).unwrap();
    let stop = AtomicBool::new(false);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let stats =
        pool.install(|| render(scene, &mut film, passes, Limits { stop: &stop, time_budget: None }, &mut |_, _| {}));
    assert_eq!(stats.invalid_samples, 0);
    film
}

/// The CIE 1931 CMFs given as a file (`scenes/sensors/cie1931.csv`, the 5 nm table) render what
/// the default renders, through the full spectrum (`path`), hero packets and continuous
/// wavelengths in a dispersive scene. Not bit-identical: the file's 5 nm rows are interpolated
/// linearly to 1 nm, which is not the 1 nm CIE table (up to 0.016 off, z̄ near its peak of 1.78:
/// 0.9% of the peak), so the per-bin weights differ from the CIE ones by up to 0.4% of a
/// channel's largest weight (0.18% in x̄, 0.13% in ȳ); the film's camera RGB then goes through
/// the fitted matrix (residual 8e-5 on the ColorChecker) instead of the exact XYZ -> sRGB. So:
/// - with bins (full spectrum, hero packets), every channel of every pixel within 5e-3 of the
///   pixel's largest channel, plus 1e-4 for near-black pixels (measured: up to 3.9e-3, a hero
///   pixel whose few bins sit where the weights differ most);
/// - with continuous wavelengths, each sample sees the curves at a single λ, up to 0.9% of the
///   peak apart: within 1.5e-2 of the pixel's largest channel (measured 8e-3), and the image's
///   mean per channel within 2e-3 relative (the differences average out over λ);
/// - a wrong projection or a missing matrix is off by far more (the raw camera RGB of the
///   Gaussian sensor differs from sRGB by tens of per cent).
///
/// The worst differences are printed.
#[test]
fn the_cmfs_as_a_file_equal_the_default() {
    let cie = Sensor::from_arg(&sensor_file("cie1931.csv")).unwrap();
    assert!(!cie.is_cie1931());
    assert!(cie.residual().unwrap() < 2e-4, "{}", cie.residual().unwrap());
    let default = Sensor::cie1931().clone();
    let cases = [
        ("cornell.ron", SettingsPatch::default()),
        (
            "cornell.ron",
            SettingsPatch { integrator: Some(rust_v::settings::IntegratorKind::Spectral), ..SettingsPatch::default() },
        ),
        (
            "prism-rainbow.ron",
            SettingsPatch {
                integrator: Some(rust_v::settings::IntegratorKind::Spectral),
                wavelengths: Some(rust_v::settings::WavelengthsKind::Continuous),
                ..SettingsPatch::default()
            },
        ),
    ];
    for (k, (file, patch)) in cases.into_iter().enumerate() {
        let continuous = k == 2;
        let mut sc = scene(file, 16, 4, patch);
        let a = render_with(&mut sc, &default, 0..4, 2).linear_srgb();
        let b = render_with(&mut sc, &cie, 0..4, 2).linear_srgb();
        let tol = if continuous { 1.5e-2 } else { 5e-3 };
        let mut worst = 0.0f64;
        for (p, q) in a.iter().zip(&b) {
            let largest = p.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for c in 0..3 {
                let d = (p[c] - q[c]).abs();
                worst = worst.max(d / largest.max(0.02));
                assert!(d <= tol * largest + 1e-4, "{file}: {p:?} vs {q:?}");
            }
        }
        let bright = a.iter().filter(|p| p.iter().any(|&v| v > 0.02)).count();
        assert!(bright > 10, "{file}: {bright} pixels above 0.02: a black image tests nothing");
        let mean = |img: &[[f64; 3]], c: usize| img.iter().map(|p| p[c]).sum::<f64>() / img.len() as f64;
        let mut worst_mean = 0.0f64;
        for c in 0..3 {
            let (ma, mb) = (mean(&a, c), mean(&b, c));
            worst_mean = worst_mean.max((ma - mb).abs() / ma);
            assert!((ma - mb).abs() <= 2e-3 * ma, "{file}: channel {c} mean {ma} vs {mb}");
        }
        eprintln!(
            "{file}: worst difference {worst:e} of the pixel's largest channel (floor 0.02), image means {worst_mean:e}"
        );
    }
}

/// Rows `(nm, [r, g, b])` of a sensor CSV, read here without the crate's parser (the shipped
/// files: comments, a header, comma-separated numbers).
fn read_curves(path: &Path) -> Vec<(f64, [f64; 3])> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("wavelength"))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            (v[0], [v[1], v[2], v[3]])
        })
        .collect()
}

/// Linear interpolation of rows at `nm`; zero outside them.
fn interp(rows: &[(f64, [f64; 3])], nm: f64) -> [f64; 3] {
    match rows.iter().position(|r| r.0 >= nm) {
        Some(k) if rows[k].0 == nm => rows[k].1,
        Some(k) if k > 0 => {
            let (a, b) = (rows[k - 1], rows[k]);
            let f = (nm - a.0) / (b.0 - a.0);
            std::array::from_fn(|c| a.1[c] * (1.0 - f) + b.1[c] * f)
        }
        _ => [0.0; 3],
    }
}

/// A 36-bin spectrum at `nm`: linear between the bins, flat beyond 380 and 730 nm.
fn spectrum_at(s: &Spectrum, nm: f64) -> f64 {
    let x = ((nm - 380.0) / 10.0).clamp(0.0, 35.0);
    let i = (x.floor() as usize).min(34);
    let f = x - i as f64;
    s[i] as f64 * (1.0 - f) + s[i + 1] as f64 * f
}

/// The fitted matrix reproduces the ColorChecker under D65 within the fit's stated residual,
/// recomputed independently: camera RGB by the trapezoidal rule at 1 nm over 360-830 nm of the
/// CSV's curves (read and interpolated here) times the patch's radiance, divided by `∫ g`; the
/// target the patch's linear sRGB from its XYZ, both relative to the Y of D65. The 1 nm
/// trapezoid differs from the exact integral of the piecewise-quadratic integrand by about
/// 1e-5 relative, so the two residuals agree to 1e-4 (the residual itself is 4e-3 for the
/// Gaussian sensor). The white maps to the white to the same 1e-4. And the fit is a minimum:
/// moving any row of the matrix along a direction that keeps the white (the constraint) makes
/// the independent residual larger.
#[test]
fn the_fit_reproduces_the_color_checker_within_its_residual() {
    for file in ["gaussian.csv", "cie1931.csv"] {
        let path = sensor_file(file);
        let sensor = Sensor::from_arg(&path).unwrap();
        let m = sensor.to_srgb().unwrap();
        let stated = sensor.residual().unwrap();
        let curves = read_curves(&path);
        let table: Vec<[f64; 3]> = (360..=830).map(|nm| interp(&curves, nm as f64)).collect();
        let trapezoid = |f: &dyn Fn(usize) -> f64| -> f64 {
            (0..table.len()).map(|i| f(i) * if i == 0 || i == table.len() - 1 { 0.5 } else { 1.0 }).sum()
        };
        let g_area = trapezoid(&|i| table[i][1]);
        let light = d65();
        let white_y = light.to_xyz().y as f64;
        let camera = |s: &Spectrum| -> [f64; 3] {
            std::array::from_fn(|c| trapezoid(&|i| table[i][c] * spectrum_at(s, 360.0 + i as f64)) / g_area / white_y)
        };
        let target = |s: &Spectrum| {
            let x = s.to_xyz() * (1.0 / white_y as f32);
            let rgb = x.to_linear_srgb();
            [rgb.r as f64, rgb.g as f64, rgb.b as f64]
        };
        let patches: Vec<([f64; 3], [f64; 3])> = COLOR_CHECKER_NAMES
            .iter()
            .map(|n| {
                let s = color_checker(n).unwrap() * light;
                (camera(&s), target(&s))
            })
            .collect();
        let rms = |m: &[[f64; 3]; 3]| {
            let sq: f64 = patches
                .iter()
                .map(|(c, t)| {
                    (0..3).map(|k| (m[k][0] * c[0] + m[k][1] * c[1] + m[k][2] * c[2] - t[k]).powi(2)).sum::<f64>()
                })
                .sum();
            (sq / 72.0).sqrt()
        };
        let got = rms(&m);
        eprintln!("{file}: residual stated {stated:.6}, recomputed {got:.6}");
        assert!((got - stated).abs() < 1e-4, "{file}: {got} vs {stated}");
        let (cw, tw) = (camera(&light), target(&light));
        for k in 0..3 {
            let v = m[k][0] * cw[0] + m[k][1] * cw[1] + m[k][2] * cw[2];
            assert!((v - tw[k]).abs() < 1e-4, "{file}: white channel {k}: {v} vs {}", tw[k]);
        }
        if file == "gaussian.csv" {
            for k in 0..3 {
                for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                    // δ with δ · c_w = 0: the white stays where it is.
                    let mut d = [0.0; 3];
                    d[j] = 1.0;
                    d[i] = -cw[j] / cw[i];
                    for eps in [-0.02, 0.02] {
                        let mut p = m;
                        for c in 0..3 {
                            p[k][c] += eps * d[c];
                        }
                        assert!(rms(&p) > got, "{file}: row {k} moved along {d:?} by {eps}: {} <= {got}", rms(&p));
                    }
                }
            }
        }
    }
}

/// With a sensor file the image is bit-identical on 1 and 2 threads, and passes 0..3 + 3..6
/// (merged, or saved and resumed from the checkpoint's bytes) are bit-identical to 0..6.
#[test]
fn sensor_renders_are_deterministic_and_resume_exactly() {
    let sensor = Sensor::from_arg(&sensor_file("gaussian.csv")).unwrap();
    let mut sc = scene("cornell.ron", 16, 6, SettingsPatch::default());
    let one = render_with(&mut sc, &sensor, 0..6, 1);
    let two = render_with(&mut sc, &sensor, 0..6, 2);
    assert_eq!(one, two);
    assert_ne!(one.sums(), render_with(&mut sc, Sensor::cie1931(), 0..6, 2).sums(), "the sensor changes the sums");
    let mut a = render_with(&mut sc, &sensor, 0..3, 2);
    let b = render_with(&mut sc, &sensor, 3..6, 1);
    a.merge(&b).unwrap();
    assert_eq!(a, one);
}

fn ok(o: &std::process::Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Fails with one line on stderr (no panic); returns it.
fn fails(o: &std::process::Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success(), "expected failure");
    assert!(!err.contains("panicked"), "panic: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    err
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn render_cli(out: &Path, extra: &[&str]) -> std::process::Output {
    let scene = root().join("scenes/cornell.ron");
    let mut args = vec!["render", s(&scene), "--width", "12", "--height", "12", "-o", s(out), "--quiet"];
    args.extend_from_slice(extra);
    rust_v(&args)
}

/// Through the binary: the render log prints the matrix and residual; `--color-space camera`
/// writes the raw camera RGB, which the matrix takes to the sRGB EXR of the same render; a
/// resume uses the checkpoint's sensor even when the file is gone; merge refuses parts of
/// different sensors; renders split by passes merge to the whole render's bytes.
#[test]
fn sensor_through_the_binary() {
    let dir = temp_dir("sensor-cli");
    let d = |n: &str| dir.join(n);
    let sensor = d("cam.csv");
    std::fs::copy(sensor_file("gaussian.csv"), &sensor).unwrap();
    let scene = root().join("scenes/cornell.ron");
    let log = rust_v(&[
        "render",
        s(&scene),
        "--width",
        "12",
        "--height",
        "12",
        "--spp",
        "4",
        "-o",
        s(&d("full.exr")),
        "--sensor",
        s(&sensor),
        "--checkpoint",
        s(&d("full.ckpt")),
    ]);
    ok(&log);
    let err = String::from_utf8_lossy(&log.stderr);
    assert!(err.contains("camera RGB -> linear sRGB [[") && err.contains("RMS residual 0.004"), "{err}");
    ok(&render_cli(&d("raw.exr"), &["--spp", "4", "--sensor", s(&sensor), "--color-space", "camera"]));
    let Ok((_, _, Pixels::Linear(srgb))) = read_image(&d("full.exr")) else { panic!("linear EXR") };
    let Ok((_, _, Pixels::Linear(raw))) = read_image(&d("raw.exr")) else { panic!("linear EXR") };
    let m = Sensor::from_arg(&sensor).unwrap().to_srgb().unwrap();
    for (p, c) in srgb.iter().zip(&raw) {
        for k in 0..3 {
            let want = m[k][0] * c[0] + m[k][1] * c[1] + m[k][2] * c[2];
            assert!((p[k] - want).abs() <= 1e-5 * want.abs() + 1e-6, "{p:?} vs M · {c:?}");
        }
    }
    // Split by passes and merged: the whole render's bytes.
    ok(&render_cli(
        &d("a.exr"),
        &["--spp", "4", "--passes", "0..2", "--sensor", s(&sensor), "--checkpoint", s(&d("a.ckpt"))],
    ));
    ok(&render_cli(
        &d("b.exr"),
        &["--spp", "4", "--passes", "2..4", "--sensor", s(&sensor), "--checkpoint", s(&d("b.ckpt"))],
    ));
    ok(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("b.ckpt")), "-o", s(&d("m.exr")), "--quiet"]));
    assert_eq!(std::fs::read(d("full.exr")).unwrap(), std::fs::read(d("m.exr")).unwrap());
    // A part of the default sensor does not merge.
    ok(&render_cli(&d("c.exr"), &["--spp", "4", "--passes", "2..4", "--checkpoint", s(&d("c.ckpt"))]));
    let err = fails(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("c.ckpt")), "-o", s(&d("x.exr"))]));
    assert!(err.contains("c.ckpt") && err.contains("different sensors"), "{err}");
    // Resumed with the sensor file gone: the checkpoint's sensor, the same bytes.
    ok(&render_cli(&d("h.exr"), &["--spp", "2", "--sensor", s(&sensor), "--checkpoint", s(&d("h.ckpt"))]));
    std::fs::remove_file(&sensor).unwrap();
    ok(&rust_v(&["resume", s(&d("h.ckpt")), "--spp", "4", "-o", s(&d("r.exr")), "--quiet"]));
    assert_eq!(std::fs::read(d("full.exr")).unwrap(), std::fs::read(d("r.exr")).unwrap());
    let ckpt = Checkpoint::read(&d("h.ckpt")).unwrap();
    assert_eq!(ckpt.film.sensor().csv(), Some(std::fs::read_to_string(sensor_file("gaussian.csv")).unwrap().as_str()));
    assert!(!d("x.exr").exists());
}

/// Bad sensor files: one line naming the file, line and column, and what was expected; a
/// missing file names the file; `--color-space camera` with the default sensor or a PNG, and
/// `--spectral` with a sensor file, are refused with a sentence saying why.
#[test]
fn hostile_sensors_are_clear_errors() {
    let dir = temp_dir("sensor-hostile");
    let cases: [(&str, &str, &str); 6] = [
        ("missing.csv", "wavelength_nm,r,g,b\n400,0.1,0.5,1\n410,0.2,0.6\n", ":3:1: expected four numbers"),
        (
            "nan.csv",
            "wavelength_nm,r,g,b\n400,0.1,0.5,1\n410,NaN,0.6,0.9\n",
            ":3:5: expected a finite number, found \"NaN\"",
        ),
        ("negative.csv", "400,0.1,0.5,1\n410,0.2,-0.6,0.9\n", ":2:9: the g response is -0.6"),
        ("zero.csv", "nm r g b\n400 0 0.5 1\n410 0 0.6 0.9\n", ":2:5: the r curve is zero at every wavelength"),
        (
            "unsorted.csv",
            "400,0.1,0.5,1\n420,0.2,0.6,0.9\n410,0.3,0.6,0.8\n",
            ":3:1: wavelengths must increase: 410 nm follows 420 nm",
        ),
        ("same.csv", "400,1,1,1\n500,1,1,1\n600,1,1,1\n", ": the three curves are not independent"),
    ];
    for (name, text, want) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let err = fails(&render_cli(&dir.join("x.png"), &["--sensor", s(&path)]));
        assert!(err.contains(&format!("{}{want}", s(&path))), "{name}: {err}");
    }
    let gone = dir.join("gone.csv");
    let err = fails(&render_cli(&dir.join("x.png"), &["--sensor", s(&gone)]));
    assert!(err.contains(s(&gone)) && err.contains("No such file"), "{err}");
    let err = fails(&render_cli(&dir.join("x.exr"), &["--color-space", "camera"]));
    assert!(err.contains("--color-space camera") && err.contains("cie1931"), "{err}");
    let cam = sensor_file("gaussian.csv");
    let err = fails(&render_cli(&dir.join("x.png"), &["--color-space", "camera", "--sensor", s(&cam)]));
    assert!(err.contains("needs an .exr output"), "{err}");
    let err = fails(&render_cli(&dir.join("x.exr"), &["--spectral", "--sensor", s(&cam)]));
    assert!(err.contains("--spectral") && err.contains("--sensor"), "{err}");
    assert!(!dir.join("x.png").exists() && !dir.join("x.exr").exists());
}

/// The RGB mode has no spectrum: with a sensor its linear sRGB goes to camera RGB by the
/// matrix's inverse (in f32) and back by the matrix, so the image is the default's up to f32
/// rounding (1e-5 relative).
#[test]
fn the_rgb_mode_reads_out_the_same_with_a_sensor() {
    let sensor = Sensor::from_arg(&sensor_file("gaussian.csv")).unwrap();
    let patch = SettingsPatch {
        integrator: Some(rust_v::settings::IntegratorKind::Spectral),
        wavelengths: Some(rust_v::settings::WavelengthsKind::Rgb),
        ..SettingsPatch::default()
    };
    let mut sc = scene("cornell.ron", 12, 2, patch);
    let a = render_with(&mut sc, Sensor::cie1931(), 0..2, 2).linear_srgb();
    let b = render_with(&mut sc, &sensor, 0..2, 2).linear_srgb();
    for (p, q) in a.iter().zip(&b) {
        for c in 0..3 {
            assert!((p[c] - q[c]).abs() <= 1e-5 * p[c].abs() + 1e-7, "{p:?} vs {q:?}");
        }
    }
}
