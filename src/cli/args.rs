//! Every subcommand and flag of the command line (clap derive): the only
//! place that knows clap. Settings flags become a [`SettingsPatch`], the
//! same type as the scene file's `render` block.

use std::ops::Range;
use std::path::PathBuf;

use clap::builder::PossibleValuesParser;
use clap::{ArgMatches, Args, FromArgMatches, Parser, Subcommand};

use rust_v::color::{ColorSpace, Tonemap};
use rust_v::error::Error;
use rust_v::settings::{FIELDS, SettingsPatch};

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
    /// Render a scene file (RON, or pbrt-v4 `.pbrt`) to a 16-bit sRGB PNG (or a linear EXR).
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
    /// Convert a pbrt-v4 scene file to a RON scene that renders the same image bit for bit.
    Convert(ConvertArgs),
}

/// Flags of `convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// The pbrt-v4 scene file (`.pbrt`).
    pub scene: PathBuf,
    /// The RON scene to write; meshes read from PLY files are written beside it
    /// (`NAME-mesh-K.ply`).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Anything in the pbrt file that is not understood is an error instead of a warning.
    #[arg(long)]
    pub strict: bool,
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
    /// Methods, comma-separated: auto, path, hero, random, whitted, rgb, bdpt, lighttrace.
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
    #[command(flatten)]
    pub run: RunArgs,
}

/// How a command that renders runs: threads and what it prints.
#[derive(Debug, Args, Clone, Default)]
pub struct RunArgs {
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// No progress bar, progress lines or summary on stderr (warnings still print).
    #[arg(short, long)]
    pub quiet: bool,
}

/// Flags of `render`. Settings given here override the scene file's `render` block.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The scene file: RON, or pbrt-v4 when its name ends in `.pbrt`.
    pub scene: PathBuf,
    /// With a `.pbrt` scene: anything not understood is an error instead of a warning.
    #[arg(long)]
    pub strict: bool,
    /// Output image: `.png` (16-bit sRGB) or `.exr` (linear sRGB, float). Default: the scene's name with `.png`, in the current directory.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Colour space of EXR output: srgb (linear, default), rec2020, acescg (Bradford-adapted
    /// from D65), xyz, or camera (a --sensor file's raw camera RGB). PNG output is always sRGB.
    #[arg(long, value_name = "SPACE", default_value = "srgb", value_parser = parse_color_space)]
    pub color_space: ColorSpace,
    /// The camera's sensor: cie1931 (the CIE 1931 colour matching functions, default: the film
    /// holds XYZ) or a CSV of three response curves `wavelength_nm,r,g,b` (the film holds camera
    /// RGB, converted to sRGB by a matrix fitted on the ColorChecker under D65; docs/sensors.md).
    /// Stored in the checkpoint: resume and merge use the checkpoint's.
    #[arg(long, value_name = "cie1931|FILE.csv", default_value = "cie1931")]
    pub sensor: PathBuf,
    #[command(flatten)]
    pub picture: PictureArgs,
    /// With an .exr output: also write the 36 spectral bins (380-730 nm) as channels in the
    /// layout of Fichet et al. 2021, summed exactly like the colour (the checkpoint then holds
    /// them too, so resumed and merged renders stay bit-identical).
    #[arg(long)]
    pub spectral: bool,
    #[command(flatten)]
    pub settings: SettingsArgs,
    #[command(flatten)]
    pub run: RunArgs,
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
    /// Checkpoint file (default: for `render` the output's name with `.ckpt`, for
    /// `resume` the checkpoint resumed). `render` also writes it when the render
    /// finishes if this is given; `resume` always does.
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
    /// Colour space of EXR output: srgb (linear, default; not stored in the checkpoint: give it again), rec2020, acescg (Bradford-adapted
    /// from D65), xyz, or camera (the checkpoint's sensor's raw camera RGB). PNG output is always sRGB.
    #[arg(long, value_name = "SPACE", default_value = "srgb", value_parser = parse_color_space)]
    pub color_space: ColorSpace,
    #[command(flatten)]
    pub picture: PictureArgs,
    #[command(flatten)]
    pub run: RunArgs,
    #[command(flatten)]
    pub checkpoint: CheckpointArgs,
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
    /// Colour space of EXR output: srgb (linear, default), rec2020, acescg (Bradford-adapted
    /// from D65), xyz, or camera (the checkpoints' sensor's raw camera RGB). PNG output is always sRGB.
    #[arg(long, value_name = "SPACE", default_value = "srgb", value_parser = parse_color_space)]
    pub color_space: ColorSpace,
    #[command(flatten)]
    pub picture: PictureArgs,
    /// No summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// How the image becomes a picture: exposure and tone mapping (output choices,
/// like the colour space: not stored in checkpoints, so give them again on
/// `resume` and `merge`).
#[derive(Debug, Args, Clone, Copy, Default)]
pub struct PictureArgs {
    /// Exposure in stops: every output value is scaled by 2^EV (PNG and EXR; -64 to 64).
    #[arg(long, value_name = "EV", default_value_t = 0.0, value_parser = parse_exposure, allow_negative_numbers = true)]
    pub exposure: f64,
    /// How a PNG maps radiance to [0, 1]: clip (each channel clipped, the default: earlier
    /// images unchanged) or filmic (a filmic luminance curve, then out-of-gamut colours move
    /// toward grey at constant luminance). EXR output stays linear.
    #[arg(long, value_name = "OPERATOR", default_value = "clip", value_parser = parse_tonemap)]
    pub tonemap: Tonemap,
}

