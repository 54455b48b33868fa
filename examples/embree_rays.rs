//! Traces the Embree peer harness's ray files (`shared/peers/embree`) with rust-v's mesh
//! BVH and writes hits in the harness's format, so that `check_hits.py compare` can
//! check them against Embree's and the speeds can be put side by side.
//!
//! ```sh
//! cargo run --release --example embree_rays -- \
//!     [--mesh ../shared/meshes/dragon_vrip.ply.gz] [--data ~/.cache/peers/embree-data] \
//!     [--kinds primary incoherent] [--passes 5] [--rounds 1] [--no-hits] [--limit N]
//! ```
//!
//! For each kind it reads `DATA/rays/STEM.KIND.rays` (N x 6 little-endian f32: origin,
//! unit direction), checks the sidecar's `geometry_sha256` against the sha256 of the
//! mesh as rust-v reads it (f32 LE vertices, then u32 LE triangle indices, file order,
//! degenerate triangles included), traces every ray once untimed (the warm-up; its
//! result is the hit file), then `--passes` timed passes on this thread: closest hit,
//! `t` in (0, inf). Reports N / median wall time and N / median thread CPU time (from
//! `/proc/thread-self/schedstat`, which shows whether the thread was descheduled).
//! `--limit N` traces only the first N rays (e.g. under valgrind).
//! Hits go to `DATA/hits/STEM.KIND.rust-v.hits`: per ray f32 t and i32 PLY face index
//! (`Mesh::face_index`), `inf` and -1 for a miss.

use glam::Vec3;
use rust_v::geometry::Ray;
use rust_v::shape::{Mesh, Transform};
use std::path::{Path, PathBuf};
use std::time::Instant;

fn main() {
    let mut mesh_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes/dragon_vrip.ply.gz");
    let mut data = std::env::var_os("EMBREE_DATA").map(PathBuf::from).unwrap_or_else(|| {
        let peers = std::env::var_os("PEERS_DIR").map(PathBuf::from).unwrap_or_else(|| {
            PathBuf::from(std::env::var_os("HOME").expect("HOME or EMBREE_DATA must be set")).join(".cache/peers")
        });
        peers.join("embree-data")
    });
    let mut kinds = vec!["primary".to_string(), "incoherent".to_string()];
    let (mut passes, mut rounds, mut write_hits, mut limit) = (5usize, 1usize, true, usize::MAX);
    let mut args = std::env::args().skip(1).peekable();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--mesh" => mesh_path = PathBuf::from(args.next().expect("--mesh PATH")),
            "--data" => data = PathBuf::from(args.next().expect("--data DIR")),
            "--passes" => passes = args.next().and_then(|s| s.parse().ok()).expect("--passes N"),
            "--rounds" => rounds = args.next().and_then(|s| s.parse().ok()).expect("--rounds N"),
            "--no-hits" => write_hits = false,
            "--limit" => limit = args.next().and_then(|s| s.parse().ok()).expect("--limit N"),
            "--kinds" => {
                kinds.clear();
                while let Some(k) = args.next_if(|s| !s.starts_with("--")) {
                    kinds.push(k);
                }
            }
            "--bench" => {} // passed by `cargo bench`
            other => panic!("unknown argument {other}"),
        }
    }
    let name = mesh_path.file_name().unwrap().to_string_lossy().to_string();
    let stem = name.split('.').next().unwrap().to_string();

    let (positions, indices) = Mesh::read_arrays(&mesh_path).unwrap_or_else(|e| panic!("{e}"));
    let mut bytes = Vec::with_capacity(positions.len() * 12 + indices.len() * 12);
    positions.iter().flat_map(|p| p.to_array()).for_each(|x| bytes.extend_from_slice(&x.to_le_bytes()));
    indices.iter().flatten().for_each(|i| bytes.extend_from_slice(&i.to_le_bytes()));
    let hash = hex(&sha256(&bytes));
    drop((positions, indices, bytes));

    let t = Instant::now();
    let mesh = Mesh::load(&mesh_path, &Transform::default()).unwrap_or_else(|e| panic!("{e}"));
    let load = t.elapsed().as_secs_f64();
    let n = mesh.triangle_count();
    let bvh = mesh.bvh();
    println!(
        "{name}: {n} triangles + {} degenerate dropped; load+build {load:.2} s; {:.1} B/tri BVH; SAH {:.2}; \
         {} nodes, {} blocks ({:.1}% of lanes used)",
        mesh.degenerate_dropped(),
        bvh.memory_bytes() as f64 / n as f64,
        bvh.sah_cost(),
        bvh.node_count(),
        bvh.block_count(),
        100.0 * n as f64 / (4 * bvh.block_count()) as f64
    );
    println!("geometry_sha256 {hash}");
    // The BVH asks for huge pages (src/shape/bvh/hint.rs); say how many the process has.
    if let Some(kb) = std::fs::read_to_string("/proc/self/smaps_rollup")
        .ok()
        .and_then(|s| s.lines().find_map(|l| l.strip_prefix("AnonHugePages:").map(|v| v.trim().to_string())))
    {
        println!(
            "huge pages: {kb} in the process; BVH nodes + blocks {:.1} MB",
            (bvh.memory_bytes() + bvh.triangle_bytes()) as f64 * 1e-6
        );
    }

    for kind in &kinds {
        let rays_path = data.join(format!("rays/{stem}.{kind}.rays"));
        let raw =
            std::fs::read(&rays_path).unwrap_or_else(|e| panic!("{}: {e} (run make_rays.py)", rays_path.display()));
        if let Ok(side) = std::fs::read_to_string(rays_path.with_extension("rays.json")) {
            match json_str(&side, "geometry_sha256") {
                Some(h) if h == hash => {}
                Some(h) => panic!("{kind}: sidecar geometry_sha256 {h} differs from the mesh's {hash}"),
                None => eprintln!("{kind}: sidecar has no geometry_sha256"),
            }
        }
        let f: Vec<f32> = raw.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        let rays: Vec<Ray> = f
            .chunks_exact(6)
            .map(|r| Ray::new(Vec3::new(r[0], r[1], r[2]), Vec3::new(r[3], r[4], r[5])))
            .take(limit)
            .collect();
        let nr = rays.len();

        // Warm-up pass: its hits are the hit file.
        let mut hits: Vec<(f32, i32)> = vec![(f32::INFINITY, -1); nr];
        for (r, out) in rays.iter().zip(hits.iter_mut()) {
            if let Some(h) = mesh.intersect(r, f32::INFINITY) {
                *out = (h.t, mesh.face_index(h.prim) as i32);
            }
        }
        let hit_frac = hits.iter().filter(|h| h.1 >= 0).count() as f64 / nr as f64;
        let (mut wall, mut cpu) = (Vec::new(), Vec::new());
        for _ in 0..passes * rounds {
            let c0 = thread_cpu_ns();
            let t0 = Instant::now();
            let mut count = 0u32;
            for r in &rays {
                if let Some(h) = mesh.intersect(r, f32::INFINITY) {
                    count += 1;
                    std::hint::black_box(h);
                }
            }
            wall.push(t0.elapsed().as_secs_f64());
            cpu.push((thread_cpu_ns() - c0) as f64 * 1e-9);
            std::hint::black_box(count);
        }
        let (mw, mc) = (median(&mut wall), median(&mut cpu));
        println!(
            "{kind:<10}: {nr} rays, {:.2} Mrays/s median wall (range {:.2}-{:.2}, {} passes), {:.2} Mrays per \
             CPU-second, hit fraction {hit_frac:.4}",
            nr as f64 / mw * 1e-6,
            nr as f64 / wall[wall.len() - 1] * 1e-6,
            nr as f64 / wall[0] * 1e-6,
            wall.len(),
            nr as f64 / mc * 1e-6,
        );
        if write_hits {
            let out = data.join(format!("hits/{stem}.{kind}.rust-v.hits"));
            std::fs::create_dir_all(out.parent().unwrap()).expect("hits folder");
            let mut b = Vec::with_capacity(nr * 8);
            for (t, p) in &hits {
                b.extend_from_slice(&t.to_le_bytes());
                b.extend_from_slice(&p.to_le_bytes());
            }
            std::fs::write(&out, b).unwrap_or_else(|e| panic!("{}: {e}", out.display()));
            println!("            hits: {}", out.display());
        }
    }
}

