//! The command line: subcommands and flags (clap derive), and what each does.
//!
//! `main` only parses, calls [`run`], prints the error and picks the exit code.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use clap::builder::TypedValueParser;
use clap::{Args, Parser, Subcommand};

use rust_v::error::{Error, Result};
use rust_v::film::Film;
use rust_v::render::{Limits, Progress, render};
use rust_v::scene::desc::{IntegratorKind, RenderDesc, WavelengthsKind};
use rust_v::scene::{Scene, load_scene};

/// rust-v: a physically based spectral path tracer.
#[derive(Debug, Parser)]
#[command(name = "rust-v", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a RON scene file to a 16-bit sRGB PNG (or a linear EXR).
    Render(RenderArgs),
    /// Compare two images (PNG 8/16-bit or EXR): thesis MSE, PSNR, SSIM, windowed SSIM, linear errors.
    Compare(CompareArgs),
    /// Convergence study: render progressively with several methods and seeds, measure
    /// against a reference at checkpoints, write CSVs and charts.
    Converge(ConvergeArgs),
}

/// Flags of `compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The image to measure (PNG or EXR).
    pub a: PathBuf,
    /// The reference image (PNG or EXR); relative errors are relative to it.
    pub b: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Flags of `converge`.
#[derive(Debug, Args)]
pub struct ConvergeArgs {
    /// The scene file (RON).
    pub scene: PathBuf,
    /// The reference image (EXR from `rust-v render SCENE -o ref.exr --spp N`, or PNG).
    /// The render size defaults to the reference's.
    #[arg(long)]
    pub reference: PathBuf,
    /// Methods, comma-separated: path, hero, random, whitted, rgb.
    #[arg(long, value_delimiter = ',', default_value = "path,hero,random")]
    pub methods: Vec<String>,
    /// Render each method with this many seeds (the scene's seed, +1, +2, ...) to show the spread.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub seeds: u32,
    /// Render each method (and seed) for this many seconds, measuring at 1, 2, 4, 8, ... spp.
    #[arg(long, value_parser = parse_seconds, conflicts_with = "spp_schedule")]
    pub time: Option<f64>,
    /// Measure at these sample counts, comma-separated (default: 1, 2, 4, ... up to --spp).
    #[arg(long, value_delimiter = ',')]
    pub spp_schedule: Option<Vec<u32>>,
    /// Directory for the CSVs and charts (default: the current directory).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// No progress lines on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// A positive, finite number of seconds.
fn parse_seconds(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v < 1e9 => Ok(v),
        _ => Err(format!("'{s}': expected a positive number of seconds")),
    }
}

/// Flags of `render`. Settings given here override the scene file's `render` block.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The scene file (RON).
    pub scene: PathBuf,
    /// Output image: `.png` (16-bit sRGB) or `.exr` (linear sRGB, float). Default: the scene's name with `.png`, in the current directory.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// No progress bar or summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
    /// Stop after this many seconds of rendering, in whole passes (no new pass starts
    /// after it). Without --spp the render runs until the time is up.
    #[arg(long, value_parser = parse_seconds)]
    pub time: Option<f64>,
}

/// Render settings shared by the subcommands that render.
#[derive(Debug, Args, Clone, Default)]
pub struct SettingsArgs {
    /// Samples per pixel (one pass adds one sample to every pixel).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    /// Seed of the deterministic sampler.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Image width in pixels.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=32768))]
    pub width: Option<u32>,
    /// Image height in pixels.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=32768))]
    pub height: Option<u32>,
    /// Maximum scattering events per path (pbrt's maxdepth; Mitsuba's max_depth minus 1).
    #[arg(long)]
    pub max_bounces: Option<u32>,
    /// Light transport method.
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorKind>,
    /// Wavelength sampling of the spectral integrator.
    #[arg(long, value_enum)]
    pub wavelengths: Option<WavelengthsKind>,
    /// Wavelengths per packet of the spectral integrator (1, 2, 4 or 8).
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(["1", "2", "4", "8"]).map(|s| s.parse::<u32>().unwrap_or(4)))]
    pub packet_size: Option<u32>,
}

impl SettingsArgs {
    /// The overrides in the scene format's terms.
    pub fn overrides(&self) -> RenderDesc {
        RenderDesc {
            width: self.width,
            height: self.height,
            spp: self.spp,
            seed: self.seed,
            max_bounces: self.max_bounces,
            integrator: self.integrator,
            wavelengths: self.wavelengths,
            packet_size: self.packet_size,
        }
    }
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render_command(args),
        Command::Compare(args) => crate::study::compare_command(args),
        Command::Converge(args) => crate::study::converge_command(args),
    }
}

