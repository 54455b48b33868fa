//! Times a mesh file's load step by step on a pool of `--threads` threads: read the
//! file, inflate it (gzip), parse it, then place it and build its BVH
//! ([`Mesh::from_triangles`]: placing, dropping degenerate triangles and the wide
//! BVH), and the whole of [`rust_v::io::read_mesh_file`] (read, inflate and parse as
//! the renderer does them, overlapped where it can). `--rounds` rounds, medians.
//!
//! ```sh
//! cargo run --release --example load_steps -- [--mesh ../shared/meshes/dragon_vrip.ply.gz] \
//!     [--threads 2] [--rounds 5]
//! ```

use std::io::Read;
use std::path::PathBuf;
use std::time::Instant;

use rust_v::io::{parse_mesh, read_mesh_file};
use rust_v::shape::Mesh;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut mesh = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes/dragon_vrip.ply.gz");
    let (mut threads, mut rounds) = (2usize, 5usize);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--mesh" => mesh = PathBuf::from(args.next().expect("--mesh PATH")),
            "--threads" => threads = args.next().and_then(|s| s.parse().ok()).expect("--threads N"),
            "--rounds" => rounds = args.next().and_then(|s| s.parse().ok()).expect("--rounds N (N >= 1)"),
            other => panic!("unknown argument {other}"),
        }
    }
    if !mesh.exists() {
        println!("load_steps skipped: {} not found", mesh.display());
        return;
    }
    let gz = mesh.extension().is_some_and(|e| e == "gz");
    let plain = PathBuf::from(mesh.file_stem().expect("a file name"));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
    let names = ["read", "inflate", "parse", "place+bvh", "read_mesh_file"];
    let mut times = vec![Vec::new(); names.len()];
    for _ in 0..rounds {
        pool.install(|| {
            let t = Instant::now();
            let raw = std::fs::read(&mesh).expect("read");
            times[0].push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            let text = if gz {
                let mut out = Vec::with_capacity(raw.len() * 4);
                flate2::read::MultiGzDecoder::new(raw.as_slice()).read_to_end(&mut out).expect("gzip");
                out
            } else {
                raw
            };
            times[1].push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            let data = parse_mesh(text, if gz { &plain } else { &mesh }).expect("parse");
            times[2].push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            let m = Mesh::from_triangles(data.positions, data.triangles, data.normals).expect("mesh");
            times[3].push(t.elapsed().as_secs_f64());
            drop(m);
            let t = Instant::now();
            let data = read_mesh_file(&mesh).expect("read_mesh_file");
            times[4].push(t.elapsed().as_secs_f64());
            drop(data);
        });
    }
    println!("{} on {threads} thread(s), medians of {rounds} rounds:", mesh.display());
    for (name, t) in names.iter().zip(times) {
        println!("  {name:<16} {:>8.4} s", median(t));
    }
}
