//! The tile scheduler: progressive passes over the film, tiles in parallel.
//!
//! A pass adds one sample to every pixel (thesis §3.6). Passes are rendered
//! in batches: a batch of `k` passes is one parallel loop over its `k × tiles`
//! (pass, tile) tasks, pass-major, each computing one sample per pixel of its
//! tile into a buffer of its own; after the batch, bands of tile rows add the
//! buffers, and the splats of light subpaths in their rows, to the film in parallel. A batch holds at least
//! `MIN_TASKS_PER_BATCH` tasks where the passes allow it (at most
//! `MAX_PASSES_PER_BATCH` passes, and at most `MAX_BATCH_BYTES` of samples): a
//! barrier per pass over only 64 tiles (a 128×128 image) left a thread idle for
//! half a tile at the end of every pass, a few per cent of the time, and on 16
//! cores a batch of 256 tasks still cost uneven scenes 10-20%.
//!
//! Sample `k` of pixel `p` draws its numbers from the sampler keyed by
//! `(seed, p, k)` (the crate-internal `sampler`, independent or Sobol with index `k`)
//! and the film's sums are exact integers,
//! so the image is bit-identical for any thread count, tile order or batch
//! size, and a render of passes `a..b` is exactly the corresponding part of
//! a longer render. No locks or atomics are touched per sample (one relaxed
//! load of the stop flag per task); allocation is one buffer per task (and,
//! for light subpaths' splats, their buffer and the two of their counting
//! sort by band).
//!
//! A render stops early when its `stop` flag is set: tasks not yet started
//! are skipped, the batch's passes that finished whole (from its first one
//! on) are kept and the rest discarded, so the film always holds whole,
//! contiguous passes. The time budget is checked between batches.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::Vec2;
use rayon::prelude::*;

use crate::color::{Spectrum, Xyz};
use crate::film::{Film, FilmSample, Splat, Tile};
use crate::integrator::{Estimator, EstimatorFn, with_estimator};
use crate::sampler::{Dim, Sampler};
use crate::scene::Scene;
use crate::spectral::Contribution;

/// Tile edge in pixels.
pub const TILE_SIZE: u32 = 16;

/// Splits a `width × height` image into tiles of at most `size × size`, row-major.
pub(crate) fn tiles(width: u32, height: u32, size: u32) -> Vec<Tile> {
    let mut out = Vec::new();
    for y0 in (0..height).step_by(size as usize) {
        for x0 in (0..width).step_by(size as usize) {
            out.push(Tile { x0, y0, x1: (x0 + size).min(width), y1: (y0 + size).min(height) });
        }
    }
    out
}

/// A batch of passes holds at least this many (pass, tile) tasks when the
/// passes allow: the idle tail at a batch's end is then about half a task in
/// this many per thread. 1024 rather than 256: on 16 cores (Xeon, x86-64-v3
/// build, one sitting) the 16-thread render of the spheres at 256² took
/// 0.36 s (median of 3) instead of 0.435 s (median of 8), the full dragon
/// 0.43 s instead of 0.52 s, the prism 0.29 s instead of 0.325 s, and no scene
/// was slower; 4096 gained no more (0.385 s, 0.445 s, 0.31 s) and holds 4 times
/// the samples (docs/performance.md, *Thread scaling on 16 cores*).
pub(crate) const MIN_TASKS_PER_BATCH: usize = 1024;

/// The most passes in one batch: bounds the time between snapshots,
/// checkpoints and progress reports, and what a stop can discard.
pub(crate) const MAX_PASSES_PER_BATCH: u32 = 16;

/// The most bytes of samples a batch holds before the film adds them (the
/// batch's buffers come on top of the film): a spectral film's samples (36 bins,
/// 160 bytes aligned) are 13 times an XYZ film's.
pub(crate) const MAX_BATCH_BYTES: usize = 64 << 20;

