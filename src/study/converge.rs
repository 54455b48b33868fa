//! Convergence studies: render a scene progressively with several methods and seeds,
//! measure the image against a reference at checkpoints, and summarise.
//!
//! This is the measurement behind the thesis' chapter 5 (Figures 5.2, 5.5, 5.7):
//! `rust-v converge` calls [`run`] once per method and seed, writes the records with
//! [`write_records`], their spread over seeds with [`summarise`] /
//! [`write_summary`], the hero/random ratios with [`ratios`], and draws the charts
//! ([`super::chart`]).
//!
//! Timing: the render is split into segments between checkpoints (a render of
//! passes `a..b` is exactly that part of a longer render, see [`crate::render`]), and
//! the recorded seconds are the sum of the segments' own render time. Measuring the
//! image and writing files happen between segments and are not counted, so every
//! method is timed the same way.

use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use super::metrics::{Image, Metrics, Ratios, measure};
use crate::error::{Error, Result};
use crate::film::Film;
use crate::render::{Limits, render};
use crate::scene::Scene;
use crate::settings::{IntegratorKind, WavelengthsKind};

/// A rendering method of a study: an integrator and, for the spectral one, a
/// wavelength sampling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Method {
    /// The name on the command line, in the CSV and in chart legends.
    pub name: &'static str,
    /// The integrator.
    pub integrator: IntegratorKind,
    /// The wavelength sampling (`None`: the scene's, irrelevant for this integrator).
    pub wavelengths: Option<WavelengthsKind>,
}

/// Every method `converge` knows. To add one, add a line here.
pub const METHODS: &[Method] = &[
    Method { name: "auto", integrator: IntegratorKind::Auto, wavelengths: None },
    Method { name: "path", integrator: IntegratorKind::Path, wavelengths: None },
    Method { name: "hero", integrator: IntegratorKind::Spectral, wavelengths: Some(WavelengthsKind::Hero) },
    Method { name: "random", integrator: IntegratorKind::Spectral, wavelengths: Some(WavelengthsKind::Random) },
    Method { name: "whitted", integrator: IntegratorKind::Whitted, wavelengths: None },
    Method { name: "rgb", integrator: IntegratorKind::Spectral, wavelengths: Some(WavelengthsKind::Rgb) },
    Method { name: "bdpt", integrator: IntegratorKind::Bdpt, wavelengths: None },
    Method { name: "lighttrace", integrator: IntegratorKind::LightTrace, wavelengths: None },
    Method { name: "caustics", integrator: IntegratorKind::Caustics, wavelengths: None },
];

impl Method {
    /// The method called `name`, or an error listing the known ones.
    pub fn by_name(name: &str) -> Result<&'static Method> {
        METHODS.iter().find(|m| m.name == name).ok_or_else(|| {
            let known: Vec<&str> = METHODS.iter().map(|m| m.name).collect();
            Error::Settings(format!("--methods: unknown method '{name}' (known: {})", known.join(", ")))
        })
    }

    /// Sets the scene's integrator (and wavelength sampling) to this method's.
    pub fn apply(&self, scene: &mut Scene) {
        scene.settings.integrator = self.integrator;
        if let Some(w) = self.wavelengths {
            scene.settings.wavelengths = w;
        }
    }
}

/// When to measure.
#[derive(Clone, Debug, PartialEq)]
pub enum Schedule {
    /// At these sample counts (increasing).
    Spp(Vec<u32>),
    /// At 1, 2, 4, 8, ... spp until this much render time has been spent.
    Time(Duration),
}

impl Schedule {
    /// The checkpoints, in spp (for [`Schedule::Time`], the geometric series up to 2³¹).
    pub fn checkpoints(&self) -> Vec<u32> {
        match self {
            Schedule::Spp(v) => v.clone(),
            Schedule::Time(_) => (0..32).map(|k| 1u32 << k).collect(),
        }
    }

    /// Checks a user-given schedule: non-empty, positive and strictly increasing.
    pub fn check(&self) -> Result<()> {
        match self {
            Schedule::Spp(v) if v.is_empty() || v[0] == 0 || v.windows(2).any(|w| w[0] >= w[1]) => Err(
                Error::Settings(format!("--spp-schedule {v:?}: expected positive, strictly increasing sample counts")),
            ),
            Schedule::Time(t) if t.is_zero() => {
                Err(Error::Settings("--time: expected a positive number of seconds".into()))
            }
            _ => Ok(()),
        }
    }
}

/// One measurement: a method and seed at a checkpoint.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// The method's name.
    pub method: String,
    /// The sampler seed.
    pub seed: u64,
    /// Passes in the film.
    pub passes: u32,
    /// Samples per pixel (one per pass).
    pub spp: u32,
    /// Render time so far, in seconds (rendering only).
    pub seconds: f64,
    /// The metrics against the reference.
    pub metrics: Metrics,
}

