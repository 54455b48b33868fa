//! Tests of [`super::Mesh`]: loading, placing, degenerate triangles, errors.

use super::*;
use crate::shape::Triangle;
use crate::shape::sphere::tests::{random_dir, uniform};
use rand_pcg::Pcg32;
use std::path::PathBuf;

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rust-v-mesh-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Triangles in file order, as vertex positions.
fn tris_in_file_order(m: &Mesh) -> Vec<[Vec3; 3]> {
    let mut v: Vec<(u32, [Vec3; 3])> =
        (0..m.triangle_count() as u32).map(|k| (m.original_index(k), m.triangle(k))).collect();
    v.sort_by_key(|x| x.0);
    v.into_iter().map(|x| x.1).collect()
}

const VERTS: [[f32; 3]; 5] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 1.0]];

fn ascii_ply(faces: &str, n_faces: usize) -> String {
    let mut s = String::from(
        "ply\nformat ascii 1.0\ncomment test\nelement vertex 5\nproperty float x\nproperty float y\n\
         property float z\nproperty float confidence\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n",
    );
    s += &format!("element face {n_faces}\nproperty uchar flags\nproperty list uchar int vertex_indices\nend_header\n");
    for (i, v) in VERTS.iter().enumerate() {
        s += &format!("{} {} {} {}\n", v[0], v[1], v[2], i as f32 * 0.5);
    }
    s += "0 1\n";
    s += faces;
    s
}

fn binary_ply() -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(
        b"ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty double x\nproperty double y\n\
          property double z\nproperty list uchar float junk\nproperty float confidence\nelement edge 1\n\
          property int vertex1\nproperty int vertex2\nelement face 2\nproperty uchar flags\n\
          property list uchar uint vertex_index\nend_header\n",
    );
    for v in VERTS {
        for c in v {
            b.extend_from_slice(&(c as f64).to_le_bytes());
        }
        b.push(2);
        b.extend_from_slice(&1.0f32.to_le_bytes());
        b.extend_from_slice(&2.0f32.to_le_bytes());
        b.extend_from_slice(&0.5f32.to_le_bytes());
    }
    b.extend_from_slice(&0i32.to_le_bytes());
    b.extend_from_slice(&1i32.to_le_bytes());
    for face in [&[0u32, 1, 2, 3][..], &[0, 1, 4]] {
        b.push(7);
        b.push(face.len() as u8);
        for i in face {
            b.extend_from_slice(&i.to_le_bytes());
        }
    }
    b
}

#[test]
fn ply_ascii_binary_and_gz_agree() {
    let t = Transform::default();
    let a = temp("quad.ply");
    std::fs::write(&a, ascii_ply("1 4 0 1 2 3\n\n0 3 0 1 4\n", 2)).unwrap();
    let b = temp("quad_bin.ply");
    std::fs::write(&b, binary_ply()).unwrap();
    let g = temp("quad.ply.gz");
    std::fs::write(&g, crate::io::gzip(ascii_ply("1 4 0 1 2 3\n0 3 0 1 4\n", 2).as_bytes())).unwrap();
    let (ma, mb, mg) = (Mesh::load(&a, &t).unwrap(), Mesh::load(&b, &t).unwrap(), Mesh::load(&g, &t).unwrap());
    assert_eq!(ma.triangle_count(), 3, "quad fan-triangulated + triangle");
    let v = VERTS.map(Vec3::from);
    let expect = vec![[v[0], v[1], v[2]], [v[0], v[2], v[3]], [v[0], v[1], v[4]]];
    assert_eq!(tris_in_file_order(&ma), expect);
    assert_eq!(tris_in_file_order(&mb), expect);
    assert_eq!(tris_in_file_order(&mg), expect);
    assert!(!ma.has_normals());
    let h = ma.intersect(&Ray::new(Vec3::new(0.2, 0.7, 5.0), -Vec3::Z), f32::INFINITY).unwrap();
    assert!((h.t - 5.0).abs() < 1e-6 && h.n == Vec3::Z && h.ns == h.n);
}