/// Sorts and returns the median.
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// CPU time of the calling thread in ns (first field of `/proc/thread-self/schedstat`).
fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(0)
}

/// The string value of `"key": "value"` in a JSON text (enough for the sidecars).
fn json_str<'a>(json: &'a str, key: &str) -> Option<&'a str> {
    let rest = &json[json.find(&format!("\"{key}\""))? + key.len() + 2..];
    let rest = &rest[rest.find('"')? + 1..];
    Some(&rest[..rest.find('"')?])
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// SHA-256 (FIPS 180-4), to compare geometry with the harness without a dependency.
fn sha256(msg: &[u8]) -> [u8; 32] {
    const K: [u32; 64] = [
        0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5, 0xd807aa98,
        0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786,
        0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8,
        0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13,
        0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819,
        0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a,
        0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
        0xc67178f2,
    ];
    let mut h: [u32; 8] =
        [0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19];
    let mut data = msg.to_vec();
    data.push(0x80);
    while data.len() % 64 != 56 {
        data.push(0);
    }
    data.extend_from_slice(&((msg.len() as u64) * 8).to_be_bytes());
    for block in data.chunks_exact(64) {
        let mut w = [0u32; 64];
        for i in 0..16 {
            w[i] = u32::from_be_bytes([block[4 * i], block[4 * i + 1], block[4 * i + 2], block[4 * i + 3]]);
        }
        for i in 16..64 {
            let s0 = w[i - 15].rotate_right(7) ^ w[i - 15].rotate_right(18) ^ (w[i - 15] >> 3);
            let s1 = w[i - 2].rotate_right(17) ^ w[i - 2].rotate_right(19) ^ (w[i - 2] >> 10);
            w[i] = w[i - 16].wrapping_add(s0).wrapping_add(w[i - 7]).wrapping_add(s1);
        }
        let [mut a, mut b, mut c, mut d, mut e, mut f, mut g, mut hh] = h;
        for i in 0..64 {
            let s1 = e.rotate_right(6) ^ e.rotate_right(11) ^ e.rotate_right(25);
            let ch = (e & f) ^ (!e & g);
            let t1 = hh.wrapping_add(s1).wrapping_add(ch).wrapping_add(K[i]).wrapping_add(w[i]);
            let s0 = a.rotate_right(2) ^ a.rotate_right(13) ^ a.rotate_right(22);
            let maj = (a & b) ^ (a & c) ^ (b & c);
            let t2 = s0.wrapping_add(maj);
            hh = g;
            g = f;
            f = e;
            e = d.wrapping_add(t1);
            d = c;
            c = b;
            b = a;
            a = t1.wrapping_add(t2);
        }
        for (x, y) in h.iter_mut().zip([a, b, c, d, e, f, g, hh]) {
            *x = x.wrapping_add(y);
        }
    }
    let mut out = [0u8; 32];
    for (i, x) in h.iter().enumerate() {
        out[4 * i..4 * i + 4].copy_from_slice(&x.to_be_bytes());
    }
    out
}
