//! The `compare` and `converge` subcommands: image metrics and convergence studies.
//!
//! The measuring is in the library ([`rust_v::study`]); this module reads the
//! flags, prints, and names the output files.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use rust_v::error::{Error, Result, show_path};
use rust_v::scene::load_scene;
use rust_v::study::chart::{self, Chart, Series};
use rust_v::study::converge::{self, Method, Record, SUMMARY_METRICS, Schedule, Summary};
use rust_v::study::metrics::{Image, Metrics, Ratios, Source, THESIS_L, firefly_share, measure};

use super::args::{CompareArgs, ConvergeArgs};
use super::console::{out, say, thread_pool, warn};

/// Reads both images and measures `a` against `b`; errors name the file(s).
fn compare_files(a: &Path, b: &Path) -> Result<(Image, Image, Metrics)> {
    let ia = Image::read(a)?;
    let ib = Image::read(b)?;
    if (ia.width, ia.height) != (ib.width, ib.height) {
        return Err(Error::Settings(format!(
            "images differ in size: {} is {}x{}, {} is {}x{}",
            show_path(a),
            ia.width,
            ia.height,
            show_path(b),
            ib.width,
            ib.height
        )));
    }
    let m = measure(&ia, &ib)?;
    Ok((ia, ib, m))
}

fn describe(source: Source) -> &'static str {
    match source {
        Source::Linear => "linear float (EXR); 16-bit codes encoded as rust-v's PNG: clamp, sRGB curve, round",
        Source::Encoded => "16-bit sRGB codes (PNG); linear values decoded from the sRGB curve (clamped, quantised)",
    }
}

/// A JSON number, or `null` for infinities and NaN (JSON has neither).
fn json_num(v: f64) -> String {
    if v.is_finite() { format!("{v:e}") } else { "null".into() }
}

fn json_str(s: &str) -> String {
    let mut o = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(o, "\\u{:04x}", c as u32);
            }
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

/// Warns (one line) when one file is a PNG (clamped, sRGB-encoded, quantised) and the
/// other linear (EXR): the linear metrics then compare clamped against unclamped values,
/// while the 16-bit-code metrics compare like with like (the EXR is encoded as rust-v
/// writes a PNG).
fn warn_mixed_sources(a: &Path, sa: Source, b: &Path, sb: Source) {
    if sa == sb {
        return;
    }
    let (png, exr) = if sa == Source::Encoded { (a, b) } else { (b, a) };
    warn(format_args!(
        "{} is a PNG (clamped to [0, 1], sRGB-encoded, 16-bit) and {} linear: the linear metrics (linear MSE and PSNR, relMSE, mean relative errors, firefly share) compare clamped against unclamped values; the 16-bit sRGB metrics (MSE, PSNR, SSIM, variance, windowed SSIM) compare like with like; use EXR files for linear errors",
        show_path(png),
        show_path(exr)
    ));
}

