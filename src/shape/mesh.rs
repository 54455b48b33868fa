//! Triangle meshes: loading (through [`crate::io::mesh_file`]: .obj, .ply, either
//! optionally gzip-compressed), placement by a [`Transform`], and intersection through the
//! mesh's own [`WideBvh`], which also stores the triangles (four to a block, in leaf
//! order); `Hit::prim` is a triangle's index in that order (its slot).

use super::{Placement, Then};
use crate::io::{fnv1a, parse_mesh, read_input};
use crate::scene::check::Check;
use crate::scene::desc::{ScaleDesc, V3};
use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};

use super::bvh::{MAX_BLOCKS, TriangleHit, WideBvh};
use crate::error::{Error, Result};
use crate::geometry::{Aabb, Hit, Ray, Transform};
use crate::io::{MeshData, read_mesh_file};

/// A mesh file read, parsed and built ahead of the scene's other objects
/// ([`Mesh::read_ahead`]): the file's path, and its content's hash with the
/// built mesh, or the read's error.
pub(crate) struct MeshAhead {
    path: PathBuf,
    read: Result<(u64, Result<Mesh>)>,
}

/// A triangle mesh with optional per-vertex normals and its own BVH.
#[derive(Clone, Debug)]
pub struct Mesh {
    /// Vertex indices of each triangle (slot order), kept only with normals or uvs.
    vert_idx: Vec<[u32; 3]>,
    /// Unit per-vertex normals, if the file had them.
    normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, if given (for textures, issue 35; no cost
    /// for a mesh without).
    uvs: Option<Vec<[f32; 2]>>,
    /// The BVH, which holds the vertices of each triangle in slot order.
    bvh: WideBvh,
    /// Input triangle indices of the dropped zero-area triangles, ascending.
    dropped: Vec<u32>,
}

impl Mesh {
    /// Loads a mesh from `.obj` (tobj, triangulated) or `.ply` (ASCII or binary), either
    /// optionally gzip-compressed (`.obj.gz`, `.ply.gz`), and applies `transform`.
    /// Zero-area triangles are dropped and counted ([`Mesh::degenerate_dropped`]); a mesh
    /// with no valid triangle, an out-of-range index or a non-finite coordinate is an
    /// error naming the file; a transform that is singular or sends a vertex out of
    /// f32's range is an [`Error::Setting`] naming the transform's field (`scale`,
    /// `rotate_deg`, `translate`).
    pub fn load(path: &Path, transform: &Transform) -> Result<Mesh> {
        Mesh::from_data(read_mesh_file(path)?, path, transform)
    }

    /// [`Mesh::load`] from a mesh file's parsed contents (`path` names it in errors).
    pub fn from_data(data: MeshData, path: &Path, transform: &Transform) -> Result<Mesh> {
        Mesh::from_data_placed(data, path, transform, None)
    }

    /// [`Mesh::from_data`], then placed by `then` (an object's transform) when given.
    pub(crate) fn from_data_placed(
        data: MeshData,
        path: &Path,
        transform: &Transform,
        then: Option<&Then>,
    ) -> Result<Mesh> {
        Mesh::from_parts(data, transform, then, &|m| Error::mesh(path, m))
    }

    /// A mesh from parsed contents (a file's or an inline description's, with
    /// optional per-vertex normals and `uvs`: one per position, the caller
    /// checks), placed by `transform` then `then`; `err` makes the errors about
    /// the contents.
    pub(crate) fn from_parts(
        data: MeshData,
        transform: &Transform,
        then: Option<&Then>,
        err: &dyn Fn(String) -> Error,
    ) -> Result<Mesh> {
        let MeshData { positions, triangles, normals, uvs } = data;
        Mesh::build(positions, triangles, normals, uvs, transform, then, err)
    }

    /// The raw contents of a mesh file as [`Mesh::load`] reads them, before any transform
    /// or filtering: vertex positions and triangles (vertex indices; polygons
    /// fan-triangulated, OBJ triangulated by tobj) in file order, degenerate triangles
    /// included. Triangle `i` here is what [`Mesh::face_index`] refers to.
    pub fn read_arrays(path: &Path) -> Result<(Vec<Vec3>, Vec<[u32; 3]>)> {
        let MeshData { positions, triangles, .. } = read_mesh_file(path)?;
        Ok((positions, triangles))
    }

    /// A mesh from positions, triangles (indices into `positions`, counter-clockwise
    /// front) and optional per-vertex normals; errors are [`Error::Settings`].
    pub fn from_triangles(positions: Vec<Vec3>, indices: Vec<[u32; 3]>, normals: Option<Vec<Vec3>>) -> Result<Mesh> {
        Mesh::build(positions, indices, normals, None, &Transform::default(), None, &|m| {
            Error::Settings(format!("mesh: {m}"))
        })
    }

