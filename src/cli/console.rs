//! The console: what a user sees while rust-v works (a progress bar, notes
//! and warnings, a render's summary), and the worker thread pool the
//! commands share.
//!
//! Nothing here can abort a render: every write to stderr or stdout ignores
//! (stderr) or returns (stdout) its error, so a closed pipe, a full disk
//! behind a redirection or `2>&1 | head` never panics and never loses an
//! image. The progress bar (indicatif) is drawn only when stderr is a
//! terminal; otherwise a plain progress line goes out at most every
//! [`PLAIN_EVERY`].
//!
//! `--quiet` silences progress, notes and summaries; warnings always print.

use std::io::{IsTerminal, Write};
use std::path::Path;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use rust_v::error::{Error, Result, show_path};
use rust_v::render::{Progress, RenderStats};
use rust_v::scene::Scene;

/// Without a terminal, a plain progress line at most this often.
pub const PLAIN_EVERY: Duration = Duration::from_secs(30);

/// A pool of `threads` workers (default: one per core).
pub fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        b = b.num_threads(n as usize);
    }
    b.build().map_err(|e| {
        let n = threads.map_or_else(|| "the default number of".to_string(), |n| n.to_string());
        Error::Settings(format!("cannot start {n} threads: {e}"))
    })
}

/// Writes `rust-v: LINE` to stderr; a failed write is ignored (there is
/// nowhere left to report it).
pub fn say(line: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr().lock(), "rust-v: {line}");
}

/// Writes `rust-v: warning: LINE` to stderr (even with `--quiet`).
pub fn warn(line: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr().lock(), "rust-v: warning: {line}");
}

/// Writes `text` to stdout (the command's data, e.g. `compare --json`);
/// unlike stderr, a failure here is the command's failure.
pub fn out(text: &str) -> Result<()> {
    let mut o = std::io::stdout().lock();
    o.write_all(text.as_bytes())
        .and_then(|()| o.flush())
        .map_err(|e| Error::Settings(format!("cannot write to standard output: {e}")))
}

/// `n` and a noun, plural unless `n` is 1: `count(1, "pass")` is "1 pass",
/// `count(2, "pass")` "2 passes", `count(3, "light")` "3 lights". Every count
/// printed with a noun goes through here.
pub fn count(n: impl Into<u64>, noun: &str) -> String {
    let n = n.into();
    if n == 1 {
        format!("1 {noun}")
    } else if noun.ends_with('s') || noun.ends_with('x') || noun.ends_with("ch") || noun.ends_with("sh") {
        format!("{n} {noun}es")
    } else {
        format!("{n} {noun}s")
    }
}

/// Prints the warnings and the summary of a finished render.
pub fn report(scene: &Scene, stats: &RenderStats, output: &Path, quiet: bool) {
    if stats.clamped_samples > 0 {
        warn(format_args!(
            "{} {} brighter than the film's range ±2^31 and clamped: the image is darker there than the scene",
            count(stats.clamped_samples, "sample"),
            if stats.clamped_samples == 1 { "was" } else { "were" }
        ));
    }
    if stats.invalid_samples > 0 {
        warn(format_args!(
            "{} {} NaN or infinite and dropped: a bug, please report it with the scene",
            count(stats.invalid_samples, "sample"),
            if stats.invalid_samples == 1 { "was" } else { "were" }
        ));
    }
    if !quiet {
        let samples = stats.passes as f64 * scene.settings.width as f64 * scene.settings.height as f64;
        say(format_args!(
            "wrote {} ({} in {:.2} s, {:.3} Msamples/s)",
            show_path(output),
            count(stats.passes, "pass"),
            stats.elapsed.as_secs_f64(),
            samples / stats.elapsed.as_secs_f64().max(1e-9) / 1e6
        ));
    }
}

/// Render progress: an indicatif bar on a terminal, an occasional plain
/// line otherwise, nothing with `--quiet`.
pub struct ProgressView {
    quiet: bool,
    bar: Option<ProgressBar>,
    last_plain: Option<Instant>,
    budget: Option<Duration>,
}

impl ProgressView {
    /// A view that prints nothing when `quiet`; with a time budget, time left counts down to it.
    pub fn new(quiet: bool, budget: Option<Duration>) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr_with_hz(5));
            let style = if budget.is_some() {
                ProgressStyle::with_template("{spinner} pass {pos} {msg}")
            } else {
                ProgressStyle::with_template("[{bar:30}] pass {pos}/{len} {msg}")
            };
            bar.set_style(style.unwrap_or_else(|_| ProgressStyle::default_bar()).progress_chars("=> "));
            bar
        });
        ProgressView { quiet, bar, last_plain: None, budget }
    }

    /// Shows the progress after a batch of passes.
    pub fn update(&mut self, p: &Progress) {
        if self.quiet {
            return;
        }
        let secs = p.elapsed.as_secs_f64().max(1e-9);
        let rate = p.passes_this_run as f64 * p.samples_per_pass as f64 / secs;
        let mut left =
            secs / p.passes_this_run.max(1) as f64 * p.passes_planned.saturating_sub(p.passes_this_run) as f64;
        if let Some(b) = self.budget {
            left = left.min((b.as_secs_f64() - secs).max(0.0));
        }
        let open_ended = p.passes_planned == u32::MAX;
        let msg = format!("{:.2} Msamples/s  {:.1} s left", rate / 1e6, left);
        match &self.bar {
            Some(bar) => {
                if !open_ended {
                    bar.set_length(p.passes_planned as u64);
                }
                bar.set_position(p.passes_this_run as u64);
                bar.set_message(msg);
            }
            None => {
                let done = p.passes_this_run == p.passes_planned;
                if done || self.last_plain.is_some_and(|t| t.elapsed() < PLAIN_EVERY) {
                    return;
                }
                if self.last_plain.is_none() {
                    // The first batch: start the clock, print nothing yet.
                    self.last_plain = Some(Instant::now());
                    return;
                }
                self.last_plain = Some(Instant::now());
                let of = if open_ended { String::new() } else { format!("/{}", p.passes_planned) };
                say(format_args!("pass {}{of}, {msg}", p.passes_this_run));
            }
        }
    }

    /// Prints a note (not with `--quiet`) without tearing the bar.
    pub fn note(&self, line: std::fmt::Arguments<'_>) {
        if !self.quiet {
            self.above(|| say(line));
        }
    }

    /// Prints a warning (always) without tearing the bar.
    pub fn warn(&self, line: std::fmt::Arguments<'_>) {
        self.above(|| warn(line));
    }

    fn above(&self, f: impl FnOnce()) {
        match &self.bar {
            Some(bar) => bar.suspend(f),
            None => f(),
        }
    }

    /// Removes the bar.
    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}
