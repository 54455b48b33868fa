//! A render session: the render loop of `render` and `resume` with signals,
//! PNG snapshots, checkpoints and the final outputs.
//!
//! Signal handlers only set flags (`signal_hook::flag`); all I/O happens on
//! the main thread between batches of passes (one pass for images of 256
//! tiles or more, up to 16 for small ones: [`rust_v::render`]), in the
//! renderer's `on_pass` callback, so snapshots and checkpoints always hold
//! whole passes:
//! - SIGUSR1: a PNG snapshot `NAME-00128.png` (passes so far), then go on.
//! - SIGUSR2: a checkpoint, then go on.
//! - SIGINT, SIGTERM: while the scene loads (nothing to save yet) they end
//!   the process at once (exit status 130 or 143). Once rendering starts they
//!   set the renderer's stop flag, which its tile loop checks, so unfinished
//!   passes are abandoned after the tiles in flight; then the snapshot and
//!   the checkpoint are written and the process exits 0. Further signals
//!   only set the flag again: they cannot interrupt the saving. Every file is
//!   written atomically ([`rust_v::io::write_atomic`]), so even `kill -9`
//!   mid-write leaves the old or the new file, never a torn one.
//!
//! Finished work is never lost to a failing disk: when the final image
//! cannot be written (disk full, directory removed, permissions changed
//! during the render), the passes go to the checkpoint, or if that fails too
//! to a checkpoint in the system's temporary directory, and the error says
//! where they are and how to continue.
//!
//! Signals that arrive faster than batches complete coalesce: one snapshot
//! or checkpoint per batch at most.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use signal_hook::SigId;

use rust_v::checkpoint::{Checkpoint, snapshot_path};
use rust_v::error::{Error, Result, show_path};
use rust_v::film::Film;
use rust_v::render::{Limits, render};
use rust_v::scene::Scene;

use super::args::{CheckpointArgs, RunArgs};
use super::console::{ProgressView, count, report, thread_pool};

/// Where a session writes and how it runs.
pub struct SessionPlan {
    /// The final image (snapshots go beside it).
    pub output: PathBuf,
    /// Where checkpoints go.
    pub checkpoint_path: PathBuf,
    /// Also write the checkpoint when the render finishes.
    pub final_checkpoint: bool,
    /// Write a checkpoint at this interval (between passes).
    pub every: Option<Duration>,
    /// Worker threads (default: all cores).
    pub threads: Option<u32>,
    /// No progress or notes on stderr (warnings still print).
    pub quiet: bool,
    /// Stop after this much render time, in whole passes (`render --time`).
    pub budget: Option<Duration>,
}

impl SessionPlan {
    /// The plan of `render` or `resume`: checkpoints at `checkpoint_path`
    /// (also at the end when `--checkpoint` was given), the image at `output`,
    /// and an optional time budget in seconds.
    pub fn new(
        checkpoint_path: PathBuf,
        checkpoint: &CheckpointArgs,
        output: PathBuf,
        run: &RunArgs,
        budget_seconds: Option<f64>,
    ) -> SessionPlan {
        SessionPlan {
            checkpoint_path,
            final_checkpoint: checkpoint.checkpoint.is_some(),
            every: checkpoint.checkpoint_every.map(Duration::from_secs_f64),
            output,
            threads: run.threads,
            quiet: run.quiet,
            budget: budget_seconds.map(Duration::from_secs_f64),
        }
    }
}

/// The signal flags of a running render; dropping it restores default handling.
pub struct Session {
    snapshot: Arc<AtomicBool>,
    checkpoint: Arc<AtomicBool>,
    stop: Arc<AtomicBool>,
    /// While set, SIGINT and SIGTERM end the process at once (loading).
    exit_on_stop: Arc<AtomicBool>,
    ids: Vec<SigId>,
}

impl Session {
    /// Registers the signal handlers; until [`Session::run`] starts
    /// rendering, SIGINT and SIGTERM end the process at once.
    pub fn start() -> Result<Session> {
        let mut s = Session {
            snapshot: Arc::default(),
            checkpoint: Arc::default(),
            stop: Arc::default(),
            exit_on_stop: Arc::new(AtomicBool::new(true)),
            ids: Vec::new(),
        };
        let cannot = |signal: i32, e: std::io::Error| {
            Error::Settings(format!("cannot install a handler for signal {signal}: {e}"))
        };
        use signal_hook::consts::{SIGINT, SIGTERM};
        for (signal, status) in [(SIGINT, 130), (SIGTERM, 143)] {
            let id = signal_hook::flag::register_conditional_shutdown(signal, status, Arc::clone(&s.exit_on_stop))
                .map_err(|e| cannot(signal, e))?;
            s.ids.push(id);
            let id = signal_hook::flag::register(signal, Arc::clone(&s.stop)).map_err(|e| cannot(signal, e))?;
            s.ids.push(id);
        }
        #[cfg(unix)]
        {
            use signal_hook::consts::{SIGUSR1, SIGUSR2};
            for (signal, flag) in [(SIGUSR1, &s.snapshot), (SIGUSR2, &s.checkpoint)] {
                let id = signal_hook::flag::register(signal, Arc::clone(flag)).map_err(|e| cannot(signal, e))?;
                s.ids.push(id);
            }
        }
        Ok(s)
    }