pub(crate) fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        b = b.num_threads(n as usize);
    }
    b.build().map_err(|e| Error::Settings(format!("cannot start {threads:?} threads: {e}")))
}

fn default_output(scene: &Path) -> PathBuf {
    let stem = scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "render".into());
    PathBuf::from(format!("{stem}.png"))
}

fn render_command(args: RenderArgs) -> Result<()> {
    let output = args.output.clone().unwrap_or_else(|| default_output(&args.scene));
    check_output_extension(&output)?;
    let load_start = Instant::now();
    let scene = load_scene(&args.scene, &args.settings.overrides())?;
    let load_time = load_start.elapsed();
    let s = &scene.settings;
    if !args.quiet {
        eprintln!(
            "rust-v: {} ({} objects, {} lights, loaded in {:.2} s): {}x{}, {} spp, {:?} integrator, {} bounces, seed {}",
            args.scene.display(),
            scene.object_count(),
            scene.lights.len(),
            load_time.as_secs_f64(),
            s.width,
            s.height,
            s.spp,
            s.integrator,
            s.max_bounces,
            s.seed
        );
    }
    let mut film = Film::new(s.width, s.height);
    let stop = AtomicBool::new(false);
    let pool = thread_pool(args.threads)?;
    let budget = args.time.map(Duration::from_secs_f64);
    // With a time budget and no explicit --spp, render until the time is up.
    let passes = if budget.is_some() && args.settings.spp.is_none() { u32::MAX } else { s.spp };
    let mut bar = ProgressBar::new(args.quiet, budget);
    let stats = pool.install(|| {
        render(&scene, &mut film, 0..passes, Limits { stop: &stop, time_budget: budget }, &mut |_, p| bar.update(p))
    });
    bar.finish();
    film.write(&output)?;
    report(&scene, &stats, &output, args.quiet);
    Ok(())
}

fn check_output_extension(output: &Path) -> Result<()> {
    match output.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()) {
        Some(e) if e == "png" || e == "exr" => Ok(()),
        _ => Err(Error::Settings(format!("output {}: expected a name ending in .png or .exr", output.display()))),
    }
}

fn report(scene: &Scene, stats: &rust_v::render::RenderStats, output: &Path, quiet: bool) {
    if stats.invalid_samples > 0 {
        eprintln!(
            "rust-v: warning: {} samples were NaN or infinite and were dropped (a bug: please report it)",
            stats.invalid_samples
        );
    }
    if !quiet {
        let samples = stats.passes as f64 * scene.settings.width as f64 * scene.settings.height as f64;
        eprintln!(
            "rust-v: wrote {} ({} passes in {:.2} s, {:.3} Msamples/s)",
            output.display(),
            stats.passes,
            stats.elapsed.as_secs_f64(),
            samples / stats.elapsed.as_secs_f64().max(1e-9) / 1e6
        );
    }
}

/// A one-line progress bar on stderr: passes done, samples per second, time left.
struct ProgressBar {
    quiet: bool,
    last: Option<Instant>,
    budget: Option<Duration>,
}

impl ProgressBar {
    fn new(quiet: bool, budget: Option<Duration>) -> Self {
        ProgressBar { quiet, last: None, budget }
    }

    fn update(&mut self, p: &Progress) {
        let done = p.passes_this_run == p.passes_planned;
        if self.quiet || (!done && self.last.is_some_and(|t| t.elapsed() < Duration::from_millis(200))) {
            return;
        }
        self.last = Some(Instant::now());
        let secs = p.elapsed.as_secs_f64().max(1e-9);
        let rate = p.passes_this_run as f64 * p.samples_per_pass as f64 / secs;
        let mut left = secs / p.passes_this_run as f64 * (p.passes_planned - p.passes_this_run) as f64;
        let width = 30;
        let mut filled = (width as u64 * p.passes_this_run as u64 / p.passes_planned.max(1) as u64) as usize;
        if let Some(b) = self.budget {
            let b = b.as_secs_f64();
            if b - secs < left {
                left = (b - secs).max(0.0);
                filled = ((width as f64 * secs / b) as usize).min(width);
            }
        }
        let mut err = std::io::stderr().lock();
        let _ = write!(
            err,
            "\r[{}{}] pass {}{}  {:.2} Msamples/s  {:.1} s left   ",
            "=".repeat(filled),
            " ".repeat(width - filled),
            p.passes_this_run,
            if p.passes_planned == u32::MAX { String::new() } else { format!("/{}", p.passes_planned) },
            rate / 1e6,
            left
        );
        let _ = err.flush();
    }

    fn finish(&self) {
        if !self.quiet && self.last.is_some() {
            eprintln!();
        }
    }
}