/// Passes per batch for an image of `tiles` tiles and `pixels` pixels whose
/// samples are `sample_bytes` each.
pub(crate) fn passes_per_batch(tiles: usize, pixels: usize, sample_bytes: usize) -> u32 {
    let by_memory = (MAX_BATCH_BYTES / (pixels * sample_bytes).max(1)).max(1);
    (MIN_TASKS_PER_BATCH.div_ceil(tiles.max(1)).min(by_memory) as u32).clamp(1, MAX_PASSES_PER_BATCH)
}

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
    /// Samples beyond the film's range ±`film::MAX_SAMPLE` that were clamped
    /// (a light brighter than the range; not a bug, but the image is darker there).
    pub clamped_samples: u64,
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
/// `film`, calling `on_pass` on the calling thread after each completed batch
/// of passes.
///
/// An empty film starts at `passes.start`; a film that already holds passes
/// must end where `passes` starts (a resumed render).
///
/// # Panics
/// When `film` holds passes and `passes` does not continue them: callers
/// check this (e.g. [`crate::checkpoint`] resume does); when the scene's sensor is not the
/// film's ([`Film::set_sensor`]: the film's sums are the scene's sensor's channels).
pub fn render(
    scene: &Scene,
    film: &mut Film,
    passes: Range<u32>,
    limits: Limits<'_>,
    on_pass: &mut dyn FnMut(&Film, &Progress),
) -> RenderStats {
    with_estimator(scene, Run { scene, film, passes, limits, on_pass })
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
        // A spectral film takes each sample's 36 bins; otherwise the samples are XYZ.
        if self.film.spectral_sums().is_some() {
            self.run::<E, Spectrum>(estimator)
        } else {
            self.run::<E, Xyz>(estimator)
        }
    }
}

impl Run<'_, '_> {
    fn run<E: Estimator, O: Contribution + FilmSample>(self, estimator: &E) -> RenderStats {
        let Run { scene, film, passes, limits, on_pass } = self;
        if film.passes() == 0 {
            film.start_at(passes.start);
        }
        assert_eq!(film.pass_range().end, passes.start, "render must continue the film's passes");
        assert!(
            std::sync::Arc::ptr_eq(&scene.sensor, film.sensor()) || scene.sensor == *film.sensor(),
            "the scene's sensor ({}) must be the film's ({})",
            scene.sensor.name(),
            film.sensor().name()
        );
        let tiles = tiles(film.width(), film.height(), TILE_SIZE);
        let pixels = film.width() as usize * film.height() as usize;
        let batch = passes_per_batch(tiles.len(), pixels, std::mem::size_of::<O>());
        let start = Instant::now();
        let mut stats = RenderStats::default();
        let planned = passes.len() as u32;
        let mut next = passes.start;
        while next < passes.end {
            if limits.stop.load(Ordering::Relaxed) {
                stats.interrupted = true;
                break;
            }
            if limits.time_budget.is_some_and(|b| start.elapsed() >= b) {
                stats.out_of_time = true;
                break;
            }
            let k = batch.min(passes.end - next);
            let results: Vec<Option<TileSamples<O>>> = (0..k as usize * tiles.len())
                .into_par_iter()
                .map(|task| {
                    if limits.stop.load(Ordering::Relaxed) {
                        return None;
                    }
                    let pass = next + (task / tiles.len()) as u32;
                    Some(render_tile::<E, O>(scene, estimator, film.width(), &tiles[task % tiles.len()], pass))
                })
                .collect();
            // Keep the passes that finished whole, from the batch's first on.
            // (An empty film has no tiles: its passes are trivially whole.)
            let whole = if tiles.is_empty() {
                k as usize
            } else {
                results.chunks(tiles.len()).take_while(|p| p.iter().all(Option::is_some)).count()
            };
            let (samples, splats): (Vec<Vec<O>>, Vec<Vec<Splat<O>>>) =
                results.into_iter().take(whole * tiles.len()).flatten().unzip();
            if whole > 0 {
                if !tiles.is_empty() {
                    // Integer sums: the order in which samples and splats are added does not matter.
                    let faults = film.add_tiles_parallel(&tiles, &samples, &splats, TILE_SIZE);
                    stats.invalid_samples += faults.dropped as u64;
                    stats.clamped_samples += faults.clamped as u64;
                }
                for _ in 0..whole {
                    film.end_pass();
                }
                stats.passes += whole as u32;
                next += whole as u32;
                let progress = Progress {
                    passes_done: film.passes(),
                    passes_planned: planned,
                    passes_this_run: stats.passes,
                    elapsed: start.elapsed(),
                    samples_per_pass: film.width() as u64 * film.height() as u64,
                };
                on_pass(film, &progress);
            }
            if whole < k as usize {
                stats.interrupted = true;
                break;
            }
        }
        stats.elapsed = start.elapsed();
        stats
    }
}

/// A tile's samples (one per pixel, row-major) and the splats its light subpaths made.
type TileSamples<O> = (Vec<O>, Vec<Splat<O>>);