    /// Renders `ckpt`'s film on to pass `end`, acting on signals and the
    /// checkpoint interval between passes, then writes the outputs.
    pub fn run(self, scene: &Scene, mut ckpt: Checkpoint, end: u32, plan: &SessionPlan) -> Result<()> {
        let pool = thread_pool(plan.threads)?;
        let mut film = std::mem::replace(&mut ckpt.film, Film::new(0, 0));
        let start = film.pass_range().end;
        let mut view = ProgressView::new(plan.quiet, plan.budget);
        let mut last_checkpoint = Instant::now();
        // From here on a stop signal saves the work instead of ending the process.
        self.exit_on_stop.store(false, Ordering::SeqCst);
        let stats = pool.install(|| {
            render(
                scene,
                &mut film,
                start..end.max(start),
                Limits { stop: &self.stop, time_budget: plan.budget },
                &mut |film, progress| {
                    view.update(progress);
                    if self.snapshot.swap(false, Ordering::SeqCst) {
                        tell(&view, write_snapshot(film, plan));
                    }
                    let due = plan.every.is_some_and(|d| last_checkpoint.elapsed() >= d);
                    if self.checkpoint.swap(false, Ordering::SeqCst) || due {
                        tell(&view, write_checkpoint(&ckpt, film, &plan.checkpoint_path));
                        last_checkpoint = Instant::now();
                    }
                },
            )
        });
        view.finish();
        ckpt.film = film;
        let stopped = self.stop.load(Ordering::SeqCst);
        if stopped {
            // The checkpoint matters more than the snapshot: a failed snapshot is a warning.
            let snapshot = write_snapshot(&ckpt.film, plan);
            if let Err(e) = &snapshot {
                view.warn(format_args!("{e}"));
            }
            let saved = save_work(&ckpt, plan, None)?;
            match snapshot {
                Ok(msg) => view.note(format_args!("stopped by a signal: {msg} and checkpoint {}", show_path(&saved))),
                Err(_) => view.note(format_args!("stopped by a signal: wrote checkpoint {}", show_path(&saved))),
            }
            view.note(format_args!("continue with: rust-v resume {}", show_path(&saved)));
        }
        if !stats.interrupted {
            // The checkpoint first: making the image allocates its buffers, and a
            // failed allocation aborts the process (the up-front memory check makes
            // that unlikely, not impossible), which must not lose the passes.
            let checkpoint = if plan.final_checkpoint && !stopped { Some(save_work(&ckpt, plan, None)?) } else { None };
            if let Err(e) = ckpt.film.write(&plan.output) {
                let saved = save_work(&ckpt, plan, Some(&e))?;
                return Err(Error::Settings(format!(
                    "{e}; the render's {} {} saved in {}: continue with `rust-v resume {} -o OTHER.png`",
                    count(ckpt.film.passes(), "pass"),
                    if ckpt.film.passes() == 1 { "is" } else { "are" },
                    show_path(&saved),
                    show_path(&saved)
                )));
            }
            if let Some(saved) = checkpoint {
                view.note(format_args!("wrote checkpoint {}", show_path(&saved)));
            }
            report(scene, &stats, &plan.output, plan.quiet);
        }
        Ok(())
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        for id in self.ids.drain(..) {
            signal_hook::low_level::unregister(id);
        }
    }
}

/// Prints a note, or a warning for a failed write during the render (which
/// does not stop it: the next attempt may succeed).
fn tell(view: &ProgressView, r: Result<String>) {
    match r {
        Ok(msg) => view.note(format_args!("{msg}")),
        Err(e) => view.warn(format_args!("{e}")),
    }
}

/// Writes the checkpoint where the plan says, or failing that to the
/// system's temporary directory; returns where it went. Fails only when
/// neither can be written, naming both errors (and `cause`, the failure
/// that made saving necessary).
fn save_work(ckpt: &Checkpoint, plan: &SessionPlan, cause: Option<&Error>) -> Result<PathBuf> {
    let first = match ckpt.write_with(&ckpt.film, &plan.checkpoint_path) {
        Ok(_) => return Ok(plan.checkpoint_path.clone()),
        Err(e) => e,
    };
    let fallback = fallback_path(&plan.checkpoint_path);
    match ckpt.write_with(&ckpt.film, &fallback) {
        Ok(_) => {
            super::console::warn(format_args!("{first}; the checkpoint went to {} instead", show_path(&fallback)));
            Ok(fallback)
        }
        Err(second) => {
            let cause = cause.map(|c| format!("{c}; ")).unwrap_or_default();
            Err(Error::Settings(format!(
                "{cause}{first}; {second}: the render's {} could not be saved anywhere",
                count(ckpt.film.passes(), "pass")
            )))
        }
    }
}

/// `$TMPDIR/NAME-PID.ckpt`: where a checkpoint goes when its own place fails.
fn fallback_path(checkpoint: &Path) -> PathBuf {
    let stem = checkpoint.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "render".into());
    let stem: String = stem.chars().take(200).collect();
    std::env::temp_dir().join(format!("{stem}-{}.ckpt", std::process::id()))
}

fn write_snapshot(film: &Film, plan: &SessionPlan) -> Result<String> {
    let path = snapshot_path(&plan.output, film.passes());
    film.write(&path)?;
    Ok(format!("wrote snapshot {} ({})", show_path(&path), count(film.passes(), "pass")))
}

fn write_checkpoint(ckpt: &Checkpoint, film: &Film, path: &Path) -> Result<String> {
    let t = Instant::now();
    let size = ckpt.write_with(film, path)?;
    let r = film.pass_range();
    Ok(format!(
        "wrote checkpoint {} (passes {}..{}, {:.2} MB in {:.0} ms)",
        show_path(path),
        r.start,
        r.end,
        size as f64 / 1e6,
        t.elapsed().as_secs_f64() * 1e3
    ))
}
