//! Times the mesh BVH's build on its own: reads a mesh once, then builds its 8-wide BVH
//! (or, with `--binary`, a whole binary `Bvh` over the triangles' boxes) `--builds`
//! times in one process on a pool of `--threads` threads, and prints the median and every
//! time. The first build's fingerprint (node and block counts, the SAH cost's bits, a
//! hash of the slot order) shows whether two versions of the crate build the same tree,
//! and the process's huge pages (`AnonHugePages` of `/proc/self/smaps_rollup`) whether
//! the tree got them. Under valgrind, `--builds 1` counts one build.
//!
//! ```sh
//! cargo run --release --example bvh_build -- [--mesh ../shared/meshes/dragon_vrip.ply.gz] \
//!     [--builds 5] [--threads 2] [--binary]
//! ```

use rust_v::geometry::Aabb;
use rust_v::io::Fnv1a;
use rust_v::shape::{Bvh, Mesh, WideBvh};
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let mut mesh = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes/dragon_vrip.ply.gz");
    let (mut builds, mut threads, mut binary) = (5usize, 1usize, false);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--mesh" => mesh = PathBuf::from(args.next().expect("--mesh PATH")),
            "--builds" => builds = args.next().and_then(|s| s.parse().ok()).expect("--builds N (N >= 1)"),
            "--threads" => threads = args.next().and_then(|s| s.parse().ok()).expect("--threads N"),
            "--binary" => binary = true,
            other => panic!("unknown argument {other}"),
        }
    }
    assert!(builds >= 1, "--builds N needs N >= 1");
    if !mesh.exists() {
        println!("bvh_build skipped: {} not found", mesh.display());
        return;
    }
    let (positions, indices) = Mesh::read_arrays(&mesh).unwrap_or_else(|e| panic!("{e}"));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
    let boxes: Vec<Aabb> = if binary {
        indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                Aabb::new(a, b).grow(c)
            })
            .collect()
    } else {
        Vec::new()
    };
    // FNV-1a (the crate's one hash) of the slot order as little-endian u32s.
    let fnv = |order: &[u32]| {
        let mut h = Fnv1a::default();
        order.iter().for_each(|k| h.write(&k.to_le_bytes()));
        h.finish()
    };
    // The process's huge pages while the first tree is alive.
    let huge = || {
        std::fs::read_to_string("/proc/self/smaps_rollup")
            .ok()
            .and_then(|s| s.lines().find(|l| l.starts_with("AnonHugePages")).map(|l| l[14..].trim().to_string()))
            .unwrap_or_else(|| "?".into())
    };
    let mut times = Vec::with_capacity(builds);
    for k in 0..builds {
        let t = Instant::now();
        let fingerprint = if binary {
            let b = pool.install(|| Bvh::build(&boxes));
            times.push(t.elapsed().as_secs_f64());
            let f = format!(
                "nodes {} sah {:08x} order {:016x}",
                b.node_count(),
                b.sah_cost().to_bits(),
                fnv(b.prim_order())
            );
            (k == 0).then(|| format!("{f}; huge pages {}", huge()))
        } else {
            let w = pool.install(|| WideBvh::build_indexed(&positions, &indices));
            times.push(t.elapsed().as_secs_f64());
            (k == 0).then(|| {
                format!(
                    "nodes {} blocks {} sah {:08x} order {:016x}; huge pages {}",
                    w.node_count(),
                    w.block_count(),
                    w.sah_cost().to_bits(),
                    fnv(w.prim_order()),
                    huge()
                )
            })
        };
        if let Some(f) = fingerprint {
            println!("{} ({} triangles): {f}", mesh.display(), indices.len());
        }
    }
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let all: Vec<String> = times.iter().map(|t| format!("{t:.4}")).collect();
    println!(
        "{} build, {threads} thread(s): median {:.4} s over {builds} (in order: {})",
        if binary { "binary" } else { "wide" },
        sorted[builds / 2],
        all.join(" ")
    );
}