/// Renders `scene` (with its method and seed already set) progressively, measuring
/// against `reference` at each checkpoint of `schedule`; calls `on_record` for each.
pub fn run(
    scene: &Scene,
    method: &str,
    schedule: &Schedule,
    reference: &Image,
    stop: &AtomicBool,
    on_record: &mut dyn FnMut(&Record),
) -> Result<Vec<Record>> {
    let s = &scene.settings;
    let mut film = Film::new(s.width, s.height);
    let budget = match schedule {
        Schedule::Time(t) => Some(*t),
        Schedule::Spp(_) => None,
    };
    let mut spent = Duration::ZERO;
    let mut out = Vec::new();
    for spp in schedule.checkpoints() {
        let left = budget.map(|b| b.saturating_sub(spent));
        if left.is_some_and(|l| l.is_zero()) {
            break;
        }
        let limits = Limits { stop, time_budget: left };
        let done = film.passes();
        let stats = render(scene, &mut film, done..spp, limits, &mut |_, _| {});
        spent += stats.elapsed;
        if stats.invalid_samples > 0 {
            eprintln!("rust-v: warning: {method}: {} NaN or infinite samples were dropped", stats.invalid_samples);
        }
        if stats.interrupted || stats.out_of_time {
            break;
        }
        let metrics = measure(&Image::from_film(&film), reference)?;
        let r = Record {
            method: method.into(),
            seed: s.seed,
            passes: film.passes(),
            spp,
            seconds: spent.as_secs_f64(),
            metrics,
        };
        on_record(&r);
        out.push(r);
    }
    Ok(out)
}

/// The header of the records CSV.
pub const CSV_HEADER: &str = "scene,method,seed,passes,spp,seconds,mse,psnr,ssim,ssim_windowed,variance,mse_lin,psnr_lin,relmse,rel_err_luminance,rel_err_r,rel_err_g,rel_err_b,firefly";

/// Writes the records as CSV (with [`CSV_HEADER`]).
pub fn write_records(path: &Path, scene: &str, records: &[Record]) -> Result<()> {
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for r in records {
        let m = &r.metrics;
        let _ = writeln!(
            s,
            "{scene},{},{},{},{},{:.6},{:.6e},{:.6},{:.8},{:.8},{:.6e},{:.6e},{:.6},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}",
            r.method,
            r.seed,
            r.passes,
            r.spp,
            r.seconds,
            m.mse,
            m.psnr,
            m.ssim,
            m.ssim_windowed,
            m.variance,
            m.mse_lin,
            m.psnr_lin,
            m.relmse,
            m.rel_err_luminance,
            m.rel_err_rgb[0],
            m.rel_err_rgb[1],
            m.rel_err_rgb[2],
            m.firefly
        );
    }
    std::fs::write(path, s).map_err(|e| Error::io(path, e))
}

/// Minimum, median and maximum of a value over seeds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    /// Smallest value.
    pub min: f64,
    /// Median (the mean of the two middle values for an even count).
    pub median: f64,
    /// Largest value.
    pub max: f64,
}

impl Spread {
    /// The spread of `values` (NaN for none).
    pub fn of(values: &[f64]) -> Spread {
        let mut v: Vec<f64> = values.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n == 0 {
            return Spread { min: f64::NAN, median: f64::NAN, max: f64::NAN };
        }
        let median = if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) };
        Spread { min: v[0], median, max: v[n - 1] }
    }
}

/// The metrics that are summarised and charted, with their CSV names.
pub const SUMMARY_METRICS: &[&str] =
    &["mse", "psnr", "ssim", "ssim_windowed", "variance", "mse_lin", "relmse", "firefly"];

/// The value of a metric by its CSV name ([`SUMMARY_METRICS`]).
pub fn metric_value(m: &Metrics, name: &str) -> f64 {
    match name {
        "mse" => m.mse,
        "psnr" => m.psnr,
        "ssim" => m.ssim,
        "ssim_windowed" => m.ssim_windowed,
        "variance" => m.variance,
        "mse_lin" => m.mse_lin,
        "relmse" => m.relmse,
        "firefly" => m.firefly,
        _ => f64::NAN,
    }
}

/// One method at one checkpoint, over all seeds that reached it.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The method.
    pub method: String,
    /// Samples per pixel.
    pub spp: u32,
    /// Number of seeds.
    pub seeds: usize,
    /// Render seconds.
    pub seconds: Spread,
    /// One spread per entry of [`SUMMARY_METRICS`].
    pub metrics: Vec<Spread>,
    /// The median metrics (for ratios).
    pub median: Metrics,
}