    fn build(
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        mut normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<[f32; 2]>>,
        transform: &Transform,
        then: Option<&Then>,
        err: &dyn Fn(String) -> Error,
    ) -> Result<Mesh> {
        let setting = |name, message| Error::Setting { name, message };
        let srt = match then {
            Some(Then::Srt(o)) => Some(o),
            _ => None,
        };
        for t in std::iter::once(transform).chain(srt) {
            if !t.rotate_deg.is_finite() {
                return Err(setting("rotate_deg", format!("expected finite angles, found {}", t.rotate_deg)));
            }
            if !t.translate.is_finite() {
                return Err(setting("translate", format!("expected finite coordinates, found {}", t.translate)));
            }
        }
        // The mesh's own placement, then the object's (`then`): one affine map.
        let (m, translate) = match then {
            None => (transform.linear(), transform.translate),
            Some(Then::Srt(o)) => {
                let lo = o.linear();
                (lo * transform.linear(), lo * transform.translate + o.translate)
            }
            Some(Then::Affine(a, b)) => (*a * transform.linear(), *a * transform.translate + *b),
        };
        let det = m.determinant();
        if let Some(Then::Affine(..)) = then
            && !(det != 0.0 && det.is_finite())
        {
            return Err(setting(
                "matrix",
                format!(
                    "the placement is singular in f32 (its linear part's determinant is {det:e}); expected an invertible matrix"
                ),
            ));
        }
        if !(det != 0.0 && det.is_finite()) {
            let scale = srt.map_or(transform.scale, |o| o.scale * transform.scale);
            return Err(setting(
                "scale",
                format!("the scale {scale} makes the transform singular in f32 (its determinant is {det:e})"),
            ));
        }
        if let Some(ns) = &normals
            && ns.len() != positions.len()
        {
            return Err(err(format!("{} normals for {} vertices", ns.len(), positions.len())));
        }
        // The file's positions stay until the triangles are checked: a transform that
        // collapses them (in f32) is told apart from a mesh that was degenerate already.
        let original = positions;
        let mut positions = Vec::with_capacity(original.len());
        for (i, p) in original.iter().enumerate() {
            if !p.is_finite() {
                return Err(err(format!("vertex {i} has a non-finite coordinate {p}")));
            }
            let q = m * *p + translate;
            if !q.is_finite() {
                return Err(setting(
                    "scale",
                    format!("vertex {i} leaves f32's range after the transform: the scale or translation is too large"),
                ));
            }
            positions.push(q);
        }
        if let Some(ns) = normals.as_mut() {
            let nm = m.inverse().transpose();
            for n in ns.iter_mut() {
                // Zero or broken normals become zero and fall back to the geometric normal.
                *n = (nm * *n).normalize_or_zero();
            }
        }
        // A mirroring transform flips the winding; swap two vertices to keep the front.
        let mirror = det < 0.0;
        let nv = positions.len();
        let mut kept: Vec<[u32; 3]> = Vec::with_capacity(indices.len());
        let mut dropped = Vec::new();
        for (f, tri) in indices.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= nv) {
                return Err(err(format!("triangle {f}: vertex index {bad} out of range (there are {nv} vertices)")));
            }
            let tri = if mirror { [tri[0], tri[2], tri[1]] } else { *tri };
            let [a, b, c] = tri.map(|i| positions[i as usize]);
            let area2 = (b - a).cross(c - a).length_squared();
            if area2 > 0.0 && area2.is_finite() {
                kept.push(tri);
            } else {
                dropped.push(f as u32);
            }
        }
        if kept.is_empty() {
            let has_area = |p: &dyn Fn(u32) -> Vec3| {
                indices
                    .iter()
                    .filter(|t| {
                        let [a, b, c] = t.map(p);
                        let area2 = (b - a).cross(c - a).length_squared();
                        area2 > 0.0 && area2.is_finite()
                    })
                    .count()
            };
            let before = has_area(&|i| original[i as usize]);
            if before > 0 {
                // Valid triangles collapsed: by the translation when the linear part alone keeps them.
                let name = if has_area(&|i| m * original[i as usize]) > 0 { "translate" } else { "scale" };
                let cause = if name == "translate" {
                    format!("the translation {translate} is too large for the mesh's size (f32 keeps about 7 digits)")
                } else {
                    "the scale or rotation shrinks them below f32's precision".to_string()
                };
                return Err(setting(
                    name,
                    format!(
                        "the transform collapses every triangle to zero area (given: {}, with an area before it: {before}): {cause}; expected a transform that keeps the triangles apart",
                        indices.len()
                    ),
                ));
            }
            return Err(err(format!("no valid triangles ({} given, {} of zero area)", indices.len(), dropped.len())));
        }
        drop(original);
        if kept.len() > MAX_BLOCKS {
            return Err(err(format!("{} triangles: at most {MAX_BLOCKS} are supported", kept.len())));
        }
        let bvh = WideBvh::build_indexed(&positions, &kept);
        let order = bvh.prim_order();
        let keep_idx = normals.is_some() || uvs.is_some();
        let vert_idx = if keep_idx { order.iter().map(|&i| kept[i as usize]).collect() } else { Vec::new() };
        Ok(Mesh { vert_idx, normals, uvs, bvh, dropped })
    }

    /// Closest hit with `0 < t < t_max`. `prim` is the triangle's index in storage order.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let h = self.bvh.intersect(ray, t_max)?;
        Some(self.make_hit(&h))
    }

    fn make_hit(&self, h: &TriangleHit) -> Hit {
        let [p0, p1, p2] = h.v;
        let [b0, b1, b2] = h.b;
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        let n = (p1 - p0).cross(p2 - p0).normalize();
        let mut ns = n;
        if let Some(normals) = &self.normals {
            let [i0, i1, i2] = self.vert_idx[h.slot as usize];
            let s = normals[i0 as usize] * b0 + normals[i1 as usize] * b1 + normals[i2 as usize] * b2;
            let s = s.normalize_or_zero();
            if s != Vec3::ZERO {
                ns = if s.dot(n) < 0.0 { -s } else { s };
            }
        }
        Hit { t: h.t, p, n, ns, prim: h.slot }
    }

    /// True if any triangle blocks the ray with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.bvh.occluded(ray, t_max)
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// Number of (non-degenerate) triangles.
    pub fn triangle_count(&self) -> usize {
        self.bvh.prim_order().len()
    }

    /// Number of zero-area triangles dropped at load.
    pub fn degenerate_dropped(&self) -> usize {
        self.dropped.len()
    }

    /// The mesh's BVH (its slots are the triangle indices of [`Mesh::triangle`]).
    pub fn bvh(&self) -> &WideBvh {
        &self.bvh
    }

    /// The vertices of triangle `prim` (storage order, as in `Hit::prim`), e.g. for
    /// sampling mesh lights. Panics if `prim >= triangle_count()` (a programming error).
    pub fn triangle(&self, prim: u32) -> [Vec3; 3] {
        self.bvh.triangle(prim)
    }

    /// Index of triangle `prim` among the valid triangles in file order.
    pub fn original_index(&self, prim: u32) -> u32 {
        self.bvh.prim_order()[prim as usize]
    }

    /// Index of triangle `prim` (storage order) in the input triangle list, counting the
    /// zero-area triangles that were dropped: for a PLY file of triangles this is the
    /// face index in file order (polygons count one per fan triangle), the primitive id
    /// other tracers such as Embree report for the same file.
    pub fn face_index(&self, prim: u32) -> u32 {
        let mut f = self.original_index(prim);
        // Each dropped triangle at or before the running index shifts it by one.
        for &d in &self.dropped {
            if d > f {
                break;
            }
            f += 1;
        }
        f
    }

    /// True if the mesh has per-vertex normals.
    pub fn has_normals(&self) -> bool {
        self.normals.is_some()
    }

    /// The texture coordinates at barycentrics `(b1, b2)` of triangle `tri` (storage
    /// order, as `Hit::prim`; the point is `(1 - b1 - b2) p0 + b1 p1 + b2 p2` of
    /// [`Mesh::triangle`]): the per-vertex uvs interpolated, or without them pbrt's
    /// default, `(0, 0)`, `(1, 0)`, `(1, 1)` at the triangle's three vertices.
    /// [`Shape::uv`](super::Shape::uv) calls it, only where a material asks.
    pub(crate) fn uv(&self, tri: u32, b1: f32, b2: f32) -> [f32; 2] {
        let b0 = 1.0 - b1 - b2;
        let [a, b, c] = match &self.uvs {
            Some(uvs) => self.vert_idx[tri as usize].map(|i| uvs[i as usize]),
            None => [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
        };
        [b0 * a[0] + b1 * b[0] + b2 * c[0], b0 * a[1] + b1 * b[1] + b2 * c[1]]
    }
}

