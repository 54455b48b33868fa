//! Inline triangle meshes: a scene's `Triangles(positions: [...], indices: [...],
//! normals: [...], uvs: [...])`, checked field by field here (each error names
//! `objects[i].shape.indices[k]` and the like) and then built through the same
//! [`Mesh`] code as a mesh file's parsed contents, so an inline mesh and the same
//! triangles in an OBJ file are the same mesh, bit for bit.

use glam::Vec3;

use super::{Mesh, Placement, Transform};
use crate::error::{Error, Result};
use crate::io::MeshData;
use crate::scene::check::Check;
use crate::scene::desc::V3;

impl Mesh {
    /// The mesh of an inline `Triangles` description at `field` (`objects[i].shape`),
    /// placed by the object's transform `xf` when it has one. Per-vertex `normals`
    /// and `uvs`, when given, need one entry per position.
    pub(crate) fn from_inline_desc(
        check: &Check,
        field: &str,
        positions: &[V3],
        indices: &[[u32; 3]],
        normals: Option<&[V3]>,
        uvs: Option<&[[f32; 2]]>,
        xf: Option<&Placement>,
    ) -> Result<Mesh> {
        let f = |name: &str| format!("{field}.{name}");
        if positions.is_empty() {
            return Err(check.err(f("positions"), "expected at least one vertex position (x, y, z)"));
        }
        if indices.is_empty() {
            return Err(check.err(f("indices"), "expected at least one triangle (a, b, c)"));
        }
        let positions = positions
            .iter()
            .enumerate()
            .map(|(k, p)| check.vec(&format!("{field}.positions[{k}]"), *p))
            .collect::<Result<Vec<Vec3>>>()?;
        let n = positions.len();
        for (k, tri) in indices.iter().enumerate() {
            if let Some(bad) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(check.err(
                    format!("{field}.indices[{k}]"),
                    format!("vertex index {bad} out of range: expected 0 to {} (there are {n} positions)", n - 1),
                ));
            }
        }
        let per_vertex = |name: &str, len: usize| {
            if len == n {
                Ok(())
            } else {
                Err(check.err(f(name), format!("expected one entry per position ({n}), found {len}")))
            }
        };
        let normals = match normals {
            None => None,
            Some(ns) => {
                per_vertex("normals", ns.len())?;
                let ns = ns
                    .iter()
                    .enumerate()
                    .map(|(k, v)| {
                        // Kept as given (not normalised here), exactly as a file's normals.
                        let f = format!("{field}.normals[{k}]");
                        let v = check.vec(&f, *v)?;
                        if v == Vec3::ZERO { Err(check.err(f, "expected a non-zero normal")) } else { Ok(v) }
                    })
                    .collect::<Result<Vec<Vec3>>>()?;
                Some(ns)
            }
        };
        if let Some(uvs) = uvs {
            per_vertex("uvs", uvs.len())?;
            if let Some(k) = uvs.iter().position(|uv| !uv.iter().all(|c| c.is_finite())) {
                return Err(
                    check.err(format!("{field}.uvs[{k}]"), format!("expected finite (u, v), found {:?}", uvs[k]))
                );
            }
        }
        let data = MeshData { positions, triangles: indices.to_vec(), normals, uvs: uvs.map(<[_]>::to_vec) };
        Mesh::from_parts(data, &Transform::default(), xf.map(Placement::then).as_ref(), &Error::Settings).map_err(|e| {
            match (e, xf) {
                (Error::Setting { name, message }, Some(x)) => check.err(format!("{}.{name}", x.field), message),
                (Error::Settings(message), _) => check.err(f("indices"), message),
                (e, _) => check.err(field, e.to_string()),
            }
        })
    }
}