#[test]
fn ply_errors_name_file_and_line() {
    let t = Transform::default();
    let p = temp("truncated.ply");
    std::fs::write(&p, ascii_ply("1 4 0 1 2 3\n", 2)).unwrap();
    let e = Mesh::load(&p, &t).unwrap_err().to_string();
    assert!(e.contains("truncated.ply") && e.contains("line 23") && e.contains("end of file"), "{e}");
    let p = temp("range.ply");
    std::fs::write(&p, ascii_ply("1 4 0 1 2 3\n0 3 0 1 5\n", 2)).unwrap();
    let e = Mesh::load(&p, &t).unwrap_err().to_string();
    assert!(e.contains("range.ply") && e.contains("line 23") && e.contains("out of range"), "{e}");
    let p = temp("short.ply");
    std::fs::write(&p, ascii_ply("1 4 0 1 2 3\n0 3 0 1\n", 2)).unwrap();
    let e = Mesh::load(&p, &t).unwrap_err().to_string();
    assert!(e.contains("short.ply") && e.contains("line 23") && e.contains("end of line"), "{e}");
    let p = temp("trunc_bin.ply");
    let b = binary_ply();
    std::fs::write(&p, &b[..b.len() - 3]).unwrap();
    let e = Mesh::load(&p, &t).unwrap_err().to_string();
    assert!(e.contains("trunc_bin.ply") && e.contains("face") && e.contains("end of file"), "{e}");
    let p = temp("bad.ply.gz");
    std::fs::write(&p, b"not gzip").unwrap();
    assert!(Mesh::load(&p, &t).unwrap_err().to_string().contains("bad.ply.gz"));
    let e = Mesh::load(&temp("missing.obj"), &t).unwrap_err().to_string();
    assert!(e.contains("missing.obj"), "{e}");
    let p = temp("degenerate.ply");
    std::fs::write(&p, ascii_ply("1 3 0 1 1\n", 1)).unwrap();
    let e = Mesh::load(&p, &t).unwrap_err().to_string();
    assert!(e.contains("no valid triangles"), "{e}");
}