/// Groups records by method (in order of first appearance) and spp.
pub fn summarise(records: &[Record]) -> Vec<Summary> {
    let mut methods: Vec<&str> = Vec::new();
    for r in records {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    let mut out = Vec::new();
    for m in methods {
        let mut spps: Vec<u32> = records.iter().filter(|r| r.method == m).map(|r| r.spp).collect();
        spps.sort_unstable();
        spps.dedup();
        for spp in spps {
            let group: Vec<&Record> = records.iter().filter(|r| r.method == m && r.spp == spp).collect();
            let spread =
                |f: &dyn Fn(&Metrics) -> f64| Spread::of(&group.iter().map(|r| f(&r.metrics)).collect::<Vec<_>>());
            let med = |f: &dyn Fn(&Metrics) -> f64| spread(f).median;
            let median = Metrics {
                mse: med(&|m| m.mse),
                psnr: med(&|m| m.psnr),
                ssim: med(&|m| m.ssim),
                ssim_windowed: med(&|m| m.ssim_windowed),
                variance: med(&|m| m.variance),
                mse_lin: med(&|m| m.mse_lin),
                psnr_lin: med(&|m| m.psnr_lin),
                relmse: med(&|m| m.relmse),
                rel_err_luminance: med(&|m| m.rel_err_luminance),
                rel_err_rgb: [0, 1, 2].map(|c| med(&|m| m.rel_err_rgb[c])),
                firefly: med(&|m| m.firefly),
            };
            out.push(Summary {
                method: m.into(),
                spp,
                seeds: group.len(),
                seconds: Spread::of(&group.iter().map(|r| r.seconds).collect::<Vec<_>>()),
                metrics: SUMMARY_METRICS.iter().map(|name| spread(&|x| metric_value(x, name))).collect(),
                median,
            });
        }
    }
    out
}

/// Writes the summary CSV: `method,spp,seeds,seconds_{min,median,max}` and `{metric}_{min,median,max}`.
pub fn write_summary(path: &Path, scene: &str, rows: &[Summary]) -> Result<()> {
    let mut s = String::from("scene,method,spp,seeds,seconds_min,seconds_median,seconds_max");
    for m in SUMMARY_METRICS {
        let _ = write!(s, ",{m}_min,{m}_median,{m}_max");
    }
    s.push('\n');
    for r in rows {
        let _ = write!(
            s,
            "{scene},{},{},{},{:.6},{:.6},{:.6}",
            r.method, r.spp, r.seeds, r.seconds.min, r.seconds.median, r.seconds.max
        );
        for v in &r.metrics {
            let _ = write!(s, ",{:.8e},{:.8e},{:.8e}", v.min, v.median, v.max);
        }
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| Error::io(path, e))
}

/// The hero/random ratios (eqs. 4.9-4.12) of the median metrics at each spp both reached.
pub fn ratios(rows: &[Summary]) -> Vec<(u32, Ratios)> {
    let find = |m: &str, spp: u32| rows.iter().find(|r| r.method == m && r.spp == spp);
    rows.iter()
        .filter(|r| r.method == "hero")
        .filter_map(|h| find("random", h.spp).map(|r| (h.spp, Ratios::new(&h.median, &r.median))))
        .collect()
}

/// Writes the ratios CSV: `spp,mse_ratio,psnr_ratio,ssim_ratio,variance_ratio`.
pub fn write_ratios(path: &Path, scene: &str, ratios: &[(u32, Ratios)]) -> Result<()> {
    let mut s = String::from("scene,spp,mse_ratio,psnr_ratio,ssim_ratio,variance_ratio\n");
    for (spp, r) in ratios {
        let _ = writeln!(s, "{scene},{spp},{:.6},{:.6},{:.6},{:.6}", r.mse, r.psnr, r.ssim, r.variance);
    }
    std::fs::write(path, s).map_err(|e| Error::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_of_odd_and_even_counts() {
        assert_eq!(Spread::of(&[3.0, 1.0, 2.0]), Spread { min: 1.0, median: 2.0, max: 3.0 });
        assert_eq!(Spread::of(&[4.0, 1.0]), Spread { min: 1.0, median: 2.5, max: 4.0 });
    }

    #[test]
    fn schedules_are_checked() {
        assert!(Schedule::Spp(vec![1, 2, 4]).check().is_ok());
        assert!(Schedule::Spp(vec![2, 2]).check().is_err());
        assert!(Schedule::Spp(vec![0, 1]).check().is_err());
        assert!(Schedule::Spp(vec![]).check().is_err());
        assert_eq!(Schedule::Time(Duration::from_secs(1)).checkpoints()[..4], [1, 2, 4, 8]);
    }

    #[test]
    fn methods_are_found_by_name() {
        assert_eq!(Method::by_name("hero").map(|m| m.integrator).ok(), Some(IntegratorKind::Spectral));
        let e = Method::by_name("hera").err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("hera") && e.contains("random"), "{e}");
    }
}
