//! Image metrics against independent truths (closed forms, hand-computed values,
//! properties), and the `compare` and `converge` subcommands through the binary.

use rust_v::study::metrics::{
    CHANNEL_L, Image, K1, THESIS_L, error_variance, measure, mse16, psnr16, ssim_global, ssim_windowed,
};

use crate::common::{root, rust_v, temp_dir};

/// A small deterministic pseudo-random sequence in [-1, 1] (xorshift), independent of the renderer.
fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

#[test]
fn l_constant_is_the_thesis_value() {
    assert!((THESIS_L - 113_509.949_7).abs() < 1e-4);
}

#[test]
fn mse_and_psnr_of_constant_images_have_closed_forms() {
    // Every pixel differs by (3, 4, 12): squared distance 9 + 16 + 144 = 169.
    let a = vec![[1000.0, 2000.0, 3000.0]; 12];
    let b = vec![[1003.0, 2004.0, 3012.0]; 12];
    assert_eq!(mse16(&a, &b), 169.0);
    let psnr = 20.0 * THESIS_L.log10() - 10.0 * 169f64.log10();
    assert!((psnr16(169.0) - psnr).abs() < 1e-12);
    // = 10 log10(L² / MSE), eq. 4.7's first form.
    assert!((psnr16(169.0) - 10.0 * (THESIS_L * THESIS_L / 169.0).log10()).abs() < 1e-9);
    assert!(psnr16(0.0).is_infinite());
    // A uniform error has no spread.
    assert_eq!(error_variance(&a, &b), 0.0);
}

#[test]
fn ssim_of_an_image_with_itself_is_exactly_one() {
    let n = noise(3 * 20 * 14, 7);
    let a: Vec<[f64; 3]> = n.chunks(3).map(|c| [c[0], c[1], c[2]].map(|v| 30000.0 + 20000.0 * v)).collect();
    assert_eq!(ssim_global(&a, &a), 1.0);
    assert_eq!(ssim_windowed(&a, &a, 20, 14), 1.0);
}

#[test]
fn global_ssim_matches_a_hand_computed_value() {
    // Two pixels per image. Magnitudes: |(3000, 4000, 0)| = 5000, |(0, 6000, 8000)| = 10000.
    let a = [[3000.0, 4000.0, 0.0], [0.0, 0.0, 0.0]];
    let b = [[0.0, 6000.0, 8000.0], [0.0, 0.0, 0.0]];
    // x = (5000, 0), y = (10000, 0): means 2500 and 5000; variances (eq. 4.3, 1/N)
    // 2500² and 5000²; covariance (2500 · 5000 + 2500 · 5000) / 2 = 12.5e6.
    let (mx, my) = (2500.0, 5000.0);
    let (vx, vy, cov) = (6.25e6, 25e6, 12.5e6);
    let c1 = (0.01f64 * 113_509.949_674_026_37).powi(2);
    let c2 = (0.03f64 * 113_509.949_674_026_37).powi(2);
    let expected = (2.0 * mx * my + c1) * (2.0 * cov + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
    assert!((ssim_global(&a, &b) - expected).abs() < 1e-12, "{} vs {expected}", ssim_global(&a, &b));
    assert!(expected < 1.0);
}

/// A known implementation's value: scikit-image 0.26.0's
/// `structural_similarity(a, b, gaussian_weights=True, sigma=1.5,
/// use_sample_covariance=False, data_range=65535, channel_axis=2)` on this
/// 24x20 pattern (computed outside the crate, in numpy) is 0.7902969638918513.
/// Its window is 11x11 (truncate 3.5), it crops the borders to the valid
/// positions and averages over channels, as ours does.
#[test]
fn windowed_ssim_matches_scikit_image_on_a_test_pattern() {
    let (w, h) = (24usize, 20usize);
    let mut a = Vec::new();
    let mut b = Vec::new();
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            a.push([
                ((x * 2311 + y * 977) % 65536) as f64,
                ((x * x * 131 + y * 3001) % 65536) as f64,
                (((x + y) * 4099) % 65536) as f64,
            ]);
            b.push([
                ((x * 2311 + y * 977 + (x * y * 17) % 9000) % 65536) as f64,
                ((x * x * 131 + y * 3001 + 5000) % 65536) as f64,
                (((x + y) * 4099 + (y * y * 53) % 7000) % 65536) as f64,
            ]);
        }
    }
    let s = ssim_windowed(&a, &b, w, h);
    assert!((s - 0.790_296_963_891_851_3).abs() < 1e-9, "{s}");
}

#[test]
fn windowed_ssim_of_constant_images_has_a_closed_form() {
    // Constant images: on every window σx = σy = σxy = 0, so each channel's SSIM is
    // (2 c d + c1) / (c² + d² + c1); the result is the mean over channels.
    let (w, h) = (16, 13);
    let x = [10000.0, 20000.0, 40000.0];
    let y = [12000.0, 20000.0, 30000.0];
    let a = vec![x; w * h];
    let b = vec![y; w * h];
    let c1 = (K1 * CHANNEL_L).powi(2);
    let expected = (0..3).map(|c| (2.0 * x[c] * y[c] + c1) / (x[c] * x[c] + y[c] * y[c] + c1)).sum::<f64>() / 3.0;
    assert!((ssim_windowed(&a, &b, w, h) - expected).abs() < 1e-9);
}

