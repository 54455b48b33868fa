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
use rayon::prelude::*;

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
        let positions = place_vertices(&original, m, translate, err)?;
        if let Some(ns) = normals.as_mut() {
            let nm = m.inverse().transpose();
            // Zero or broken normals become zero and fall back to the geometric normal.
            let turn = |n: &mut Vec3| *n = (nm * *n).normalize_or_zero();
            if ns.len() > PARALLEL_PLACE {
                ns.par_chunks_mut(PLACE_CHUNK).for_each(|c| c.iter_mut().for_each(turn));
            } else {
                ns.iter_mut().for_each(turn);
            }
        }
        // A mirroring transform flips the winding; swap two vertices to keep the front.
        let (kept, dropped) = keep_triangles(&positions, &indices, det < 0.0, err)?;
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

/// Meshes with more vertices or triangles than this are placed and checked in
/// parallel, over fixed chunks of [`PLACE_CHUNK`] joined in order: the same arrays,
/// and the same first error, as one pass in order.
const PARALLEL_PLACE: usize = 1 << 16;
/// Vertices or triangles per chunk of the parallel placing.
const PLACE_CHUNK: usize = 1 << 15;

/// The first problem a chunk of the placing found (made an [`Error`] outside the pool).
enum Bad {
    /// Vertex `i` is not finite in the file.
    Vertex(usize, Vec3),
    /// Vertex `i` is not finite after the transform.
    Placed(usize),
    /// Triangle `f` names vertex `bad`, out of range of the `nv` vertices.
    Index(usize, u32, usize),
}

/// Runs `one(first index, items chunk, out chunk)` over `items` and an output of the
/// same length, chunk by chunk: in parallel over fixed chunks when there are many (each
/// chunk writes its own part of the output, so its pages are first touched, and zeroed,
/// by the thread that fills them), in one pass otherwise. Returns what the chunks
/// returned, in order, or the first problem in order: the output and the error are
/// those of one pass in order.
fn in_chunks<T: Sync, O: Send, R: Send>(
    items: &[T],
    out: &mut [O],
    one: impl Fn(usize, &[T], &mut [O]) -> std::result::Result<R, Bad> + Sync,
) -> std::result::Result<Vec<R>, Bad> {
    debug_assert_eq!(items.len(), out.len());
    if items.len() <= PARALLEL_PLACE {
        return Ok(vec![one(0, items, out)?]);
    }
    let parts: Vec<std::result::Result<R, Bad>> = items
        .par_chunks(PLACE_CHUNK)
        .zip(out.par_chunks_mut(PLACE_CHUNK))
        .enumerate()
        .map(|(c, (chunk, o))| one(c * PLACE_CHUNK, chunk, o))
        .collect();
    parts.into_iter().collect()
}

/// The vertices `original` under `m · p + translate`; the first vertex (in order) that
/// is not finite before or after is the error. Large meshes are placed, then checked,
/// in parallel (rayon writes each part of the output from the thread that computes it).
fn place_vertices(original: &[Vec3], m: Mat3, translate: Vec3, err: &dyn Fn(String) -> Error) -> Result<Vec<Vec3>> {
    let place = |p: &Vec3| m * *p + translate;
    let bad = |(i, (p, q)): (usize, (&Vec3, &Vec3))| {
        if !p.is_finite() {
            Some(Bad::Vertex(i, *p))
        } else if !q.is_finite() {
            Some(Bad::Placed(i))
        } else {
            None
        }
    };
    let mut out = Vec::new();
    let first_bad = if original.len() <= PARALLEL_PLACE {
        out.extend(original.iter().map(place));
        original.iter().zip(&out).enumerate().find_map(bad)
    } else {
        original.par_iter().with_min_len(PLACE_CHUNK).map(place).collect_into_vec(&mut out);
        original.par_iter().zip(&out).enumerate().with_min_len(PLACE_CHUNK).find_map_first(bad)
    };
    match first_bad {
        Some(b) => Err(b.error(err)),
        None => Ok(out),
    }
}

/// The triangles of `indices` with an area (in `positions`), two vertices swapped
/// when `mirror`, and the file-order indices of those without; an index out of range
/// is an error (the first, in order). Each chunk packs its kept triangles at the start
/// of its own part of the output; the parts are closed up after, which moves nothing
/// when no triangle was dropped (the usual case).
fn keep_triangles(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    mirror: bool,
    err: &dyn Fn(String) -> Error,
) -> Result<(Vec<[u32; 3]>, Vec<u32>)> {
    let nv = positions.len();
    let mut kept = vec![[0u32; 3]; indices.len()];
    let parts = in_chunks(indices, &mut kept, |base, tris, out| {
        let mut n = 0;
        let mut dropped = Vec::new();
        for (k, tri) in tris.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= nv) {
                return Err(Bad::Index(base + k, bad, nv));
            }
            let tri = if mirror { [tri[0], tri[2], tri[1]] } else { *tri };
            let [a, b, c] = tri.map(|i| positions[i as usize]);
            let area2 = (b - a).cross(c - a).length_squared();
            if area2 > 0.0 && area2.is_finite() {
                out[n] = tri;
                n += 1;
            } else {
                dropped.push((base + k) as u32);
            }
        }
        Ok((n, dropped))
    })
    .map_err(|bad| bad.error(err))?;
    let chunk = if indices.len() <= PARALLEL_PLACE { indices.len() } else { PLACE_CHUNK };
    let mut end = 0;
    let mut dropped = Vec::new();
    for (c, (n, d)) in parts.into_iter().enumerate() {
        kept.copy_within(c * chunk..c * chunk + n, end);
        end += n;
        dropped.extend(d);
    }
    kept.truncate(end);
    Ok((kept, dropped))
}

impl Bad {
    /// The error the serial pass gave for this problem.
    fn error(self, err: &dyn Fn(String) -> Error) -> Error {
        match self {
            Bad::Vertex(i, p) => err(format!("vertex {i} has a non-finite coordinate {p}")),
            Bad::Placed(i) => Error::Setting {
                name: "scale",
                message: format!(
                    "vertex {i} leaves f32's range after the transform: the scale or translation is too large"
                ),
            },
            Bad::Index(f, bad, nv) => {
                err(format!("triangle {f}: vertex index {bad} out of range (there are {nv} vertices)"))
            }
        }
    }
}

#[cfg(test)]
mod tests;
