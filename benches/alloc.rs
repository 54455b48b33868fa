//! Heap allocations while rendering, counted by a global allocator wrapper: shows that
//! a pass allocates per tile (one sample buffer each, plus rayon's bookkeeping), not
//! per ray or per sample. Renders `scenes/dragon.ron` (or the scenes given) with the
//! auto, path and spectral estimators at two image sizes and two pass counts, on 1 and 2
//! threads, and prints allocations per pass, per tile and pass, and per sample.
//!
//! `cargo bench --bench alloc [-- SCENE...]`

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use rust_v::film::Film;
use rust_v::render::{Limits, TILE_SIZE, render};
use rust_v::scene::load_scene;
use rust_v::settings::{IntegratorKind, SettingsPatch};

/// Counts calls to `alloc` and `realloc` (and bytes asked for), then defers to the system allocator.
struct Counting;

static ALLOCS: AtomicU64 = AtomicU64::new(0);
static BYTES: AtomicU64 = AtomicU64::new(0);

// SAFETY: every call is forwarded unchanged to `System`, which upholds the contract.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(layout.size() as u64, Ordering::Relaxed);
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(layout.size() as u64, Ordering::Relaxed);
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(new_size as u64, Ordering::Relaxed);
        // SAFETY: forwarded unchanged.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let scenes: Vec<String> = if args.is_empty() { vec!["scenes/dragon.ron".into()] } else { args };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    println!(
        "{:<20} {:>9} {:>7} {:>6} {:>7} {:>6} {:>10} {:>11} {:>10} {:>12} {:>12}",
        "scene",
        "estimator",
        "size",
        "passes",
        "threads",
        "tiles",
        "samples",
        "allocations",
        "per pass",
        "per tile-pass",
        "per sample"
    );
    for scene_path in &scenes {
        for integrator in [IntegratorKind::Auto, IntegratorKind::Path, IntegratorKind::Spectral] {
            for size in [64u32, 128] {
                let overrides = SettingsPatch {
                    width: Some(size),
                    height: Some(size),
                    integrator: Some(integrator),
                    ..Default::default()
                };
                let scene = match load_scene(&root.join(scene_path), &overrides) {
                    Ok(s) => s,
                    Err(e) => {
                        println!("{scene_path}: skipped ({e})");
                        continue;
                    }
                };
                for threads in [1usize, 2] {
                    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
                    for passes in [1u32, 4] {
                        let mut film = Film::new(size, size);
                        let stop = AtomicBool::new(false);
                        let limits = Limits { stop: &stop, time_budget: None };
                        // Warm up the pool's threads (their first jobs allocate thread-local state).
                        pool.install(|| rayon::join(|| (), || ()));
                        let before = ALLOCS.load(Ordering::SeqCst);
                        pool.install(|| render(&scene, &mut film, 0..passes, limits, &mut |_, _| {}));
                        let n = ALLOCS.load(Ordering::SeqCst) - before;
                        let tiles = (size.div_ceil(TILE_SIZE) * size.div_ceil(TILE_SIZE)) as u64;
                        let samples = size as u64 * size as u64 * passes as u64;
                        println!(
                            "{:<20} {:>9} {:>7} {:>6} {:>7} {:>6} {:>10} {:>11} {:>10.1} {:>12.2} {:>12.5}",
                            scene_path,
                            format!("{integrator:?}").to_lowercase(),
                            format!("{size}x{size}"),
                            passes,
                            threads,
                            tiles,
                            samples,
                            n,
                            n as f64 / passes as f64,
                            n as f64 / (tiles * passes as u64) as f64,
                            n as f64 / samples as f64
                        );
                    }
                }
            }
        }
    }
}
