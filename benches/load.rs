//! Scene loading: a scene of many mesh files (200 copies of `meshes/dragon_vrip_res3.ply.gz`,
//! 47k triangles each, written to a temporary folder) and, where `../shared/meshes/` has it,
//! the full 871k-triangle dragon: load time (read, inflate, parse, BVH build) on 1 and
//! 2 threads, 5 interleaved rounds, medians and the median of the per-round ratios.
//! Mesh files are read, parsed and built in parallel (`Mesh::read_ahead`), so the
//! many-files scene scales with threads; one big file scales only as far as its BVH
//! build does.
//!
//! `cargo bench --bench load [-- COPIES]`

use std::path::{Path, PathBuf};
use std::time::Instant;

use rust_v::scene::load_scene;
use rust_v::settings::SettingsPatch;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A scene of `copies` copies of the small dragon in a temporary folder.
fn many_meshes(root: &Path, copies: usize) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rust-v-bench-load-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let mesh = std::fs::read(root.join("meshes/dragon_vrip_res3.ply.gz")).expect("meshes/dragon_vrip_res3.ply.gz");
    let mut objects = Vec::new();
    for i in 0..copies {
        std::fs::write(dir.join(format!("d{i}.ply.gz")), &mesh).expect("write mesh");
        let (x, z) = ((i % 20) as f32 * 0.3 - 3.0, (i / 20) as f32 * 0.3 - 3.0);
        objects.push(format!(r#"(shape: Mesh(path: "d{i}.ply.gz", translate: ({x}, 0, {z})), material: "white")"#));
    }
    let scene = format!(
        r#"(
    camera: (eye: (0, 2, 6), look_at: (0, 0, 0), fov_deg: 50),
    materials: {{ "white": Lambertian(reflectance: Constant(0.5)) }},
    objects: [ {} ],
    lights: [ Point(position: (0, 5, 0), intensity: Constant(10)) ],
)"#,
        objects.join(",\n")
    );
    let path = dir.join("many.ron");
    std::fs::write(&path, scene).expect("write scene");
    path
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let copies: usize =
        std::env::args().skip(1).find(|a| !a.starts_with("--")).and_then(|a| a.parse().ok()).unwrap_or(200);
    let many = many_meshes(root, copies);
    let mut scenes = vec![(format!("{copies} small dragons"), many.clone())];
    let full = root.join("scenes/full/dragon-full.ron");
    if root.join("../shared/meshes/dragon_vrip.ply.gz").exists() {
        scenes.push(("full dragon".into(), full));
    } else {
        println!("full dragon: skipped (../shared/meshes/dragon_vrip.ply.gz absent)");
    }
    let pools: Vec<rayon::ThreadPool> =
        [1, 2].map(|t| rayon::ThreadPoolBuilder::new().num_threads(t).build().expect("thread pool")).into();
    println!("{:<24} {:>12} {:>12} {:>8}", "scene", "1 thread s", "2 threads s", "ratio");
    for (name, path) in &scenes {
        let time = |pool: &rayon::ThreadPool| {
            let t = Instant::now();
            pool.install(|| load_scene(path, &SettingsPatch::default()).expect("scene loads"));
            t.elapsed().as_secs_f64()
        };
        let rounds: Vec<(f64, f64)> = (0..5).map(|_| (time(&pools[0]), time(&pools[1]))).collect();
        let one = median(rounds.iter().map(|r| r.0).collect());
        let two = median(rounds.iter().map(|r| r.1).collect());
        let ratio = median(rounds.iter().map(|r| r.0 / r.1).collect());
        println!("{name:<24} {one:>12.3} {two:>12.3} {ratio:>8.2}");
    }
    let _ = std::fs::remove_dir_all(many.parent().expect("temp dir"));
}
