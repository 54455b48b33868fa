//! A render session: the render loop of `render` and `resume` with signals,
//! PNG snapshots, checkpoints and the final outputs.
//!
//! Signal handlers only set flags (`signal_hook::flag::register`); all I/O
//! happens on the main thread between batches of passes (one pass for
//! images of 256 tiles or more, up to 16 for small ones: [`rust_v::render`]),
//! in the renderer's `on_pass` callback, so snapshots and checkpoints always
//! hold whole passes:
//! - SIGUSR1: a PNG snapshot `NAME-00128.png` (passes so far), then go on.
//! - SIGUSR2: a checkpoint, then go on.
//! - SIGINT, SIGTERM: set the renderer's stop flag, which its tile loop
//!   checks, so unfinished passes are abandoned after the tiles in flight;
//!   then write both and exit 0. Further SIGINTs only set the flag again:
//!   they cannot interrupt the saving. Every file is written atomically
//!   ([`rust_v::io::atomic_file`]), so even `kill -9` mid-write leaves the old
//!   or the new file, never a torn one.
//!
//! Signals that arrive faster than batches complete coalesce: one snapshot
//! or checkpoint per batch at most.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use signal_hook::SigId;

use rust_v::checkpoint::{Checkpoint, snapshot_path};
use rust_v::error::{Error, Result};
use rust_v::film::Film;
use rust_v::render::{Limits, render};
use rust_v::scene::Scene;

use super::console::{ProgressBar, report, thread_pool};

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
    /// No progress or notes on stderr.
    pub quiet: bool,
    /// Stop after this much render time, in whole passes (`render --time`).
    pub budget: Option<Duration>,
}

/// The signal flags of a running render; dropping it restores default handling.
pub struct Session {
    snapshot: Arc<AtomicBool>,
    checkpoint: Arc<AtomicBool>,
    stop: Arc<AtomicBool>,
    ids: Vec<SigId>,
}

impl Session {
    /// Registers the signal handlers.
    pub fn start() -> Result<Session> {
        let mut s =
            Session { snapshot: Arc::default(), checkpoint: Arc::default(), stop: Arc::default(), ids: Vec::new() };
        let mut register = |signal: i32, flag: &Arc<AtomicBool>| -> Result<()> {
            let id = signal_hook::flag::register(signal, Arc::clone(flag))
                .map_err(|e| Error::Settings(format!("cannot install a handler for signal {signal}: {e}")))?;
            s.ids.push(id);
            Ok(())
        };
        use signal_hook::consts::{SIGINT, SIGTERM};
        register(SIGINT, &s.stop)?;
        register(SIGTERM, &s.stop)?;
        #[cfg(unix)]
        {
            use signal_hook::consts::{SIGUSR1, SIGUSR2};
            register(SIGUSR1, &s.snapshot)?;
            register(SIGUSR2, &s.checkpoint)?;
        }
        Ok(s)
    }

    /// Renders `ckpt`'s film on to pass `end`, acting on signals and the
    /// checkpoint interval between passes, then writes the outputs.
    pub fn run(self, scene: &Scene, mut ckpt: Checkpoint, end: u32, plan: &SessionPlan) -> Result<()> {
        let pool = thread_pool(plan.threads)?;
        let mut film = std::mem::replace(&mut ckpt.film, Film::new(0, 0));
        let start = film.pass_range().end;
        let mut bar = ProgressBar::new(plan.quiet, plan.budget);
        let mut last_checkpoint = Instant::now();
        let stats = pool.install(|| {
            render(
                scene,
                &mut film,
                start..end.max(start),
                Limits { stop: &self.stop, time_budget: plan.budget },
                &mut |film, progress| {
                    bar.update(progress);
                    if self.snapshot.swap(false, Ordering::SeqCst) {
                        let r = write_snapshot(film, plan);
                        note(&mut bar, plan.quiet, r);
                    }
                    let due = plan.every.is_some_and(|d| last_checkpoint.elapsed() >= d);
                    if self.checkpoint.swap(false, Ordering::SeqCst) || due {
                        let r = write_checkpoint(&ckpt, film, plan);
                        note(&mut bar, plan.quiet, r);
                        last_checkpoint = Instant::now();
                    }
                },
            )
        });
        bar.finish();
        ckpt.film = film;
        let stopped = self.stop.load(Ordering::SeqCst);
        if stopped {
            let snapshot = write_snapshot(&ckpt.film, plan)?;
            let checkpoint = write_checkpoint(&ckpt, &ckpt.film, plan)?;
            if !plan.quiet {
                eprintln!("rust-v: stopped by a signal: {snapshot}; {checkpoint}");
                eprintln!("rust-v: continue with: rust-v resume {}", plan.checkpoint_path.display());
            }
        }
        if !stats.interrupted {
            ckpt.film.write(&plan.output)?;
            if plan.final_checkpoint && !stopped {
                let msg = write_checkpoint(&ckpt, &ckpt.film, plan)?;
                if !plan.quiet {
                    eprintln!("rust-v: {msg}");
                }
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

/// Prints a note or a warning between progress bar lines. A failed write
/// during the render does not stop it: the next attempt may succeed.
fn note(bar: &mut ProgressBar, quiet: bool, r: Result<String>) {
    match r {
        Ok(msg) if !quiet => {
            bar.finish();
            eprintln!("rust-v: {msg}");
        }
        Ok(_) => {}
        Err(e) => {
            bar.finish();
            eprintln!("rust-v: warning: {e}");
        }
    }
}

fn write_snapshot(film: &Film, plan: &SessionPlan) -> Result<String> {
    let path = snapshot_path(&plan.output, film.passes());
    film.write(&path)?;
    Ok(format!("wrote snapshot {} ({} passes)", path.display(), film.passes()))
}

fn write_checkpoint(ckpt: &Checkpoint, film: &Film, plan: &SessionPlan) -> Result<String> {
    let t = Instant::now();
    let size = ckpt.write_with(film, &plan.checkpoint_path)?;
    let r = film.pass_range();
    Ok(format!(
        "wrote checkpoint {} (passes {}..{}, {:.2} MB in {:.0} ms)",
        plan.checkpoint_path.display(),
        r.start,
        r.end,
        size as f64 / 1e6,
        t.elapsed().as_secs_f64() * 1e3
    ))
}
