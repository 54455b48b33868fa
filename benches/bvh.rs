//! BVH benchmark on the full Stanford dragon (871,414 triangles): load time, build
//! time of the mesh's 8-wide BVH (and of a whole binary `Bvh` over the same boxes, which
//! splits down to single triangles where the wide build stops at 12) on 1 and
//! 2 threads, memory per triangle, SAH cost, and single-thread closest-hit throughput
//! for coherent primary rays and incoherent random rays.
//! Run with `cargo bench --bench bvh`; skips (exit 0) if the mesh is absent.

use glam::Vec3;
use rand::Rng;
use rand_pcg::Pcg32;
use rust_v::geometry::{Aabb, Ray};
use rust_v::shape::{Bvh, Mesh, Transform, WideBvh};
use std::path::Path;
use std::time::{Duration, Instant};

/// Median of a few timings.
fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// Uniform f32 in [0, 1).
fn uniform(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Median wall time of 5 runs of `build` inside a pool of `threads` threads.
fn build_time<T: Send>(threads: usize, build: impl Fn() -> T + Sync) -> Duration {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
    let mut times = Vec::new();
    for _ in 0..5 {
        let t = Instant::now();
        std::hint::black_box(pool.install(&build));
        times.push(t.elapsed());
    }
    median(times)
}

/// Traces all rays on the current thread; returns (median rays/s of 3 runs, hit fraction).
fn trace(mesh: &Mesh, rays: &[Ray]) -> (f64, f64) {
    let mut times = Vec::new();
    let mut hits = 0usize;
    for _ in 0..3 {
        hits = 0;
        let t = Instant::now();
        for r in rays {
            if let Some(h) = mesh.intersect(r, f32::INFINITY) {
                hits += 1;
                std::hint::black_box(h);
            }
        }
        times.push(t.elapsed());
    }
    (rays.len() as f64 / median(times).as_secs_f64(), hits as f64 / rays.len() as f64)
}

fn main() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes/dragon_vrip.ply.gz");
    if !path.exists() {
        println!("bvh bench skipped: {} not found (shared/ is expected beside the repository)", path.display());
        return;
    }
    let t = Instant::now();
    let mesh = match Mesh::load(&path, &Transform::default()) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let load = t.elapsed();
    let n = mesh.triangle_count();
    let tris: Vec<[Vec3; 3]> = (0..n as u32).map(|k| mesh.triangle(k)).collect();
    let bounds: Vec<Aabb> = tris.iter().map(|[a, b, c]| Aabb::new(*a, *b).grow(*c)).collect();
    let build1 = build_time(1, || WideBvh::build(&tris));
    let build2 = build_time(2, || WideBvh::build(&tris));
    let binary1 = build_time(1, || Bvh::build(&bounds));
    let binary2 = build_time(2, || Bvh::build(&bounds));
    let mb = mesh.bvh();

    // (a) Primary rays: a 512x512 pinhole camera in front of the bounding box.
    let b = mesh.bounds();
    let (c, d) = (b.centroid(), b.diagonal());
    let dist = 2.0 * d.length();
    let eye = c + Vec3::new(0.0, 0.0, dist);
    let half = 0.55 * d.x.max(d.y) / (dist - 0.5 * d.z);
    let res = 512;
    let primary: Vec<Ray> = (0..res * res)
        .map(|i| {
            let (x, y) = ((i % res) as f32 + 0.5, (i / res) as f32 + 0.5);
            let dir = Vec3::new((2.0 * x / res as f32 - 1.0) * half, (1.0 - 2.0 * y / res as f32) * half, -1.0);
            Ray::new(eye, dir.normalize())
        })
        .collect();
    // (b) Incoherent rays: random origins inside the bounds, random directions.
    let mut rng = Pcg32::new(7, 1);
    let incoherent: Vec<Ray> = (0..res * res)
        .map(|_| {
            let o = b.min + d * Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng));
            let z = 1.0 - 2.0 * uniform(&mut rng);
            let phi = std::f32::consts::TAU * uniform(&mut rng);
            let s = (1.0 - z * z).max(0.0).sqrt();
            Ray::new(o, Vec3::new(s * phi.cos(), s * phi.sin(), z))
        })
        .collect();
    let (prim_rate, prim_hits) = trace(&mesh, &primary);
    let (inc_rate, inc_hits) = trace(&mesh, &incoherent);

    println!("BVH benchmark: {} ({n} triangles, {} degenerate dropped)", path.display(), mesh.degenerate_dropped());
    println!("| measure                          | value        |");
    println!("|----------------------------------|--------------|");
    println!("| load (gunzip + parse + BVH)      | {:>9.3} s  |", load.as_secs_f64());
    println!("| BVH build, 1 thread (median/5)   | {:>9.3} s  |", build1.as_secs_f64());
    println!("| BVH build, 2 threads (median/5)  | {:>9.3} s  |", build2.as_secs_f64());
    println!("| whole binary Bvh, 1 / 2 threads | {:.3} / {:.3} s |", binary1.as_secs_f64(), binary2.as_secs_f64());
    println!("| 8-wide nodes (256 B)             | {:>12} |", mb.node_count());
    println!(
        "| 4-triangle blocks (144 B)        | {:>12} | ({:.0}% of lanes used)",
        mb.block_count(),
        25.0 * n as f64 / mb.block_count() as f64
    );
    println!("| nodes + index bytes / triangle   | {:>12.1} |", mb.memory_bytes() as f64 / n as f64);
    println!("| vertex bytes / triangle (blocks) | {:>12.1} |", mb.triangle_bytes() as f64 / n as f64);
    println!("| SAH cost (node 1, block 1)       | {:>12.2} |", mb.sah_cost());
    println!("| primary rays/s, 1 thread         | {:>10.2} M | ({:.0}% hit)", prim_rate / 1e6, prim_hits * 100.0);
    println!("| incoherent rays/s, 1 thread      | {:>10.2} M | ({:.0}% hit)", inc_rate / 1e6, inc_hits * 100.0);
}
