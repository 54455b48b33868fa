//! Render throughput: samples per second on the committed scenes at 128x128,
//! on 1 and 2 threads, and the scaling ratio, for the full-spectrum
//! integrators (`path`, `auto` collapsing to 4 or 8), hero packets of 4
//! and 8 wavelengths, and the bidirectional ones (`bdpt`, `lighttrace`, whose
//! splats the film adds in parallel bands).
//!
//! Each method runs 5 rounds of one 1-thread and one 2-thread render of 32
//! passes, alternating, so that both see the same machine load; the table
//! gives the median rate of each and the median of the 5 per-round ratios
//! (on a shared machine a ratio of medians taken minutes apart mixes in
//! the load's drift).
//!
//! `cargo bench --bench render [-- SCENE...]`

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use rust_v::film::Film;
use rust_v::render::{Limits, render};
use rust_v::scene::load_scene;
use rust_v::settings::{IntegratorKind, SettingsPatch};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let scenes: Vec<String> = if args.is_empty() {
        ["scenes/cornell.ron", "scenes/cornell-lambert.ron", "scenes/spheres.ron", "scenes/dragon.ron"]
            .map(String::from)
            .to_vec()
    } else {
        args
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    println!(
        "{:<28} {:>10} {:>8} {:>14} {:>14} {:>8}",
        "scene", "integrator", "passes", "1 thread Ms/s", "2 threads Ms/s", "ratio"
    );
    for scene_path in scenes {
        let methods = [
            ("path", IntegratorKind::Path, 4),
            ("auto", IntegratorKind::Auto, 4),
            ("auto-8", IntegratorKind::Auto, 8),
            ("hero-4", IntegratorKind::Spectral, 4),
            ("hero-8", IntegratorKind::Spectral, 8),
            ("bdpt", IntegratorKind::Bdpt, 4),
            ("lighttrace", IntegratorKind::LightTrace, 4),
            ("whitted", IntegratorKind::Whitted, 4),
        ];
        for (name, integrator, packet) in methods {
            let overrides = SettingsPatch {
                width: Some(128),
                height: Some(128),
                integrator: Some(integrator),
                packet_size: Some(packet),
                ..Default::default()
            };
            let scene = match load_scene(&root.join(&scene_path), &overrides) {
                Ok(s) => s,
                Err(e) => {
                    println!("{scene_path}: skipped ({e})");
                    break;
                }
            };
            let passes = 32;
            let pools: Vec<rayon::ThreadPool> =
                [1, 2].map(|t| rayon::ThreadPoolBuilder::new().num_threads(t).build().expect("thread pool")).into();
            let rate = |pool: &rayon::ThreadPool| {
                let mut film = Film::new(128, 128);
                let stop = AtomicBool::new(false);
                let t = Instant::now();
                pool.install(|| {
                    render(&scene, &mut film, 0..passes, Limits { stop: &stop, time_budget: None }, &mut |_, _| {})
                });
                (passes as f64 * 128.0 * 128.0) / t.elapsed().as_secs_f64() / 1e6
            };
            let rounds: Vec<(f64, f64)> = (0..5).map(|_| (rate(&pools[0]), rate(&pools[1]))).collect();
            let one = median(rounds.iter().map(|r| r.0).collect());
            let two = median(rounds.iter().map(|r| r.1).collect());
            let ratio = median(rounds.iter().map(|r| r.1 / r.0).collect());
            println!("{:<28} {:>10} {:>8} {:>14.3} {:>14.3} {:>8.2}", scene_path, name, passes, one, two, ratio);
        }
    }
}
