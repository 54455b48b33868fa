//! The command line: subcommands and flags (clap derive), and what each does.
//!
//! `main` only parses, calls [`run`], prints the error and picks the exit code.
//! `render` and `resume` run through [`crate::session`] (signals, snapshots,
//! checkpoints); `merge` combines checkpoints of disjoint pass ranges.

use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::builder::TypedValueParser;
use clap::{Args, Parser, Subcommand};

use rust_v::checkpoint::{Checkpoint, default_checkpoint_path, merge};
use rust_v::error::{Error, Result};
use rust_v::film::Film;
use rust_v::render::Progress;
use rust_v::scene::desc::{IntegratorKind, RenderDesc, WavelengthsKind};
use rust_v::scene::{Scene, load_scene};

use crate::session::{Session, SessionPlan};

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
    ///
    /// While it runs: SIGUSR1 writes a PNG snapshot (NAME-00128.png), SIGUSR2
    /// a checkpoint, SIGINT/SIGTERM both and then exit 0.
    Render(RenderArgs),
    /// Continue a render from a checkpoint and write its image.
    Resume(ResumeArgs),
    /// Sum checkpoints of disjoint pass ranges of one scene into an image or a checkpoint.
    Merge(MergeArgs),
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
    /// Methods, comma-separated: auto, path, hero, random, whitted, rgb.
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
    /// Render only passes A to B-1 (`A..B`), e.g. one job's share of a distributed render.
    #[arg(long, value_name = "A..B", value_parser = parse_pass_range)]
    pub passes: Option<Range<u32>>,
    #[command(flatten)]
    pub checkpoint: CheckpointArgs,
    /// Stop after this many seconds of rendering, in whole passes (no new pass starts
    /// after it). Without --spp the render runs until the time is up.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub time: Option<f64>,
}

/// Checkpoint flags shared by `render` and `resume`.
#[derive(Debug, Args, Clone, Default)]
pub struct CheckpointArgs {
    /// Checkpoint file (default: the output's name with `.ckpt`). When given, the
    /// checkpoint is also written when the render finishes.
    #[arg(long, value_name = "PATH")]
    pub checkpoint: Option<PathBuf>,
    /// Write a checkpoint every SECONDS (between batches of passes).
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub checkpoint_every: Option<f64>,
}

/// Flags of `resume`.
#[derive(Debug, Args)]
pub struct ResumeArgs {
    /// The checkpoint to continue.
    pub checkpoint_file: PathBuf,
    /// Total samples per pixel to reach (default: the original target).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    /// Output image, `.png` or `.exr` (default: the original render's output).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// No progress bar or summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
    /// Checkpoint file (default: the checkpoint resumed). When given, the
    /// checkpoint is also written when the render finishes.
    #[arg(long, value_name = "PATH")]
    pub checkpoint: Option<PathBuf>,
    /// Write a checkpoint every SECONDS (between batches of passes).
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub checkpoint_every: Option<f64>,
    /// Resume even if the scene file changed since the checkpoint was written (the
    /// image then mixes passes of two scenes; the new checkpoint records the new scene).
    #[arg(long)]
    pub force: bool,
}

/// Flags of `merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Checkpoints of disjoint pass ranges of the same scene and settings.
    #[arg(required = true, value_name = "PART.ckpt")]
    pub parts: Vec<PathBuf>,
    /// Output: `.png` or `.exr` writes the image, `.ckpt` a merged checkpoint.
    #[arg(short, long)]
    pub output: PathBuf,
    /// No summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `A..B` with A < B.
fn parse_pass_range(s: &str) -> std::result::Result<Range<u32>, String> {
    let (a, b) = s.split_once("..").ok_or_else(|| format!("expected A..B (e.g. 0..64), got {s:?}"))?;
    let a: u32 = a.trim().parse().map_err(|e| format!("start {a:?}: {e}"))?;
    let b: u32 = b.trim().parse().map_err(|e| format!("end {b:?}: {e}"))?;
    if a >= b {
        return Err(format!("{a}..{b} is empty: the end must be greater than the start"));
    }
    Ok(a..b)
}

