//! Triangle meshes: loading (.obj via tobj, .ply via our reader, either optionally
//! gzip-compressed), placement by a [`Transform`], and intersection through the
//! mesh's own [`Bvh`]. Triangles are stored in BVH leaf order, so the triangles of
//! a leaf are contiguous in memory; `Hit::prim` is a triangle's index in that order.

use super::ply;
use super::triangle::TriRay;
use super::{Aabb, Hit, Ray};
use crate::bvh::Bvh;
use crate::error::{Error, Result};
use glam::{Mat3, Vec3};
use std::io::Read;
use std::path::Path;

/// Placement of a mesh: scale, then rotate about X, then Y, then Z (degrees), then
/// translate. The default is the identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Per-axis scale (applied first).
    pub scale: Vec3,
    /// Rotation angles in degrees about X, Y and Z, applied in that order.
    pub rotate_deg: Vec3,
    /// Translation (applied last).
    pub translate: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            scale: Vec3::ONE,
            rotate_deg: Vec3::ZERO,
            translate: Vec3::ZERO,
        }
    }
}

impl Transform {
    /// The linear part: `Rz * Ry * Rx * S`.
    pub fn linear(&self) -> Mat3 {
        let r = self.rotate_deg * (std::f32::consts::PI / 180.0);
        Mat3::from_rotation_z(r.z)
            * Mat3::from_rotation_y(r.y)
            * Mat3::from_rotation_x(r.x)
            * Mat3::from_diagonal(self.scale)
    }

    /// Transforms a point.
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.linear() * p + self.translate
    }
}

/// A triangle mesh with optional per-vertex normals and its own BVH.
#[derive(Clone, Debug)]
pub struct Mesh {
    /// Vertices of each triangle, in BVH slot order.
    tris: Vec<[Vec3; 3]>,
    /// Vertex indices of each triangle (slot order), kept only with normals.
    normal_idx: Vec<[u32; 3]>,
    /// Unit per-vertex normals, if the file had them.
    normals: Option<Vec<Vec3>>,
    bvh: Bvh,
    degenerate: usize,
}

/// Barycentric payload of a mesh hit, turned into a [`Hit`] once the closest is known.
#[derive(Clone, Copy)]
struct TriHit {
    k: u32,
    t: f32,
    b: [f32; 3],
}

