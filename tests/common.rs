//! Helpers shared by the integration tests.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::AtomicBool;

use rust_v::film::Film;
use rust_v::render::{Limits, render};
use rust_v::scene::load_scene_str;
use rust_v::settings::{IntegratorKind, SettingsPatch};

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `../shared` beside the repository, if present.
pub fn shared(rel: &str) -> Option<PathBuf> {
    let p = root().join("../shared").join(rel);
    p.exists().then_some(p)
}

/// Renders a scene given as RON text with overrides; returns the film.
pub fn render_str(ron: &str, overrides: &SettingsPatch) -> Film {
    render_film(ron, overrides, false)
}

/// As [`render_str`] on a spectral film (`--spectral`): the film also sums the 36 bins, and
/// single-wavelength paths stay at the bin centres.
pub fn render_str_bins(ron: &str, overrides: &SettingsPatch) -> Film {
    render_film(ron, overrides, true)
}

/// Renders the scene file at `path` (its textures, maps and grids beside it) with
/// overrides; returns the film. Asserts that no sample was NaN or infinite.
pub fn render_file(path: &Path, overrides: &SettingsPatch) -> Film {
    let scene = rust_v::scene::load_scene(path, overrides).expect("test scene loads");
    render_scene(&scene, false)
}

fn render_film(ron: &str, overrides: &SettingsPatch, bins: bool) -> Film {
    let scene = load_scene_str(ron, Path::new("test.ron"), overrides).expect("test scene loads");
    render_scene(&scene, bins)
}

fn render_scene(scene: &rust_v::scene::Scene, bins: bool) -> Film {
    let s = &scene.settings;
    let mut film = if bins { Film::new_spectral(s.width, s.height, 0) } else { Film::new(s.width, s.height) };
    let stop = AtomicBool::new(false);
    let stats = render(scene, &mut film, 0..s.spp, Limits { stop: &stop, time_budget: None }, &mut |_, _| {});
    assert_eq!(stats.invalid_samples, 0, "NaN or infinite samples");
    film
}

/// Mean and standard error of the per-pixel means of channel `c` (0 = X, 1 = Y, 2 = Z).
pub fn mean_and_stderr(film: &Film, c: usize) -> (f64, f64) {
    let v: Vec<f64> = film.mean_xyz().iter().map(|p| p[c]).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Runs the rust-v binary.
pub fn rust_v(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rust-v")).args(args).current_dir(root()).output().expect("binary runs")
}

/// A fresh temporary directory for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rust-v-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// Polls `cond` every 20 ms until it holds or `timeout` passes; returns whether it held.
pub fn wait_for(timeout: std::time::Duration, mut cond: impl FnMut() -> bool) -> bool {
    let start = std::time::Instant::now();
    loop {
        if cond() {
            return true;
        }
        if start.elapsed() > timeout {
            return false;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Per-block means of Y (blocks of `b`×`b` pixels) of a film.
pub fn block_means(film: &Film, b: usize) -> Vec<f64> {
    let (w, h) = (film.width() as usize, film.height() as usize);
    let xyz = film.mean_xyz();
    let mut out = vec![0.0; (w / b) * (h / b)];
    for y in 0..h {
        for x in 0..w {
            out[(y / b) * (w / b) + x / b] += xyz[y * w + x][1] / (b * b) as f64;
        }
    }
    out
}

/// For each pixel of an `n` x `n` render of `scene` (row by row), the checkerboard square
/// `(⌊scale u⌋, ⌊scale v⌋)` of object 0 that the whole pixel lies within (all four corners'
/// rays hit object 0 in that square), or `None` at a square's edge or off the object.
pub fn pixel_squares(scene: &rust_v::scene::Scene, n: u32, scale: f32) -> Vec<Option<(i64, i64)>> {
    let square = |x: u32, y: u32| {
        let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(dx, dy)| {
            let ray = scene.camera.ray(glam::Vec2::new(x as f32 + dx, y as f32 + dy));
            let si = scene.intersect(&ray, f32::INFINITY).filter(|s| s.object == 0)?;
            let uv = scene.uv(&si) * scale;
            Some((uv.x.floor() as i64, uv.y.floor() as i64))
        });
        let first = corners[0]?;
        corners.iter().all(|c| *c == Some(first)).then_some(first)
    };
    (0..n * n).map(|k| square(k % n, k / n)).collect()
}

/// Settings for a `size`² render with `integrator`, `spp` and `seed`.
pub fn square_settings(integrator: IntegratorKind, size: u32, spp: u32, seed: u64) -> SettingsPatch {
    SettingsPatch {
        integrator: Some(integrator),
        width: Some(size),
        height: Some(size),
        spp: Some(spp),
        seed: Some(seed),
        ..Default::default()
    }
}

/// Renders `passes` of `scene` into `film`, asserting no NaN or infinite sample.
pub fn render_into(scene: &rust_v::scene::Scene, film: &mut Film, passes: std::ops::Range<u32>) {
    let stop = AtomicBool::new(false);
    let stats = render(scene, film, passes, Limits { stop: &stop, time_budget: None }, &mut |_, _| {});
    assert_eq!(stats.invalid_samples, 0, "NaN or infinite samples");
}

/// Mean and standard error, per 4x4 block, over renders with different seeds;
/// and of the image sum (the sum of a render's block means), whose standard
/// error comes from the seeds too (blocks of one render can be correlated:
/// a light subpath splats into several).
pub fn seeded_blocks(
    text: &str,
    integrator: IntegratorKind,
    size: u32,
    spp: u32,
    seeds: u64,
) -> (Vec<(f64, f64)>, (f64, f64)) {
    let runs: Vec<Vec<f64>> = (0..seeds)
        .map(|s| block_means(&render_str(text, &square_settings(integrator, size, spp, 100 + s)), 4))
        .collect();
    seed_stats(&runs)
}

/// Renders passes `0..passes` of `scene` on a `size`² film on 1 and on 2 threads, and as
/// the merge of `0..passes/2` and `passes/2..passes`; asserts the three films are the same
/// (bit for bit: `what` names the case) and returns it.
pub fn assert_threads_and_merge_exact(scene: &rust_v::scene::Scene, size: u32, passes: u32, what: &str) -> Film {
    let whole = |threads: usize| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            let mut f = Film::new(size, size);
            render_into(scene, &mut f, 0..passes);
            f
        })
    };
    let (whole1, whole2) = (whole(1), whole(2));
    assert_eq!(whole1, whole2, "{what}: 1 vs 2 threads");
    let half = passes / 2;
    let mut a = Film::new(size, size);
    render_into(scene, &mut a, 0..half);
    let mut b = Film::starting_at(size, size, half);
    render_into(scene, &mut b, half..passes);
    a.merge(&b).unwrap();
    assert_eq!(a, whole1, "{what}: merged halves");
    whole1
}

/// Mean and standard error over the runs (one vector of block means per seed) of
/// each block, and of each run's sum over its blocks.
pub fn seed_stats(runs: &[Vec<f64>]) -> (Vec<(f64, f64)>, (f64, f64)) {
    let n = runs.len() as f64;
    let stats = |v: &dyn Fn(&Vec<f64>) -> f64| {
        let m = runs.iter().map(v).sum::<f64>() / n;
        let var = runs.iter().map(|r| (v(r) - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m, (var / n).sqrt())
    };
    let blocks = (0..runs[0].len()).map(|k| stats(&|r| r[k])).collect();
    (blocks, stats(&|r| r.iter().sum()))
}