fn parse_exposure(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && (-64.0..=64.0).contains(&v) => Ok(v),
        _ => Err(format!("expected stops from -64 to 64, found {s:?}")),
    }
}

fn parse_tonemap(s: &str) -> std::result::Result<Tonemap, String> {
    Tonemap::from_name(s).ok_or_else(|| format!("expected one of {}, found {s:?}", Tonemap::NAMES.join(", ")))
}

/// A colour space by name.
fn parse_color_space(s: &str) -> std::result::Result<ColorSpace, String> {
    ColorSpace::from_name(s).ok_or_else(|| format!("expected one of {}, found {s:?}", ColorSpace::NAMES.join(", ")))
}

/// `A..B` with A < B.
fn parse_pass_range(s: &str) -> Result<Range<u32>, Error> {
    let bad = Error::Settings;
    let (a, b) = s.split_once("..").ok_or_else(|| bad(format!("expected A..B (e.g. 0..64), got {s:?}")))?;
    let a: u32 = a.trim().parse().map_err(|e| bad(format!("start {a:?}: {e}")))?;
    let b: u32 = b.trim().parse().map_err(|e| bad(format!("end {b:?}: {e}")))?;
    if a >= b {
        return Err(bad(format!("{a}..{b} is empty: the end must be greater than the start")));
    }
    Ok(a..b)
}

/// The longest time a flag takes: a year, in seconds.
pub const MAX_SECONDS: f64 = 365.25 * 24.0 * 3600.0;

/// The message for a number flag's bad value: the library's parser says "a whole number
/// from 0 to" the type's maximum; when the setting's own check takes a narrower interval
/// (`--spp` from 1, `--width` up to 32768) say that one, found by asking the check, and
/// when it takes a set that is no interval (`--packet-size`) say what the check says.
fn not_a_number(name: &str, text: &str, message: String) -> String {
    let type_max = message
        .strip_prefix("expected a whole number from 0 to ")
        .and_then(|rest| rest.split(',').next())
        .and_then(|n| n.parse::<u64>().ok());
    let Some(type_max) = type_max else { return message };
    let ok = |v: u64| SettingsPatch::default().set(name, &v.to_string()).is_ok();
    let Some(lo) = [0, 1].into_iter().find(|&v| ok(v)) else { return message };
    // The largest value taken (a binary search, right for an interval from `lo`).
    let (mut good, mut bad) = (lo, type_max);
    if ok(type_max) {
        good = type_max;
    }
    while bad - good > 1 {
        let mid = good + (bad - good) / 2;
        if ok(mid) { good = mid } else { bad = mid }
    }
    let interval = [lo + 1, lo + 2, lo + (good - lo) / 3, lo + (good - lo) / 2].into_iter().all(|v| v > good || ok(v));
    if interval {
        return format!("expected a whole number from {lo} to {good}, found {text:?}");
    }
    // Not an interval (`--packet-size`): what the check says of a refused value.
    match SettingsPatch::default().set(name, "0") {
        Err(Error::Setting { message: m, .. }) => {
            format!("{}, found {text:?}", m.split(", found").next().unwrap_or(&m))
        }
        _ => message,
    }
}

/// A positive, finite number of seconds, at most [`MAX_SECONDS`].
fn parse_seconds(s: &str) -> Result<f64, Error> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= MAX_SECONDS => Ok(v),
        _ => Err(Error::Settings(format!(
            "expected a positive number of seconds up to {MAX_SECONDS} (a year), got {s:?}"
        ))),
    }
}

/// Render settings shared by the subcommands that render: one flag per
/// setting of [`rust_v::settings::FIELDS`] (`max_bounces` is
/// `--max-bounces`), with the setting's doc as help and its constraint
/// checked as the value is parsed. Not derived: the settings are defined
/// once, in the library, which knows nothing of clap.
#[derive(Debug, Clone, Default)]
pub struct SettingsArgs(pub SettingsPatch);

impl SettingsArgs {
    /// The overrides in the scene format's terms.
    pub fn overrides(&self) -> SettingsPatch {
        self.0.clone()
    }

    /// Whether `--spp` was given.
    pub fn spp_given(&self) -> bool {
        self.0.spp.is_some()
    }
}

/// `max_bounces` -> `max-bounces`.
fn flag(name: &str) -> String {
    name.replace('_', "-")
}

impl Args for SettingsArgs {
    fn augment_args(mut cmd: clap::Command) -> clap::Command {
        for f in FIELDS {
            let name = f.name;
            let arg = clap::Arg::new(name).long(flag(name)).value_name(name.to_uppercase()).help(f.doc.trim());
            cmd = cmd.arg(if f.choices.is_empty() {
                arg.value_parser(move |s: &str| {
                    SettingsPatch::default().set(name, s).map(|()| s.to_string()).map_err(|e| match e {
                        // clap names the flag; the message says what was expected.
                        Error::Setting { message, .. } => Error::Settings(not_a_number(name, s, message)),
                        e => e,
                    })
                })
            } else {
                arg.value_parser(PossibleValuesParser::new(f.choices))
            });
        }
        cmd
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl FromArgMatches for SettingsArgs {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut s = SettingsArgs::default();
        s.update_from_arg_matches(m)?;
        Ok(s)
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        for f in FIELDS {
            if let Some(v) = m.get_one::<String>(f.name) {
                self.0.set(f.name, v).map_err(|e| clap::Error::raw(clap::error::ErrorKind::ValueValidation, e))?;
            }
        }
        Ok(())
    }
}