/// `rust-v compare A B [--json]`.
pub fn compare_command(args: CompareArgs) -> Result<()> {
    let (ia, ib, m) = compare_files(&args.a, &args.b)?;
    warn_mixed_sources(&args.a, ia.source, &args.b, ib.source);
    let src = |s: Source| if s == Source::Linear { "linear" } else { "srgb16" };
    if args.json {
        let fields = [
            ("mse", m.mse),
            ("psnr", m.psnr),
            ("ssim", m.ssim),
            ("ssim_windowed", m.ssim_windowed),
            ("variance", m.variance),
            ("mse_lin", m.mse_lin),
            ("psnr_lin", m.psnr_lin),
            ("relmse", m.relmse),
            ("rel_err_luminance", m.rel_err_luminance),
            ("rel_err_r", m.rel_err_rgb[0]),
            ("rel_err_g", m.rel_err_rgb[1]),
            ("rel_err_b", m.rel_err_rgb[2]),
            ("firefly", m.firefly),
            ("firefly_b", firefly_share(&ib.linear)),
        ];
        let mut s = format!(
            "{{\"a\": {}, \"b\": {}, \"width\": {}, \"height\": {}, \"a_source\": \"{}\", \"b_source\": \"{}\", \"l\": {}",
            json_str(&args.a.display().to_string()),
            json_str(&args.b.display().to_string()),
            ia.width,
            ia.height,
            src(ia.source),
            src(ib.source),
            json_num(THESIS_L)
        );
        for (k, v) in fields {
            let _ = write!(s, ", \"{k}\": {}", json_num(v));
        }
        s.push_str("}\n");
        return out(&s);
    }
    let mut o = String::new();
    // Appends a line to the report (writing to a String cannot fail).
    macro_rules! w {
        ($($t:tt)*) => {
            let _ = writeln!(o, $($t)*);
        };
    }
    w!("A: {} ({})", show_path(&args.a), describe(ia.source));
    w!("B: {} ({}) [reference]", show_path(&args.b), describe(ib.source));
    w!("size: {}x{}", ia.width, ia.height);
    w!("thesis metrics (16-bit sRGB codes, pixel = RGB vector, L = {THESIS_L:.4}):");
    w!("  MSE       {:.6e}   (eq. 4.6, mean squared Euclidean RGB distance)", m.mse);
    w!("  PSNR      {:.4} dB  (eq. 4.7)", m.psnr);
    w!("  SSIM      {:.6}   (eq. 4.8, global, on pixel magnitudes, k1 = 0.01, k2 = 0.03)", m.ssim);
    w!("  variance  {:.6e}   (variance of the per-pixel error distance, Figure 5.2d)", m.variance);
    w!("standard:");
    w!("  SSIM      {:.6}   (Wang et al. 2004: 11x11 Gaussian, sigma 1.5, per channel, L = 65535)", m.ssim_windowed);
    w!("linear sRGB (as the Mitsuba harness):");
    w!("  MSE       {:.6e}   (mean over pixels and channels of squared difference)", m.mse_lin);
    w!("  PSNR      {:.4} dB  (peak 1)", m.psnr_lin);
    w!("  relMSE    {:.6e}   (mean of d^2 / (ref^2 + 0.01))", m.relmse);
    w!(
        "  mean relative error |mean_A - mean_B| / mean_B: luminance {:.4e}, R {:.4e}, G {:.4e}, B {:.4e}",
        m.rel_err_luminance,
        m.rel_err_rgb[0],
        m.rel_err_rgb[1],
        m.rel_err_rgb[2]
    );
    w!(
        "  firefly share {:.4e} (reference {:.4e})   (share of total luminance in the brightest 0.1% of pixels)",
        m.firefly,
        firefly_share(&ib.linear)
    );
    out(&o)
}

/// The default schedule: 1, 2, 4, ... below `spp`, then `spp`.
fn geometric_up_to(spp: u32) -> Vec<u32> {
    let mut v: Vec<u32> = (0..32).map(|k| 1u32 << k).take_while(|&s| s < spp).collect();
    v.push(spp);
    v
}