/// A positive, finite number of seconds.
fn parse_seconds(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("expected a positive number of seconds, got {s:?}")),
    }
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
    /// Wavelengths per packet of the spectral integrator, and the wavelengths `auto` draws where a path refracts into dispersive glass (1, 2, 4 or 8).
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
        Command::Resume(args) => resume_command(args),
        Command::Merge(args) => merge_command(args),
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
    // Signals first: from here on SIGUSR1/2 no longer kill the process, and
    // the first line on stderr tells a script that it may send them.
    let session = Session::start()?;
    let output = args.output.clone().unwrap_or_else(|| default_output(&args.scene));
    check_output_extension(&output)?;
    let load_start = Instant::now();
    let scene = load_scene(&args.scene, &args.settings.overrides())?;
    let load_time = load_start.elapsed();
    let s = &scene.settings;
    if !args.quiet {
        eprintln!(
            "rust-v: {} ({} objects, {} lights, loaded in {:.2} s): {}x{}, {} spp, {} bounces, seed {}\nrust-v: {}",
            args.scene.display(),
            scene.object_count(),
            scene.lights.len(),
            load_time.as_secs_f64(),
            s.width,
            s.height,
            s.spp,
            s.max_bounces,
            s.seed,
            rust_v::integrator::describe(&scene)
        );
    }
    // With a time budget and no --spp (or --passes), render until the time is up.
    let open_ended = args.time.is_some() && args.settings.spp.is_none() && args.passes.is_none();
    let passes = args.passes.clone().unwrap_or(0..if open_ended { u32::MAX } else { s.spp });
    let scene_path = std::path::absolute(&args.scene).map_err(|e| Error::io(&args.scene, e))?;
    let checkpoint = Checkpoint {
        crate_version: env!("CARGO_PKG_VERSION").into(),
        scene_path,
        content_hash: scene.content_hash,
        settings: scene.settings.clone(),
        target_end: passes.end,
        output: std::path::absolute(&output).map_err(|e| Error::io(&output, e))?,
        film: Film::starting_at(s.width, s.height, passes.start),
    };
    let plan = SessionPlan {
        checkpoint_path: args.checkpoint.checkpoint.clone().unwrap_or_else(|| default_checkpoint_path(&output)),
        final_checkpoint: args.checkpoint.checkpoint.is_some(),
        every: args.checkpoint.checkpoint_every.map(Duration::from_secs_f64),
        output,
        threads: args.threads,
        quiet: args.quiet,
        budget: args.time.map(Duration::from_secs_f64),
    };
    session.run(&scene, checkpoint, passes.end, &plan)
}