impl Mesh {
    /// A mesh from the scene description at `field`: the file `path` (relative to the
    /// scene file, recorded in the scene's identity), placed by its own transform.
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        path: &str,
        scale: &Option<ScaleDesc>,
        rotate_deg: &Option<V3>,
        translate: &Option<V3>,
        xf: Option<&Placement>,
    ) -> Result<Mesh> {
        let transform = check.transform(field, scale, rotate_deg, translate)?;
        let then = xf.map(Placement::then);
        let ahead = Mesh::read_ahead(check.dir.join(path), &transform, then.as_ref());
        Mesh::from_ahead(check, field, path, ahead, xf)
    }

    /// Reads, parses and builds the mesh file at `path` placed by `transform`
    /// then `then`, without a [`Check`]: the scene loader calls it for every
    /// mesh of a scene at once on the thread pool, then [`Mesh::from_ahead`] in
    /// object order. The result (and the mesh's BVH) does not depend on the
    /// thread that made it.
    pub(crate) fn read_ahead(path: PathBuf, transform: &Transform, then: Option<&Then>) -> MeshAhead {
        let read = read_input(&path).map(|bytes| {
            // The file's hash (serial, about 1.5 ns a byte) beside the parse, not before it.
            let (data, hash) = rayon::join(|| parse_mesh(&bytes, &path), || fnv1a(&bytes));
            drop(bytes);
            (hash, data.and_then(|data| Mesh::from_data_placed(data, &path, transform, then)))
        });
        MeshAhead { path, read }
    }

    /// The mesh of field `field` (`rel`: the file as the scene names it) from
    /// what [`Mesh::read_ahead`] made: records the file in the scene's identity
    /// and names the field in any error, exactly as reading it here would.
    pub(crate) fn from_ahead(
        check: &Check,
        field: &str,
        rel: &str,
        ahead: MeshAhead,
        xf: Option<&Placement>,
    ) -> Result<Mesh> {
        let f = |name: &str| format!("{field}.{name}");
        let (hash, built) = ahead.read.map_err(|e| check.err(f("path"), e.to_string()))?;
        check.record_input(rel, ahead.path, hash);
        built.map_err(|e| match (e, xf) {
            // A transform that breaks the composed placement is the object's when it has one.
            (Error::Setting { name, message }, Some(x)) => check.err(format!("{}.{name}", x.field), message),
            (Error::Setting { name, message }, None) => check.err(f(name), message),
            (e, _) => check.err(f("path"), e.to_string()),
        })
    }

    /// A copy of this mesh placed by `x -> m x + t` (an instance that cannot share the
    /// mesh, see [`super::MeshInstance::new`]): its triangles in storage order, with their
    /// normals and uvs, built as a mesh placed by a `matrix:` is.
    pub(crate) fn placed_copy(&self, m: Mat3, t: Vec3) -> Result<Mesh> {
        let n = self.triangle_count() as u32;
        let mut positions = Vec::with_capacity(3 * n as usize);
        let mut normals = self.normals.as_ref().map(|_| Vec::with_capacity(3 * n as usize));
        let mut uvs = self.uvs.as_ref().map(|_| Vec::with_capacity(3 * n as usize));
        for k in 0..n {
            positions.extend(self.triangle(k));
            if let (Some(out), Some(ns)) = (normals.as_mut(), &self.normals) {
                out.extend(self.vert_idx[k as usize].map(|i| ns[i as usize]));
            }
            if let (Some(out), Some(us)) = (uvs.as_mut(), &self.uvs) {
                out.extend(self.vert_idx[k as usize].map(|i| us[i as usize]));
            }
        }
        let indices = (0..n).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
        let then = Then::Affine(m, t);
        Mesh::build(positions, indices, normals, uvs, &Transform::default(), Some(&then), &Error::Settings)
    }

    /// A cuboid `[min, max]` placed by `t` as a closed mesh of 12 triangles, wound
    /// counter-clockwise seen from outside (outward normals: still a solid).
    pub(crate) fn cuboid(min: Vec3, max: Vec3, t: &Transform) -> Result<Mesh> {
        let corners: Vec<Vec3> =
            (0..8).map(|i| Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), max, min)).collect();
        // Corner i has x = bit 0, y = bit 1, z = bit 2; two triangles per face.
        let faces: [[u32; 4]; 6] = [
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
        ];
        let tris = faces.iter().flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]]).collect();
        Mesh::build(corners, tris, None, None, &Transform::default(), Some(&Then::Srt(*t)), &|m| {
            Error::Settings(format!("cuboid: {m}"))
        })
    }
}

#[cfg(test)]
mod tests {
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
        s += &format!(
            "element face {n_faces}\nproperty uchar flags\nproperty list uchar int vertex_indices\nend_header\n"
        );
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
        let t =
            Transform { scale: Vec3::new(2.0, 3.0, 1.0), rotate_deg: Vec3::new(0.0, 0.0, 90.0), translate: Vec3::Z };
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
}