#[test]
fn windowed_ssim_is_symmetric_and_falls_with_noise_amplitude() {
    let (w, h) = (24, 20);
    let base = vec![[30000.0, 25000.0, 20000.0]; w * h];
    let n = noise(3 * w * h, 3);
    let noisy = |amp: f64| -> Vec<[f64; 3]> {
        base.iter().zip(n.chunks(3)).map(|(p, e)| [p[0] + amp * e[0], p[1] + amp * e[1], p[2] + amp * e[2]]).collect()
    };
    // A constant base: per window the luminance term falls with |amp · mean(noise)| and
    // the structure term is c2 / (c2 + amp² σn²), so SSIM falls strictly with amp.
    let mut last = 1.0;
    for amp in [100.0, 500.0, 2000.0, 8000.0, 16000.0] {
        let b = noisy(amp);
        let s = ssim_windowed(&base, &b, w, h);
        assert!(s < last, "amplitude {amp}: {s} !< {last}");
        assert!((s - ssim_windowed(&b, &base, w, h)).abs() < 1e-12, "not symmetric");
        last = s;
    }
    // A textured pair too: symmetric.
    let a = noisy(5000.0);
    let b: Vec<[f64; 3]> =
        a.iter().zip(noise(3 * w * h, 9).chunks(3)).map(|(p, e)| p.map(|v| v + 800.0 * e[0])).collect();
    assert!((ssim_windowed(&a, &b, w, h) - ssim_windowed(&b, &a, w, h)).abs() < 1e-12);
}

#[test]
fn measure_refuses_different_sizes() {
    let a = Image::from_linear(2, 2, vec![[0.5; 3]; 4]);
    let b = Image::from_linear(4, 1, vec![[0.5; 3]; 4]);
    assert!(measure(&a, &b).is_err());
    let m = measure(&a, &a).expect("same size");
    assert_eq!((m.mse, m.mse_lin, m.rel_err_luminance), (0.0, 0.0, 0.0));
}

/// Writes a 16-bit PNG of a constant colour.
fn write_png(path: &std::path::Path, w: u32, h: u32, v: u16) {
    image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_raw(w, h, vec![v; (w * h * 3) as usize])
        .expect("size")
        .save(path)
        .expect("png written");
}