fn resume_command(args: ResumeArgs) -> Result<()> {
    let session = Session::start()?;
    let mut ckpt = Checkpoint::read(&args.checkpoint_file)?;
    let path = &args.checkpoint_file;
    if ckpt.crate_version != env!("CARGO_PKG_VERSION") && !args.quiet {
        eprintln!(
            "rust-v: warning: {} was written by rust-v {}, this is {}: new passes may differ from what it would have rendered",
            path.display(),
            ckpt.crate_version,
            env!("CARGO_PKG_VERSION")
        );
    }
    let done = ckpt.passes();
    let end = match args.spp {
        Some(n) => done.start.checked_add(n).ok_or_else(|| Error::Settings(format!("--spp {n} is too large")))?,
        None => ckpt.target_end,
    };
    if args.spp.is_some() {
        ckpt.settings.spp = end - done.start;
    }
    let output = args.output.clone().unwrap_or_else(|| ckpt.output.clone());
    check_output_extension(&output)?;
    let scene = load_scene(&ckpt.scene_path, &ckpt.overrides())
        .map_err(|e| Error::checkpoint(path, format!("cannot load its scene {}: {e}", ckpt.scene_path.display())))?;
    if scene.content_hash != ckpt.content_hash && args.force {
        eprintln!(
            "rust-v: warning: {} changed since the checkpoint was written; resuming anyway (--force)",
            ckpt.scene_path.display()
        );
        ckpt.content_hash = scene.content_hash;
    }
    if scene.content_hash != ckpt.content_hash {
        return Err(Error::checkpoint(
            path,
            format!(
                "the scene file {} changed since the checkpoint was written (content hash {:016x}, was {:016x}); resuming needs the same scene (or --force)",
                ckpt.scene_path.display(),
                scene.content_hash,
                ckpt.content_hash
            ),
        ));
    }
    if scene.settings != ckpt.settings {
        return Err(Error::checkpoint(path, format!("its settings {:?} load as {:?}", ckpt.settings, scene.settings)));
    }
    if !args.quiet {
        eprintln!(
            "rust-v: resuming {} ({}): passes {}..{} done, rendering to pass {}",
            path.display(),
            ckpt.scene_path.display(),
            done.start,
            done.end,
            end.max(done.end)
        );
    }
    ckpt.target_end = end.max(done.end);
    ckpt.output = std::path::absolute(&output).map_err(|e| Error::io(&output, e))?;
    let plan = SessionPlan {
        checkpoint_path: args.checkpoint.clone().unwrap_or_else(|| path.clone()),
        final_checkpoint: args.checkpoint.is_some(),
        every: args.checkpoint_every.map(Duration::from_secs_f64),
        output,
        threads: args.threads,
        quiet: args.quiet,
        budget: None,
    };
    session.run(&scene, ckpt, end, &plan)
}

fn merge_command(args: MergeArgs) -> Result<()> {
    let is_ckpt = args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("ckpt"));
    if !is_ckpt {
        check_output_extension(&args.output)
            .map_err(|_| Error::Settings(format!("output {}: expected .png, .exr or .ckpt", args.output.display())))?;
    }
    let mut parts = Vec::with_capacity(args.parts.len());
    for p in &args.parts {
        parts.push((p.clone(), Checkpoint::read(p)?));
    }
    let merged = merge(parts)?;
    if is_ckpt {
        merged.write(&args.output)?;
    } else {
        merged.film.write(&args.output)?;
    }
    if !args.quiet {
        let r = merged.passes();
        eprintln!(
            "rust-v: merged {} checkpoints (passes {}..{}) into {}",
            args.parts.len(),
            r.start,
            r.end,
            args.output.display()
        );
    }
    Ok(())
}

pub(crate) fn check_output_extension(output: &Path) -> Result<()> {
    match output.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()) {
        Some(e) if e == "png" || e == "exr" => Ok(()),
        _ => Err(Error::Settings(format!("output {}: expected a name ending in .png or .exr", output.display()))),
    }
}

/// Prints the warnings and the summary of a finished render.
pub fn report(scene: &Scene, stats: &rust_v::render::RenderStats, output: &Path, quiet: bool) {
    if stats.invalid_samples > 0 {
        eprintln!(
            "rust-v: warning: {} samples were NaN, infinite (dropped) or beyond ±2^31 (clamped): a bug, please report it",
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
pub struct ProgressBar {
    quiet: bool,
    last: Option<Instant>,
    budget: Option<Duration>,
}

impl ProgressBar {
    /// A bar that prints nothing when `quiet`; with a time budget, time left counts down to it.
    pub fn new(quiet: bool, budget: Option<Duration>) -> Self {
        ProgressBar { quiet, last: None, budget }
    }

    /// Redraws the bar (at most every 200 ms, and after the last pass).
    pub fn update(&mut self, p: &Progress) {
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

    /// Ends the bar's line.
    pub fn finish(&mut self) {
        if !self.quiet && self.last.is_some() {
            eprintln!();
        }
        self.last = None;
    }
}