fn brute(m: &Mesh, ray: &Ray, t_max: f32) -> Option<(f32, u32)> {
    (0..m.triangle_count() as u32)
        .filter_map(|k| {
            let [a, b, c] = m.triangle(k);
            Triangle::new(a, b, c).intersect(ray, t_max).map(|h| (h.t, k))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// BVH traversal agrees with brute force on random rays through the mesh's bounds.
fn check_against_brute_force(m: &Mesh, n_rays: usize, seed: u64) {
    let b = m.bounds();
    let mut rng = Pcg32::new(seed, 4);
    let point = |rng: &mut Pcg32| {
        b.min + b.diagonal() * Vec3::new(uniform(rng), uniform(rng), uniform(rng)) * 1.4 - b.diagonal() * 0.2
    };
    let mut hits = 0;
    for i in 0..n_rays {
        let o = point(&mut rng);
        let d = if i % 2 == 0 { random_dir(&mut rng) } else { (point(&mut rng) - o).normalize() };
        let ray = Ray::new(o, d);
        let expect = brute(m, &ray, f32::INFINITY);
        let got = m.intersect(&ray, f32::INFINITY);
        match (expect, got) {
            (None, None) => {}
            (Some((t, k)), Some(h)) => {
                hits += 1;
                assert!((t - h.t).abs() <= 1e-5 * t, "ray {i}: t {t} vs {}", h.t);
                // Different triangles only for a tie (a ray through a shared edge or vertex).
                assert!(k == h.prim || (t - h.t).abs() <= 1e-6 * t, "ray {i}: triangle {k} vs {}", h.prim);
                assert!((h.n.length() - 1.0).abs() < 1e-5 && h.ns.dot(h.n) >= 0.0);
            }
            (e, g) => panic!("ray {i}: brute force {e:?} vs bvh {:?}", g.map(|h| (h.t, h.prim))),
        }
        assert_eq!(m.occluded(&ray, f32::INFINITY), expect.is_some(), "ray {i}: occluded");
    }
    assert!(hits > n_rays / 10, "{hits} hits");
}

#[test]
fn bunny_obj_matches_brute_force() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/bunny.obj");
    let m = Mesh::load(&path, &Transform::default()).unwrap();
    println!("bunny: {} triangles, {} degenerate dropped", m.triangle_count(), m.degenerate_dropped());
    assert_eq!(m.triangle_count() + m.degenerate_dropped(), 3674);
    check_against_brute_force(&m, 10_000, 1);
}

#[test]
fn dragon_ply_gz_matches_brute_force() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes/dragon_vrip_res4.ply.gz");
    if !path.exists() {
        println!("skipped: {} not found (shared/ is expected beside the repository)", path.display());
        return;
    }
    let m = Mesh::load(&path, &Transform::default()).unwrap();
    println!("dragon res4: {} triangles, {} degenerate dropped", m.triangle_count(), m.degenerate_dropped());
    assert_eq!(m.triangle_count() + m.degenerate_dropped(), 11_102);
    check_against_brute_force(&m, 10_000, 2);
}

#[test]
fn face_index_counts_dropped_triangles() {
    let pos: Vec<Vec3> = (0..12).map(|i| Vec3::new(i as f32, (i * i % 7) as f32, (i % 3) as f32)).collect();
    // Faces 0, 3, 4 and 7 are degenerate (repeated vertex).
    let faces: Vec<[u32; 3]> = (0..9u32)
        .map(|f| if [0, 3, 4, 7].contains(&f) { [f, f, f + 1] } else { [f, f + 1, f + 2 + (f % 2)] })
        .collect();
    let m = Mesh::from_triangles(pos.clone(), faces.clone(), None).unwrap();
    assert_eq!(m.degenerate_dropped(), 4);
    let mut seen: Vec<u32> = (0..m.triangle_count() as u32)
        .map(|k| {
            let f = m.face_index(k);
            assert_eq!(m.triangle(k), faces[f as usize].map(|i| pos[i as usize]), "slot {k} -> face {f}");
            f
        })
        .collect();
    seen.sort();
    assert_eq!(seen, vec![1, 2, 5, 6, 8]);
}

#[test]
fn transform_and_normals() {
    let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let t = Transform { scale: Vec3::new(2.0, 3.0, 1.0), rotate_deg: Vec3::new(0.0, 0.0, 90.0), translate: Vec3::Z };
    let m = Mesh::build(pos.clone(), vec![[0, 1, 2]], None, None, &t, None, &|m| Error::Settings(m)).unwrap();
    let [a, b, c] = m.triangle(0);
    assert!((a - Vec3::Z).length() < 1e-6);
    assert!((b - Vec3::new(0.0, 2.0, 1.0)).length() < 1e-6, "{b}");
    assert!((c - Vec3::new(-3.0, 0.0, 1.0)).length() < 1e-6, "{c}");
    // Mirroring keeps the front side (normal +z before and after).
    let mirror = Transform { scale: Vec3::new(-1.0, 1.0, 1.0), ..Default::default() };
    let m = Mesh::build(pos.clone(), vec![[0, 1, 2]], None, None, &mirror, None, &|m| Error::Settings(m)).unwrap();
    let h = m.intersect(&Ray::new(Vec3::new(-0.2, 0.2, 1.0), -Vec3::Z), f32::INFINITY).unwrap();
    assert_eq!(h.n, Vec3::Z);
    assert!(
        Mesh::build(pos.clone(), vec![[0, 1, 2]], None, None, &Transform { scale: Vec3::ZERO, ..t }, None, &|m| {
            Error::Settings(m)
        })
        .is_err()
    );
    // Interpolated vertex normals, flipped into n's hemisphere.
    let ns = vec![Vec3::new(0.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(0.0, 0.0, -1.0)];
    let m = Mesh::from_triangles(pos.clone(), vec![[0, 1, 2]], Some(ns)).unwrap();
    let h = m.intersect(&Ray::new(Vec3::new(0.5, 0.25, 1.0), -Vec3::Z), f32::INFINITY).unwrap();
    assert!(h.ns.z > 0.0 && h.ns.x < 0.0 && (h.ns.length() - 1.0).abs() < 1e-6, "{}", h.ns);
    let e = Mesh::from_triangles(pos, vec![[0, 1, 3]], None).unwrap_err();
    assert!(matches!(e, Error::Settings(_)) && e.to_string().contains("out of range"));
}

#[test]
fn uv_interpolates_vertex_uvs_or_takes_pbrts_default() {
    // A square whose uvs are its (x, y): the uv at any hit is the hit's (x, y).
    let pos = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    let uvs = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let data =
        MeshData { positions: pos.clone(), triangles: vec![[0, 1, 2], [0, 2, 3]], normals: None, uvs: Some(uvs) };
    let m = Mesh::from_parts(data, &Transform::default(), None, &Error::Settings).unwrap();
    let mut rng = Pcg32::new(5, 1);
    for _ in 0..200 {
        let (x, y) = (uniform(&mut rng), uniform(&mut rng));
        let h = m.intersect(&Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z), f32::INFINITY).unwrap();
        // Barycentrics of the hit in the stored triangle (in the z = 0 plane).
        let [p0, p1, p2] = m.triangle(h.prim);
        let (e1, e2, q) = (p1 - p0, p2 - p0, h.p - p0);
        let det = e1.x * e2.y - e1.y * e2.x;
        let (b1, b2) = ((q.x * e2.y - q.y * e2.x) / det, (e1.x * q.y - e1.y * q.x) / det);
        let uv = m.uv(h.prim, b1, b2);
        assert!((uv[0] - x).abs() < 1e-5 && (uv[1] - y).abs() < 1e-5, "({x}, {y}): {uv:?}");
    }
    // Without uvs: (0, 0), (1, 0), (1, 1) at the vertices, linear between.
    let m = Mesh::from_triangles(pos, vec![[0, 1, 2]], None).unwrap();
    assert!(m.uvs.is_none() && m.vert_idx.is_empty(), "no cost without uvs");
    assert_eq!([m.uv(0, 0.0, 0.0), m.uv(0, 1.0, 0.0), m.uv(0, 0.0, 1.0)], [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]);
    assert_eq!(m.uv(0, 0.5, 0.25), [0.75, 0.25]);
}

/// Large meshes are placed and checked in parallel chunks: the kept triangles, the
/// dropped ones and the first error must be those of one pass in order (written out
/// here as that pass).
#[test]
fn parallel_placing_equals_one_pass_in_order() {
    let n = 3 * PLACE_CHUNK + 123;
    assert!(n > PARALLEL_PLACE);
    let pos: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f32, ((i * 37) % 101) as f32, ((i * 11) % 7) as f32)).collect();
    // Every 997th face repeats a vertex (zero area), in every chunk.
    let faces: Vec<[u32; 3]> =
        (0..n as u32 - 2).map(|f| if f % 997 == 5 { [f, f, f + 1] } else { [f, f + 1, f + 2] }).collect();
    let mirror = Transform { scale: Vec3::new(-1.0, 2.0, 1.0), ..Default::default() };
    let m = Mesh::build(pos.clone(), faces.clone(), None, None, &mirror, None, &|m| Error::Settings(m)).unwrap();
    let lin = mirror.linear();
    let placed: Vec<Vec3> = pos.iter().map(|&p| lin * p + mirror.translate).collect();
    let (mut kept, mut dropped) = (Vec::new(), Vec::new());
    for (f, t) in faces.iter().enumerate() {
        let [a, b, c] = t.map(|i| placed[i as usize]);
        let area2 = (b - a).cross(c - a).length_squared();
        if area2 > 0.0 && area2.is_finite() { kept.push([t[0], t[2], t[1]]) } else { dropped.push(f as u32) }
    }
    assert_eq!(m.degenerate_dropped(), dropped.len());
    assert_eq!(m.triangle_count(), kept.len());
    for k in (0..m.triangle_count() as u32).step_by(101) {
        let orig = m.original_index(k) as usize;
        assert_eq!(m.triangle(k), kept[orig].map(|i| placed[i as usize]), "slot {k}");
        let face = m.face_index(k) as usize;
        assert_eq!(kept[orig], [faces[face][0], faces[face][2], faces[face][1]], "slot {k}");
    }
    // The first bad index and the first non-finite vertex, in the last chunks.
    let mut bad = faces.clone();
    bad[2 * PLACE_CHUNK + 7][1] = n as u32 + 5;
    bad[3 * PLACE_CHUNK + 1][0] = n as u32 + 9;
    let e = Mesh::from_triangles(pos.clone(), bad, None).unwrap_err().to_string();
    let f = 2 * PLACE_CHUNK + 7;
    assert!(e.contains(&format!("triangle {f}: vertex index {} out of range (there are {n} vertices)", n + 5)), "{e}");
    let mut nan = pos.clone();
    nan[PLACE_CHUNK + 3].y = f32::NAN;
    nan[3 * PLACE_CHUNK].x = f32::INFINITY;
    let e = Mesh::from_triangles(nan, faces, None).unwrap_err().to_string();
    assert!(e.contains(&format!("vertex {} has a non-finite coordinate", PLACE_CHUNK + 3)), "{e}");
}
