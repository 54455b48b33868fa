//! The tile scheduler: progressive passes over the film, tiles in parallel.
//!
//! A pass adds one sample to every pixel (thesis §3.6). Within a pass, rayon
//! renders the tiles in parallel; each tile's samples are computed into a
//! buffer of its own and added to the film after the pass (each pixel gets
//! exactly one sample per pass, so the order of tiles does not matter).
//! Sample `k` of pixel `p` draws its random numbers from the stream
//! `(seed, p, k)` ([`crate::sampler`]), so the image is bit-identical for any
//! thread count or tile order, and a render of passes `a..b` is exactly the
//! corresponding part of a longer render. No locks or atomics are touched
//! per sample (one relaxed load of the stop flag per tile); allocation is one
//! buffer per tile per pass. After a pass, bands of tile rows are added to the
//! film in parallel.
//!
//! A render stops early, between tiles, when its `stop` flag is set: the
//! unfinished pass is discarded, so the film always holds whole passes.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::Vec2;
use rayon::prelude::*;

use crate::color::Xyz;
use crate::film::{Film, Tile, tiles};
use crate::integrator::{Estimator, EstimatorFn, with_estimator};
use crate::sampler::Sampler;
use crate::scene::Scene;

/// Tile edge in pixels.
pub const TILE_SIZE: u32 = 16;

/// What the renderer reports after each pass.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Passes in the film now.
    pub passes_done: u32,
    /// Passes this call plans to render.
    pub passes_planned: u32,
    /// Passes rendered by this call so far.
    pub passes_this_run: u32,
    /// Render time of this call so far.
    pub elapsed: Duration,
    /// Samples per pass (pixels).
    pub samples_per_pass: u64,
}

/// A summary of one render call.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderStats {
    /// Passes completed.
    pub passes: u32,
    /// Samples that were NaN or infinite and were dropped (always a bug).
    pub invalid_samples: u64,
    /// Wall time spent rendering.
    pub elapsed: Duration,
    /// True when the stop flag ended the render before its last pass.
    pub interrupted: bool,
    /// True when the time budget ended the render before its last pass.
    pub out_of_time: bool,
}

/// When to stop a render early.
#[derive(Clone, Copy, Debug)]
pub struct Limits<'a> {
    /// Set by a signal handler: stop after the current tile.
    pub stop: &'a AtomicBool,
    /// A time budget: no new pass starts after it has run out.
    pub time_budget: Option<Duration>,
}

/// Renders passes `passes` (pass indices, whole samples per pixel) into
/// `film`, calling `on_pass` on the calling thread after each completed pass.
///
/// An empty film starts at `passes.start`; a film that already holds passes
/// must end where `passes` starts (a resumed render).
///
/// # Panics
/// When `film` holds passes and `passes` does not continue them: callers
/// check this (e.g. [`crate::checkpoint`] resume does).
pub fn render(
    scene: &Scene,
    film: &mut Film,
    passes: Range<u32>,
    limits: Limits<'_>,
    on_pass: &mut dyn FnMut(&Film, &Progress),
) -> RenderStats {
    with_estimator(&scene.settings, Run { scene, film, passes, limits, on_pass })
}

struct Run<'a, 'b> {
    scene: &'a Scene,
    film: &'a mut Film,
    passes: Range<u32>,
    limits: Limits<'b>,
    on_pass: &'a mut dyn FnMut(&Film, &Progress),
}

impl EstimatorFn<RenderStats> for Run<'_, '_> {
    fn call<E: Estimator>(self, estimator: &E) -> RenderStats {
        let Run { scene, film, passes, limits, on_pass } = self;
        if film.passes() == 0 {
            film.start_at(passes.start);
        }
        assert_eq!(film.pass_range().end, passes.start, "render must continue the film's passes");
        let tiles = tiles(film.width(), film.height(), TILE_SIZE);
        let start = Instant::now();
        let mut stats = RenderStats::default();
        let planned = passes.len() as u32;
        for pass in passes {
            if limits.stop.load(Ordering::Relaxed) {
                stats.interrupted = true;
                break;
            }
            if limits.time_budget.is_some_and(|b| start.elapsed() >= b) {
                stats.out_of_time = true;
                break;
            }
            let results: Option<Vec<Vec<Xyz>>> = tiles
                .par_iter()
                .map(|tile| {
                    if limits.stop.load(Ordering::Relaxed) {
                        return None;
                    }
                    Some(render_tile(scene, estimator, film.width(), tile, pass))
                })
                .collect();
            let Some(results) = results else {
                stats.interrupted = true;
                break;
            };
            stats.invalid_samples += film.add_tiles_parallel(&tiles, &results, TILE_SIZE) as u64;
            film.end_pass();
            stats.passes += 1;
            let progress = Progress {
                passes_done: film.passes(),
                passes_planned: planned,
                passes_this_run: stats.passes,
                elapsed: start.elapsed(),
                samples_per_pass: film.width() as u64 * film.height() as u64,
            };
            on_pass(film, &progress);
        }
        stats.elapsed = start.elapsed();
        stats
    }
}

/// One sample for every pixel of `tile` in pass `pass`.
fn render_tile<E: Estimator>(scene: &Scene, estimator: &E, width: u32, tile: &Tile, pass: u32) -> Vec<Xyz> {
    let seed = scene.settings.seed;
    let mut out = Vec::with_capacity(tile.len());
    for y in tile.y0..tile.y1 {
        for x in tile.x0..tile.x1 {
            let pixel = y as u64 * width as u64 + x as u64;
            let mut sampler = Sampler::new(seed, pixel, pass as u64);
            let jitter = sampler.next_2d();
            let film_pos = Vec2::new(x as f32, y as f32) + jitter;
            out.push(estimator.sample(scene, film_pos, &mut sampler));
        }
    }
    out
}