impl Mesh {
    /// Loads a mesh from `.obj` (tobj, triangulated) or `.ply` (ASCII or binary), either
    /// optionally gzip-compressed (`.obj.gz`, `.ply.gz`), and applies `transform`.
    /// Zero-area triangles are dropped and counted ([`Mesh::degenerate_dropped`]); a mesh
    /// with no valid triangle, an out-of-range index, a non-finite coordinate or a
    /// singular transform is an error naming the file.
    pub fn load(path: &Path, transform: &Transform) -> Result<Mesh> {
        let raw = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_lowercase())
            .unwrap_or_default();
        let (data, name) = if let Some(stem) = name.strip_suffix(".gz") {
            let mut out = Vec::with_capacity(raw.len() * 4);
            flate2::read::MultiGzDecoder::new(raw.as_slice())
                .read_to_end(&mut out)
                .map_err(|e| Error::mesh(path, format!("gzip decompression failed: {e}")))?;
            (out, stem.to_string())
        } else {
            (raw, name)
        };
        let (positions, indices, normals) = if name.ends_with(".ply") {
            let d = ply::parse(&data, path)?;
            (d.positions, d.triangles, d.normals)
        } else if name.ends_with(".obj") {
            load_obj(&data, path)?
        } else {
            return Err(Error::mesh(
                path,
                "unknown mesh format: expected a name ending in .obj, .ply, .obj.gz or .ply.gz",
            ));
        };
        Mesh::build(positions, indices, normals, transform, &|m| {
            Error::mesh(path, m)
        })
    }

    /// A mesh from positions, triangles (indices into `positions`, counter-clockwise
    /// front) and optional per-vertex normals; errors are [`Error::Settings`].
    pub fn from_triangles(
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        normals: Option<Vec<Vec3>>,
    ) -> Result<Mesh> {
        Mesh::build(positions, indices, normals, &Transform::default(), &|m| {
            Error::Settings(format!("mesh: {m}"))
        })
    }

    fn build(
        mut positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        mut normals: Option<Vec<Vec3>>,
        transform: &Transform,
        err: &dyn Fn(String) -> Error,
    ) -> Result<Mesh> {
        let m = transform.linear();
        let det = m.determinant();
        if !(det != 0.0 && det.is_finite() && transform.translate.is_finite()) {
            return Err(err(format!(
                "transform {transform:?} is singular or not finite"
            )));
        }
        if let Some(ns) = &normals {
            if ns.len() != positions.len() {
                return Err(err(format!(
                    "{} normals for {} vertices",
                    ns.len(),
                    positions.len()
                )));
            }
        }
        for (i, p) in positions.iter_mut().enumerate() {
            if !p.is_finite() {
                return Err(err(format!("vertex {i} has a non-finite coordinate {p:?}")));
            }
            *p = m * *p + transform.translate;
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
        let mut degenerate = 0;
        for (f, tri) in indices.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= nv) {
                return Err(err(format!(
                    "triangle {f}: vertex index {bad} out of range (there are {nv} vertices)"
                )));
            }
            let tri = if mirror {
                [tri[0], tri[2], tri[1]]
            } else {
                *tri
            };
            let [a, b, c] = tri.map(|i| positions[i as usize]);
            let area2 = (b - a).cross(c - a).length_squared();
            if area2 > 0.0 && area2.is_finite() {
                kept.push(tri);
            } else {
                degenerate += 1;
            }
        }
        if kept.is_empty() {
            return Err(err(format!(
                "no valid triangles ({} given, {degenerate} of zero area)",
                indices.len()
            )));
        }
        let bounds: Vec<Aabb> = kept
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                Aabb::new(a, b).grow(c)
            })
            .collect();
        let bvh = Bvh::build(&bounds);
        let order = bvh.prim_order();
        let tris = order
            .iter()
            .map(|&i| kept[i as usize].map(|v| positions[v as usize]))
            .collect();
        let normal_idx = if normals.is_some() {
            order.iter().map(|&i| kept[i as usize]).collect()
        } else {
            Vec::new()
        };
        Ok(Mesh {
            tris,
            normal_idx,
            normals,
            bvh,
            degenerate,
        })
    }

    /// Closest hit with `0 < t < t_max`. `prim` is the triangle's index in storage order.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let tr = TriRay::new(ray);
        let h = self.bvh.intersect(ray, t_max, |k, t_max| {
            let [p0, p1, p2] = self.tris[k as usize];
            tr.intersect(p0, p1, p2, t_max).map(|(t, b0, b1, b2)| {
                (
                    t,
                    TriHit {
                        k,
                        t,
                        b: [b0, b1, b2],
                    },
                )
            })
        })?;
        Some(self.make_hit(&h))
    }

    fn make_hit(&self, h: &TriHit) -> Hit {
        let [p0, p1, p2] = self.tris[h.k as usize];
        let [b0, b1, b2] = h.b;
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        let n = (p1 - p0).cross(p2 - p0).normalize();
        let mut ns = n;
        if let Some(normals) = &self.normals {
            let [i0, i1, i2] = self.normal_idx[h.k as usize];
            let s =
                normals[i0 as usize] * b0 + normals[i1 as usize] * b1 + normals[i2 as usize] * b2;
            let s = s.normalize_or_zero();
            if s != Vec3::ZERO {
                ns = if s.dot(n) < 0.0 { -s } else { s };
            }
        }
        Hit {
            t: h.t,
            p,
            n,
            ns,
            prim: h.k,
        }
    }

    /// True if any triangle blocks the ray with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        let tr = TriRay::new(ray);
        self.bvh.occluded(ray, t_max, |k, t_max| {
            let [p0, p1, p2] = self.tris[k as usize];
            tr.intersect(p0, p1, p2, t_max).is_some()
        })
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// Number of (non-degenerate) triangles.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Number of zero-area triangles dropped at load.
    pub fn degenerate_dropped(&self) -> usize {
        self.degenerate
    }

    /// The mesh's BVH (its slots are the triangle indices of [`Mesh::triangle`]).
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// The vertices of triangle `prim` (storage order, as in `Hit::prim`), e.g. for
    /// sampling mesh lights. Panics if `prim >= triangle_count()` (a programming error).
    pub fn triangle(&self, prim: u32) -> [Vec3; 3] {
        self.tris[prim as usize]
    }

    /// Index of triangle `prim` among the valid triangles in file order.
    pub fn original_index(&self, prim: u32) -> u32 {
        self.bvh.prim_order()[prim as usize]
    }

    /// True if the mesh has per-vertex normals.
    pub fn has_normals(&self) -> bool {
        self.normals.is_some()
    }
}

type Loaded = (Vec<Vec3>, Vec<[u32; 3]>, Option<Vec<Vec3>>);

/// Reads an OBJ file (all its objects and groups merged) with tobj, triangulated, with
/// one index per vertex so that normals line up with positions.
fn load_obj(data: &[u8], path: &Path) -> Result<Loaded> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let mut reader = std::io::BufReader::new(data);
    let (models, _materials) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Ok((Vec::new(), Default::default())))
            .map_err(|e| Error::mesh(path, format!("OBJ parse error: {e}")))?;
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut normals = Vec::new();
    let mut all_normals = true;
    for model in &models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        let nv = m.positions.len() / 3;
        positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        if m.normals.len() == m.positions.len() {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            );
        } else {
            all_normals = false;
        }
        if m.indices.len() % 3 != 0 {
            return Err(Error::mesh(
                path,
                format!(
                    "object '{}': {} indices is not a multiple of 3",
                    model.name,
                    m.indices.len()
                ),
            ));
        }
        for c in m.indices.chunks_exact(3) {
            if let Some(&bad) = c.iter().find(|&&i| i as usize >= nv) {
                return Err(Error::mesh(
                    path,
                    format!(
                        "object '{}': vertex index {} out of range ({nv} vertices)",
                        model.name,
                        bad + 1
                    ),
                ));
            }
            indices.push([base + c[0], base + c[1], base + c[2]]);
        }
    }
    let normals = (all_normals && !normals.is_empty()).then_some(normals);
    Ok((positions, indices, normals))
}