#[test]
fn compare_reports_metrics_and_json() {
    let dir = temp_dir("compare");
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    write_png(&a, 8, 8, 1000);
    write_png(&b, 8, 8, 1010);
    let o = rust_v(&["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Squared distance 3 · 10² = 300 on every pixel.
    assert!(out.contains("MSE       3.000000e2") && out.contains("PSNR") && out.contains("SSIM"), "{out}");
    let o = rust_v(&["compare", a.to_str().unwrap(), b.to_str().unwrap(), "--json"]);
    let json = String::from_utf8_lossy(&o.stdout).trim().to_string();
    assert!(json.starts_with('{') && json.ends_with('}'), "{json}");
    for key in ["\"mse\": 3e2", "\"psnr\": ", "\"ssim\": ", "\"ssim_windowed\": ", "\"mse_lin\": ", "\"relmse\": "] {
        assert!(json.contains(key), "{key} missing in {json}");
    }
    assert_eq!(json.matches('{').count(), 1);
    assert!(!json.contains("inf") && !json.contains("NaN"), "{json}");
}

/// A PNG against an EXR (or the other way round): the PNG is clamped and sRGB-encoded,
/// the EXR linear, so the linear metrics compare clamped against unclamped values (a
/// render as PNG gave mse_lin 0.93 against its EXR reference, 0.0031 as EXR). One
/// warning line on stderr names the metrics affected (issue 34 item 13); files of the
/// same kind get none.
#[test]
fn compare_warns_when_a_png_meets_an_exr() {
    let dir = temp_dir("compare-kinds");
    let (png, exr, exr2) = (dir.join("a.png"), dir.join("ref.exr"), dir.join("b.exr"));
    write_png(&png, 8, 8, 65535);
    for p in [&exr, &exr2] {
        image::ImageBuffer::<image::Rgb<f32>, Vec<f32>>::from_raw(8, 8, vec![2.0; 8 * 8 * 3])
            .expect("size")
            .save(p)
            .expect("exr written");
    }
    let s = |p: &std::path::Path| p.to_str().unwrap().to_owned();
    for args in [vec![s(&png), s(&exr)], vec![s(&exr), s(&png)], vec![s(&png), s(&exr), "--json".into()]] {
        let mut all = vec!["compare".to_owned()];
        all.extend(args.iter().cloned());
        let o = rust_v(&all.iter().map(String::as_str).collect::<Vec<_>>());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        let lines: Vec<&str> = err.lines().collect();
        assert_eq!(lines.len(), 1, "{args:?}: {err}");
        assert!(lines[0].starts_with("rust-v: warning: ") && lines[0].contains("a.png"), "{err}");
        for metric in ["linear", "relMSE", "clamped"] {
            assert!(lines[0].contains(metric), "{metric} not in {err}");
        }
    }
    // The linear MSE the warning is about: the PNG's 1.0 against the EXR's 2.0.
    let o = rust_v(&["compare", &s(&png), &s(&exr), "--json"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("\"mse_lin\": 1e0"), "{}", String::from_utf8_lossy(&o.stdout));
    for (a, b) in [(&png, &png), (&exr, &exr2)] {
        let o = rust_v(&["compare", &s(a), &s(b)]);
        assert!(o.status.success() && o.stderr.is_empty(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    // converge measures linear renders: a PNG reference gets the same warning, an EXR none.
    let scene = root().join("scenes/cornell.ron");
    for (reference, warned) in [(&png, true), (&exr, false)] {
        let out = dir.join("out");
        let o = rust_v(&[
            "converge",
            &s(&scene),
            "--reference",
            &s(reference),
            "--methods",
            "path",
            "--spp-schedule",
            "1",
            "--out",
            &s(&out),
            "--quiet",
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert_eq!(err.lines().count(), usize::from(warned), "{err}");
        assert!(!warned || (err.contains("a.png") && err.contains("relMSE")), "{err}");
    }
}

#[test]
fn compare_errors_name_the_files() {
    let dir = temp_dir("compare-bad");
    let (a, b) = (dir.join("small.png"), dir.join("wide.png"));
    write_png(&a, 4, 4, 0);
    write_png(&b, 5, 4, 0);
    let o = rust_v(&["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("small.png") && err.contains("wide.png") && err.contains("size"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let junk = dir.join("junk.png");
    std::fs::write(&junk, b"not an image").unwrap();
    for (x, name) in [(junk.to_str().unwrap(), "junk.png"), ("no/such/file.exr", "no/such/file.exr")] {
        let o = rust_v(&["compare", x, a.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(name) && !err.contains("panicked"), "{err}");
    }
}

#[test]
fn converge_writes_csv_and_charts_and_error_falls() {
    let dir = temp_dir("converge");
    let scene = root().join("scenes/cornell.ron");
    let reference = dir.join("ref.exr");
    let (s, r) = (scene.to_str().unwrap(), reference.to_str().unwrap());
    let o = rust_v(&["render", s, "-o", r, "--width", "16", "--height", "16", "--spp", "64", "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = dir.join("out");
    let o = rust_v(&[
        "converge",
        s,
        "--reference",
        r,
        "--methods",
        "path,hero",
        "--seeds",
        "2",
        "--spp-schedule",
        "1,2,4",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("cornell-converge.csv")).expect("csv written");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], rust_v::study::converge::CSV_HEADER);
    assert_eq!(lines.len(), 1 + 2 * 2 * 3, "2 methods x 2 seeds x 3 checkpoints");
    for stem in ["mse-spp", "mse-seconds", "psnr-spp", "ssim-spp", "variance-spp"] {
        for ext in ["png", "svg"] {
            let p = out.join(format!("cornell-{stem}.{ext}"));
            assert!(std::fs::metadata(&p).map(|m| m.len() > 1000).unwrap_or(false), "{} missing", p.display());
        }
    }
    // Mean MSE over methods and seeds at 4 spp against 1 spp. The noise part of the
    // MSE falls as 1/spp (to about a quarter); the reference's own noise (64 spp) adds
    // a floor of about 1/64 of the 1-spp error. A ratio below 0.7 leaves a wide margin,
    // and the renders are deterministic (fixed seeds), so this cannot flake.
    let mse_at = |spp: &str| -> f64 {
        let v: Vec<f64> = lines[1..]
            .iter()
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|f| f[4] == spp)
            .map(|f| f[6].parse::<f64>().expect("mse"))
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    assert!(mse_at("4") < 0.7 * mse_at("1"), "MSE at 4 spp {} vs 1 spp {}", mse_at("4"), mse_at("1"));
}

#[test]
fn converge_rejects_unknown_methods_and_mismatched_reference() {
    let dir = temp_dir("converge-bad");
    let reference = dir.join("ref.png");
    write_png(&reference, 8, 8, 0);
    let scene = root().join("scenes/cornell.ron");
    let (s, r) = (scene.to_str().unwrap(), reference.to_str().unwrap());
    let o = rust_v(&["converge", s, "--reference", r, "--methods", "path,hera", "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("hera"), "{err}");
    let o = rust_v(&["converge", s, "--reference", r, "--width", "9", "--spp-schedule", "1", "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("ref.png") && err.contains("8x8"), "{err}");
}

#[test]
fn render_stops_after_its_time_budget() {
    let dir = temp_dir("render-time");
    let out = dir.join("t.png");
    let scene = root().join("scenes/cornell.ron");
    let o = rust_v(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "--time",
        "0.3",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(out.exists() && err.contains("passes in"), "{err}");
    let o = rust_v(&["render", scene.to_str().unwrap(), "--time", "-1", "--quiet"]);
    assert!(!o.status.success());
}