/// One sample for every pixel of `tile` in pass `pass`.
fn render_tile<E: Estimator, O: Contribution>(
    scene: &Scene,
    estimator: &E,
    width: u32,
    tile: &Tile,
    pass: u32,
) -> TileSamples<O> {
    let (seed, kind) = (scene.settings.seed, scene.settings.sampler);
    let pixels = width as u64 * scene.settings.height as u64;
    let mut out = Vec::with_capacity(tile.len());
    let mut splats = Vec::new();
    for y in tile.y0..tile.y1 {
        for x in tile.x0..tile.x1 {
            let pixel = y as u64 * width as u64 + x as u64;
            let mut sampler = Sampler::of_kind(kind, seed, pixel, pass as u64, pixels);
            let jitter = sampler.get_2d(Dim::FILM);
            let film_pos = Vec2::new(x as f32, y as f32) + jitter;
            out.push(estimator.sample(scene, film_pos, &mut sampler, &mut splats));
        }
    }
    (out, by_band(splats, TILE_SIZE))
}

/// `splats` ordered by band of `band_rows` pixel rows (`y / band_rows`), so that the film's
/// bands find theirs by binary search and add them in parallel. A counting sort: two passes
/// and a copy, about 60% of what a comparison sort by row cost (which was more than the
/// serial addition it replaced).
fn by_band<S: Copy>(splats: Vec<Splat<S>>, band_rows: u32) -> Vec<Splat<S>> {
    let band = |s: &Splat<S>| (s.y / band_rows) as usize;
    let bands = splats.iter().map(band).max().map_or(0, |b| b + 1);
    if splats.is_sorted_by_key(band) {
        return splats;
    }
    // next[b]: where the next splat of band b goes.
    let mut next = vec![0usize; bands];
    for s in &splats {
        next[band(s)] += 1;
    }
    let mut at = 0;
    for n in &mut next {
        (*n, at) = (at, at + *n);
    }
    let mut out = splats.clone();
    for s in &splats {
        let b = band(s);
        out[next[b]] = *s;
        next[b] += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batches_hold_enough_tasks_within_their_memory() {
        let xyz = std::mem::size_of::<Xyz>();
        let spec = std::mem::size_of::<Spectrum>();
        // 128²: 64 tiles, 16 passes (the cap) of 64 tasks.
        assert_eq!(passes_per_batch(64, 128 * 128, xyz), 16);
        // 256²: 256 tiles, 4 passes (3 MiB of XYZ samples, 40 MiB of spectral ones).
        assert_eq!(passes_per_batch(256, 256 * 256, xyz), 4);
        assert_eq!(passes_per_batch(256, 256 * 256, spec), 4);
        // 1024² spectral: 4096 tiles would be enough for one pass anyway; 768²
        // spectral (2304 tiles, 1 pass): the memory bound never drops below one pass.
        assert_eq!(passes_per_batch(4096, 1024 * 1024, spec), 1);
        // 128² with a spectral film: 16 passes would hold 40 MiB; the bound allows them.
        assert_eq!(passes_per_batch(64, 128 * 128, spec), 16);
        // Where the tasks alone would ask for more than fits: 256 tiles of a
        // (hypothetical) 1 KiB sample: 64 MiB hold 1 pass of 65536 samples, not 4.
        assert_eq!(passes_per_batch(256, 256 * 256, 1024), 1);
        // 2048²: 16384 tiles are enough tasks for one pass.
        assert_eq!(passes_per_batch(16384, 2048 * 2048, xyz), 1);
        // An image larger than the byte budget still renders a pass per batch.
        assert_eq!(passes_per_batch(65536, 4096 * 4096, spec), 1);
        assert_eq!(passes_per_batch(0, 0, xyz), 16);
    }

    #[test]
    fn tiles_cover_any_size_exactly_once() {
        for (w, h) in [(1, 1), (17, 5), (64, 64), (65, 33)] {
            let mut seen = vec![0; (w * h) as usize];
            for t in tiles(w, h, 16) {
                for y in t.y0..t.y1 {
                    for x in t.x0..t.x1 {
                        seen[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "{w}x{h}");
        }
    }

    /// The counting sort keeps every splat once (a permutation: the same multiset of values)
    /// and orders them by band, keeping the order within a band.
    #[test]
    fn splats_by_band_are_a_stable_permutation() {
        let splats: Vec<Splat<f32>> =
            (0..200u32).map(|i| Splat { x: i % 13, y: (i * 37) % 71, value: i as f32 }).collect();
        for rows in [1, 7, 16, 100] {
            let out = by_band(splats.clone(), rows);
            assert!(out.is_sorted_by_key(|s| s.y / rows), "{rows}");
            let mut want = splats.clone();
            want.sort_by_key(|s| s.y / rows); // a stable sort: the reference order
            let key = |v: &[Splat<f32>]| v.iter().map(|s| (s.x, s.y, s.value.to_bits())).collect::<Vec<_>>();
            assert_eq!(key(&out), key(&want), "{rows}");
        }
        assert!(by_band(Vec::<Splat<f32>>::new(), 16).is_empty());
    }
}