/// `rust-v converge SCENE --reference REF ...`.
pub fn converge_command(args: ConvergeArgs) -> Result<()> {
    let methods: Vec<&'static Method> =
        args.methods.iter().map(|m| Method::by_name(m.trim())).collect::<Result<Vec<_>>>()?;
    let reference = Image::read(&args.reference)?;
    let mut overrides = args.settings.overrides();
    overrides.width = overrides.width.or(Some(reference.width));
    overrides.height = overrides.height.or(Some(reference.height));
    let mut scene = thread_pool(args.run.threads)?.install(|| load_scene(&args.scene, &overrides))?;
    let (w, h) = (scene.settings.width, scene.settings.height);
    if (w, h) != (reference.width, reference.height) {
        return Err(Error::Settings(format!(
            "the render is {w}x{h} but the reference {} is {}x{}",
            show_path(&args.reference),
            reference.width,
            reference.height
        )));
    }
    // The renders are measured as linear images (like an EXR).
    warn_mixed_sources(Path::new("the renders"), Source::Linear, &args.reference, reference.source);
    let schedule = match (&args.time, &args.spp_schedule) {
        (Some(t), _) => Schedule::Time(Duration::from_secs_f64(*t)),
        (None, Some(v)) => Schedule::Spp(v.clone()),
        (None, None) => Schedule::Spp(geometric_up_to(scene.settings.spp)),
    };
    schedule.check()?;
    let out_dir = args.out.clone().unwrap_or_else(|| PathBuf::from("."));
    std::fs::create_dir_all(&out_dir).map_err(|e| Error::io(&out_dir, e))?;
    let name = args.scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
    let pool = thread_pool(args.run.threads)?;
    let stop = AtomicBool::new(false);
    let base_seed = scene.settings.seed;
    let mut records: Vec<Record> = Vec::new();
    for method in &methods {
        for k in 0..args.seeds as u64 {
            method.apply(&mut scene);
            scene.settings.seed = base_seed.wrapping_add(k);
            let quiet = args.run.quiet;
            let mut print = |r: &Record| {
                if !quiet {
                    say(format_args!(
                        "{name} {:8} seed {:3} spp {:6} {:9.3} s  MSE {:.4e}  PSNR {:7.3} dB  SSIM {:.5}  mse_lin {:.4e}",
                        r.method,
                        r.seed,
                        r.spp,
                        r.seconds,
                        r.metrics.mse,
                        r.metrics.psnr,
                        r.metrics.ssim,
                        r.metrics.mse_lin
                    ));
                }
            };
            let got = pool.install(|| converge::run(&scene, method.name, &schedule, &reference, &stop, &mut print))?;
            records.extend(got);
        }
    }
    let file = |suffix: &str| out_dir.join(format!("{name}-{suffix}"));
    let mut written = vec![file("converge.csv"), file("summary.csv")];
    converge::write_records(&written[0], &name, &records)?;
    let summary = converge::summarise(&records);
    converge::write_summary(&written[1], &name, &summary)?;
    let ratios = converge::ratios(&summary);
    if !ratios.is_empty() {
        written.push(file("ratios.csv"));
        converge::write_ratios(&file("ratios.csv"), &name, &ratios)?;
    }
    let seeds = if args.seeds > 1 { format!(", {} seeds (band: min..max)", args.seeds) } else { String::new() };
    let size = format!("{w}x{h}");
    let metric_index = |m: &str| SUMMARY_METRICS.iter().position(|x| *x == m).unwrap_or(0);
    let series = |metric: &str, by_seconds: bool| -> Vec<Series> {
        let i = metric_index(metric);
        let mut out: Vec<Series> = Vec::new();
        for m in &methods {
            let rows: Vec<&Summary> = summary.iter().filter(|r| r.method == m.name).collect();
            if rows.is_empty() {
                continue;
            }
            let points = rows
                .iter()
                .map(|r| {
                    let x = if by_seconds { r.seconds.median } else { r.spp as f64 };
                    (x, r.metrics[i].min, r.metrics[i].median, r.metrics[i].max)
                })
                .collect();
            out.push(Series { label: m.name.to_string(), points });
        }
        out
    };
    let spp_axis = "samples per pixel (spp)";
    let charts: [(&str, &str, &str, bool, bool); 6] = [
        ("mse-spp", "mse", "MSE (16-bit code units²)", true, false),
        ("mse-seconds", "mse", "MSE (16-bit code units²)", true, true),
        ("psnr-spp", "psnr", "PSNR (dB)", false, false),
        ("ssim-spp", "ssim", "SSIM (eq. 4.8, unitless)", false, false),
        ("variance-spp", "variance", "variance of error distance (16-bit code units²)", true, false),
        ("mse_lin-seconds", "mse_lin", "linear MSE (linear sRGB units²)", true, true),
    ];
    for (suffix, metric, y_label, log_y, by_seconds) in charts {
        let title = format!(
            "{name} ({size}): {} vs {}{seeds}",
            metric.to_uppercase().replace('_', " "),
            if by_seconds { "render time" } else { "spp" }
        );
        let x_label = if by_seconds { "render time (s)" } else { spp_axis };
        let c = Chart {
            title,
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_y,
            y_line: None,
            legend_middle: false,
        };
        let stem = file(suffix);
        chart::draw(&stem, &c, &series(metric, by_seconds))?;
        written.push(stem.with_extension("png"));
    }
    if !ratios.is_empty() {
        let pts = |f: &dyn Fn(&Ratios) -> f64| {
            ratios.iter().map(|(spp, r)| (*spp as f64, f(r), f(r), f(r))).collect::<Vec<_>>()
        };
        let s = vec![
            Series { label: "MSE (hero/random)".into(), points: pts(&|r| r.mse) },
            Series { label: "PSNR (random/hero)".into(), points: pts(&|r| r.psnr) },
            Series { label: "SSIM (random/hero)".into(), points: pts(&|r| r.ssim) },
            Series { label: "variance (hero/random)".into(), points: pts(&|r| r.variance) },
        ];
        let c = Chart {
            title: format!("{name} ({size}): hero/random ratios of medians, < 1: hero better"),
            x_label: spp_axis.into(),
            y_label: "ratio (eqs. 4.9-4.11, unitless)".into(),
            log_y: false,
            y_line: Some(1.0),
            legend_middle: true,
        };
        chart::draw(&file("ratios-spp"), &c, &s)?;
        written.push(file("ratios-spp.png"));
    }
    if !args.run.quiet {
        for p in &written {
            say(format_args!("wrote {}", show_path(p)));
        }
        say(format_args!("charts are written as .png and .svg"));
    }
    Ok(())
}
