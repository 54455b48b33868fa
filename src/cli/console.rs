//! The console: what a user sees on stderr while rust-v works (a progress
//! bar, notes and warnings, a render's summary), and the worker thread pool
//! the commands share.

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use rust_v::error::{Error, Result};
use rust_v::render::{Progress, RenderStats};
use rust_v::scene::Scene;

/// A pool of `threads` workers (default: one per core).
pub fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        b = b.num_threads(n as usize);
    }
    b.build().map_err(|e| Error::Settings(format!("cannot start {threads:?} threads: {e}")))
}

/// Prints the warnings and the summary of a finished render.
pub fn report(scene: &Scene, stats: &RenderStats, output: &Path, quiet: bool) {
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
